"""Scenario files (TOML): what to simulate, how the firmware is set up, what to compare.

A scenario file names a ship motion (a fixed-position one may add heave,
surge and sway of the ship's reference point and lever arms to the IMU:
`pyins.sim.ShipAtSea`), sensor errors (a preset and/or values with units
such as ``"0.003 deg/h"``), the turntable and its indexing scheme, the
firmware configuration (alignment, ...), errors of the initial
state, the duration, the noise seed and the record interval; optionally a
``[compare]`` table that runs variants side by side, the ``[paper]``
figures it reproduces and which ``[outputs]`` to write. docs/scenarios.md
is the reference of every key.

Everything is validated when the file is loaded: an unknown key (with the
closest known key suggested), a wrong or missing unit, a value out of range
or of the wrong type, malformed TOML (with its line), an unknown preset,
scheme or motion kind all raise `ScenarioError`, whose message is one line
``FILE: key.path: reason``. The compiled firmware's own configuration
check (``pyins_config_check``) runs too.

The package holds the data only, in four rooms: `schema` (the Key tables),
`values` (one value against its Key), `resolve` (a whole file to SI
values), `build` (the motion, errors, table, firmware configuration and
initial state of a run, `RunSpec`); this module the loaded `Scenario` and
the built-ins.

    >>> sc = load("seed002_exp1")            # a built-in, or a path to a .toml file
    >>> for run in sc.runs():                 # one RunSpec per [compare] value
    ...     result = run_scenario.run(run)    # pyins.run_scenario.run: fil.run_fil(...)  # doctest: +SKIP

The built-in scenarios are TOML files in ``pyins/builtin/scenarios/`` (shipped in
the wheel: scikit-build-core's ``wheel.packages = ["pyins"]`` copies every
file of the package directory that git does not ignore, as it does for the
headers CMake installs beside the library); `builtin_path` says where one
is, to copy and edit it.

The firmware runs at 100 Hz (`pyins.units.TICK_HZ`), the rate
`pyins.fil.run_fil` uses; every time that becomes a tick count (duration,
record interval, alignment and stop lengths...) must be a whole number of
ticks.
"""
import copy
import difflib
import hashlib
import json
from pathlib import Path

try:
    import tomllib
except ImportError:            # Python 3.10: the same parser as a package
    import tomli as tomllib

from pyins import metrics
# the schema's tables and the build functions are importable from here too
# (campaigns, the CLI and the tests read them as pyins.scenario.NAME)
from pyins.scenario.build import (RunSpec, _build_motion, _firmware_check, _firmware_config, _runspec,
                                  initial_config, initial_errors, initial_truth)
from pyins.scenario.resolve import (_ALTERNATIVES, _NOT_COMPARABLE, _check_key_path, _resolve,
                                    _resolve_paper, _set_key)
from pyins.scenario.schema import (COARSE_METHODS, COMPARE_KEYS, COMPONENT_KEYS, FINE_CORRECTIONS,
                                   FINE_NOISES, FIGURE_KEYS, INDEX_SCHEMES, INDEX_SUMS, METRICS, MOTION_COMMON, MOTION_KINDS, SCHEMA_VERSION, SEGMENT_KEYS,
                                   SHIP_KEYS, SPECTRUM_KEYS, STEP_KEYS, TABLES, TOP_KEYS, VERTICAL_MODES,
                                   GNSS_KEYS, NAV_MODES, REFERENCE_TABLES, WINDOW_KEYS, ZERO_VELOCITY_KEYS,
                                   Key)
from pyins.scenario.values import _need_table, _read
from pyins.units import DT, TICK_HZ, UNITS, ScenarioError

__all__ = ["load", "loads", "list_builtin", "builtin_path", "Scenario", "RunSpec", "ScenarioError",
           "format_figure", "in_figure_unit", "initial_truth", "initial_config", "initial_errors",
           "TICK_HZ", "DT", "METRICS"]

BUILTIN_DIR = Path(__file__).resolve().parent.parent / "builtin" / "scenarios"   #: the built-in scenarios (data)


def _canonical(value):
    return json.dumps(value, sort_keys=True, separators=(",", ":"), allow_nan=False)


class Scenario:
    """A loaded, validated scenario.

    ``text`` is the TOML text as read, ``data`` its parsed tables, ``source``
    the file it came from. `resolved` gives every value in SI, `runs` the
    runs, `with_overrides` a changed copy (validated again).
    """

    def __init__(self, text, data, source, stem):
        self.text = text
        self.data = data
        self.source = source
        self._stem = stem
        self.notes = []         #: what an override changed beyond its key ([compare] collapsed, figures left out)
        try:
            self._base = _resolve(data, stem)
            self._compare, self._variants = self._resolve_compare(data)
            labels = [label for label, _ in self._variants]
            self._paper = _resolve_paper(data.get("paper", {}), labels if self._compare else [])
            for label, res in self._variants:
                motion = _build_motion(res["motion"])
                _firmware_check(motion, _firmware_config(res, motion))
        except ScenarioError as exc:
            raise exc.with_source(source) from None

    def _resolve_compare(self, data):
        if "compare" not in data:
            return None, [(self._base["name"], self._base)]
        c = _read(_need_table(data["compare"], "compare"), "compare", COMPARE_KEYS)
        key = c["key"]
        _check_key_path(key, "compare.key")
        if key.split(".")[0] in _NOT_COMPARABLE:
            raise ScenarioError(f"{key!r} cannot be compared (only the run's own keys: seed, "
                                f"duration, record_every, motion.*, sensors.*, ...)", "compare.key")
        labels = c["labels"]
        if labels is None:
            labels = [f"{key} = {v}" for v in c["values"]]
        elif len(labels) != len(c["values"]):
            raise ScenarioError(f"{len(labels)} labels for {len(c['values'])} values", "compare.labels")
        elif not all(isinstance(s, str) for s in labels):
            raise ScenarioError("must be strings", "compare.labels")
        if len(set(labels)) != len(labels):
            raise ScenarioError("labels must differ from each other", "compare.labels")
        variants = []
        for i, value in enumerate(c["values"]):
            d = copy.deepcopy(data)
            del d["compare"]
            d.pop("paper", None)
            try:
                _set_key(d, key, value)
                variants.append((labels[i], _resolve(d, self._stem)))
            except ScenarioError as exc:
                reason = f"{exc.key}: {exc.reason}" if exc.key else exc.reason
                if exc.key != key:
                    reason = f"with {key} = {value!r}: {reason}"
                raise ScenarioError(reason, f"compare.values[{i}]") from None
        return {"key": key, "values": c["values"], "labels": labels}, variants

    # -- properties --------------------------------------------------------
    @property
    def name(self):
        return self._base["name"]

    @property
    def title(self):
        return self._base["title"]

    @property
    def duration_s(self):
        return self._base["duration_s"]

    @property
    def seed(self):
        return self._base["seed"]

    @property
    def labels(self):
        """The labels of the runs, in order."""
        return [label for label, _ in self._variants]

    @property
    def paper(self):
        """The resolved [paper]: citation, note, figures (each with metric,
        value_si, shown, relation, variant, note)."""
        return copy.deepcopy(self._paper)

    @property
    def outputs(self):
        return dict(self._base["outputs"])

    def __repr__(self):
        return f"Scenario({self.name!r}, {len(self._variants)} run(s), source={self.source!r})"

    # -- the API -----------------------------------------------------------
    def resolved(self):
        """Every value of the scenario in SI, as a plain JSON-serialisable
        dict (keys carry their unit: ``lat_rad``, ``duration_s``; None = not
        set, the firmware's default). With [compare], ``compare`` holds the
        key, values and labels and ``variants`` the resolved form of each run."""
        out = copy.deepcopy(self._base)
        out["source"] = self.source
        out["paper"] = self.paper
        if self._compare is not None:
            out["compare"] = copy.deepcopy(self._compare)
            out["variants"] = [dict(label=label, **copy.deepcopy(res)) for label, res in self._variants]
        return out

    def resolved_json(self):
        """`resolved` as indented JSON text (for resolved_scenario.json)."""
        return json.dumps(self.resolved(), indent=2, allow_nan=False) + "\n"

    def digest(self):
        """SHA-256 (hex) of `resolved` in canonical JSON, without ``source``:
        the same scenario loaded from anywhere gives the same digest, any
        change of a value (title and [paper] included) changes it."""
        res = self.resolved()
        del res["source"]
        return hashlib.sha256(_canonical(res).encode()).hexdigest()

    def runs(self):
        """One `RunSpec` per [compare] value (one without [compare])."""
        for i, (label, res) in enumerate(self._variants):
            yield _runspec(res, label, i)

    def with_overrides(self, overrides):
        """A new validated Scenario with keys replaced.

        ``overrides``: {"seed": 3, "motion.yaw": "60 deg", "indexing.scheme":
        "flexible"}: dotted paths as in the file, values as a file writes
        them (quantities as strings with units); None removes a key (back to
        its default). Setting yaw removes heading and the other way round.
        ``text`` stays the original file's; ``source`` says "with overrides".
        """
        data = copy.deepcopy(self.data)
        where = f"{self.source} (with overrides)"
        notes = list(getattr(self, "notes", []))
        cmp = data.get("compare") if isinstance(data.get("compare"), dict) else None
        for path, value in overrides.items():
            if cmp is not None and path == cmp.get("key") and isinstance(cmp.get("values"), list):
                # the value given wins over [compare]'s: one variant, under its label when it is one of them
                values, labels = cmp["values"], cmp.get("labels")
                label = (labels[values.index(value)] if value in values and isinstance(labels, list)
                         and len(labels) == len(values) else f"{path} = {value}")
                cmp.update(values=[value], labels=[label])
                notes.append(f"{path} = {value!r} replaces [compare], which varied it over "
                             f"{', '.join(map(str, values))}: one run, {label!r}")
            elif cmp is not None and path == "compare.values" and "compare.labels" not in overrides:
                cmp.pop("labels", None)        # the file's labels are for its values
            try:
                _set_key(data, path, value)
            except ScenarioError as exc:
                raise exc.with_source(where) from None
        _drop_figures_of_variants_not_run(data, notes)
        scn = Scenario(self.text, data, where, self._stem)
        scn.notes = notes
        return scn

    def only_variant(self, n, option="--variant"):
        """The scenario with only its [compare] variant ``n`` (its label and
        paper figures kept); ScenarioError naming ``option`` when there is none."""
        labels = self.labels
        if not 0 <= n < len(labels):
            raise ScenarioError(f"{option} {n}: {self.name} has {len(labels)} variant(s) "
                                f"(0..{len(labels) - 1})", "", self.source)
        if self._compare is None:
            return self
        data = copy.deepcopy(self.data)
        data["compare"].update(values=[self._compare["values"][n]], labels=[labels[n]])
        notes = list(getattr(self, "notes", []))
        _drop_figures_of_variants_not_run(data, notes)
        scn = Scenario(self.text, data, f"{self.source} (variant {n})", self._stem)
        scn.notes = notes + [f"{option} {n}: only the variant {labels[n]!r} of [compare] is run"]
        return scn


def _drop_figures_of_variants_not_run(data, notes):
    """[paper] figures of variants an override took out of [compare] leave
    the scenario (a note says which)."""
    cmp = data.get("compare") if isinstance(data.get("compare"), dict) else None
    paper = data.get("paper") if isinstance(data.get("paper"), dict) else None
    if cmp is None or paper is None or not isinstance(paper.get("figures"), list):
        return
    labels = cmp.get("labels")
    if not isinstance(labels, list):
        labels = [f"{cmp.get('key')} = {v}" for v in cmp.get("values", [])]
    keep = [f for f in paper["figures"] if not isinstance(f, dict) or f.get("variant") in (None, *labels)]
    gone = sorted({f.get("variant") for f in paper["figures"] if f not in keep})
    if gone:
        paper["figures"] = keep
        notes.append(f"the paper's figures of {', '.join(map(repr, gone))} are not shown: that run is not "
                     "made")


def loads(text, source="<string>", name=None):
    """A Scenario from TOML text. ``name``: the default of the ``name`` key
    (``load`` passes the file name without .toml)."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"malformed TOML: {exc}", "", source) from None
    return Scenario(text, data, source, name or "scenario")


def find_builtin(directory, name, what, names):
    """``directory/name.toml``, or a ScenarioError naming the built-ins
    (``what``: "scenario", "campaign")."""
    path = Path(directory) / f"{name}.toml"
    if not path.is_file():
        close = difflib.get_close_matches(name, names, n=1)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise ScenarioError(f"no such file or built-in {what}{hint} (built-ins: {', '.join(names)})",
                            "", name)
    return path


def read_toml_source(path_or_name, builtin):
    """(text, path) of a .toml file, or of the built-in ``builtin(name)``
    returns the path of; unreadable files raise ScenarioError."""
    path = Path(path_or_name)
    if path.is_dir():
        run = (path / "summary.json").exists() or (path / "resolved_scenario.json").exists()
        raise ScenarioError("a directory, not a scenario file" + (
            f" (a run directory: `pyins report {path_or_name}` renders it, `pyins run SCENARIO --out "
            f"{path_or_name} --resume` continues it)" if run else ": give a .toml file or a built-in name "
            "(pyins list)"), "", str(path_or_name))
    if not path.is_file():
        path = builtin(str(path_or_name))
    try:
        return path.read_text(encoding="utf-8"), path
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError(f"cannot read: {exc}", "", str(path_or_name)) from None


def builtin_path(name):
    """The path of built-in scenario ``name`` (to copy and edit)."""
    return find_builtin(BUILTIN_DIR, name, "scenario", [n for n, _ in list_builtin()])


def load(path_or_name):
    """A Scenario from a .toml file, or the built-in of that name."""
    text, path = read_toml_source(path_or_name, builtin_path)
    return loads(text, source=str(path), name=path.stem)


def list_builtin():
    """[(name, title)] of the built-in scenarios, sorted by name."""
    out = []
    for path in sorted(BUILTIN_DIR.glob("*.toml")):
        data = tomllib.loads(path.read_text(encoding="utf-8"))
        out.append((path.stem, data.get("title", path.stem)))
    return out


def format_figure(figure):
    """A [paper] figure as text, e.g. "horizontal_error_final = 8.57 nmi"."""
    return f"{figure['metric']} {figure['relation']} {figure['value']:g} {figure['unit']}".rstrip()


def in_figure_unit(value_si, figure):
    """Our ``value_si`` of a figure's metric, in the unit the paper's
    figure is written in (to print them side by side)."""
    if not figure["unit"]:
        return value_si
    return value_si / UNITS[metrics.dimension(figure["metric"])][figure["unit"]]
