"""A campaign's definition: the grid, the seeds and the groups, expanded into points.

A campaign is a base scenario (a built-in name or a TOML path), a grid of
overrides (dotted scenario keys -> lists of values, as
`pyins.scenario.Scenario.with_overrides` takes them), optional fixed
overrides applied to every run, noise seeds (a count or a list, optionally
turned into the scenario's ``seed`` by a formula, `pyins.campaign.grid`)
and the keys to group the runs by. Every combination of grid values times
every seed is one `Point`; each point is one scenario, validated when the
campaign is built, whose `Scenario.digest` names its run directory
(``runs/<digest[:16]>``).

Building a campaign (`_build`, whichever way it is written):
1. the grid and fixed keys are scenario keys the campaign may set;
2. the labels of grid values;
3. the seeds and their formula;
4. what becomes of the base's [compare] (``compare``: "auto", "keep", "drop",
   see `pyins.campaign`);
5. the group keys;
6. the fixed overrides, then every grid value alone, on the base (a message
   names the value);
7. the points, in grid order then seeds, and their groups.

Written three ways: a campaign file (`load_campaign`, `loads_campaign`),
a built-in of pyins/builtin/campaigns/ (`list_builtin`, `builtin_path`), or
command-line arguments (`from_args`).
"""
import copy
import difflib
import hashlib
import itertools
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

try:
    import tomllib
except ImportError:            # Python 3.10
    import tomli as tomllib

from pyins import scenario as scenario_mod
from pyins.campaign.grid import (canonical, compile_formula, eval_formula, formula_names,
                                 number_as_written, parse_grid, parse_overrides, parse_seeds, qkey,
                                 show, value_label)
from pyins.sim import sensors
from pyins.units import ScenarioError

__all__ = ["Campaign", "Point", "load_campaign", "loads_campaign", "from_args", "list_builtin",
           "builtin_path", "default_out_dir", "BUILTIN_DIR", "CAMPAIGN_KEYS"]

BUILTIN_DIR = Path(__file__).resolve().parent.parent / "builtin" / "campaigns"   #: the built-in campaigns (data)
CAMPAIGN_KEYS = ("name", "title", "description", "scenario", "seeds", "seed_formula", "group_by",
                 "compare", "grid", "set", "labels", "random_constants")


@dataclass(frozen=True)
class Point:
    """One run of a campaign."""
    index: int                  #: position in the campaign (grid order, then seeds)
    values: dict                #: grid key -> value as written
    run: object                 #: the `seeds` entry (None: no seeds)
    seed: object                #: the scenario seed set (None: the base's own)
    group: int                  #: index of its group
    overrides: dict             #: everything passed to Scenario.with_overrides
    digest: str                 #: Scenario.digest() of the overridden scenario

    @property
    def dir(self):
        """Its run directory, relative to the campaign's out_dir."""
        return f"runs/{self.digest[:16]}"

    def label(self, labels=None):
        """"motion.heading = 60 deg, run 3 (seed 60003)" (``labels``: Campaign.labels)."""
        parts = [value_label(labels, k, v, self.values) for k, v in self.values.items()]
        if self.run is not None:
            parts.append(f"run {self.run}" + (f" (seed {self.seed})" if self.seed != self.run else ""))
        return ", ".join(parts) or "base"


@dataclass
class Campaign:
    """A validated campaign; build it with `load_campaign` or `from_args`."""
    name: str
    title: str
    description: str
    base: object                      #: the base pyins.scenario.Scenario
    scenario_ref: str                 #: the base as written (built-in name or path)
    grid: dict                        #: grid key -> [values]
    seeds: object                     #: [int] or None
    seed_formula: object              #: str or None
    group_by: list
    overrides: dict                   #: fixed overrides (every run)
    compare: str                      #: "keep" or "drop" (what "auto" became)
    labels: dict                      #: grid key -> ([canonical values], [labels])
    source: str
    points: list = field(default_factory=list)
    groups: list = field(default_factory=list)   #: [{values: {key: value}, label: str}]
    random_constants: object = None   #: sensor preset whose random constants each run draws, or None

    def __repr__(self):
        return (f"Campaign({self.name!r}, {len(self.points)} runs in {len(self.groups)} group(s), "
                f"base {self.base.name!r})")

    @property
    def variants(self):
        """The [compare] labels of the base each point runs (None: one run per point)."""
        return self.base.labels if self.compare == "keep" and len(self.base.labels) > 1 else None

    def digest(self):
        """SHA-256 of the campaign's content: its points (digests) and grouping."""
        body = {"points": [[p.digest, p.group, canonical(p.values), p.run] for p in self.points],
                "group_by": self.group_by, "compare": self.compare}
        return hashlib.sha256(canonical(body).encode()).hexdigest()

    def describe(self):
        """The campaign's definition as a plain dict (for campaign.json)."""
        return {"name": self.name, "title": self.title, "description": self.description,
                "source": self.source, "scenario": self.scenario_ref,
                "base": {"name": self.base.name, "title": self.base.title, "source": self.base.source,
                         "digest": self.base.digest(), "labels": self.base.labels},
                "grid": self.grid, "labels": {k: v[1] for k, v in self.labels.items()},
                "seeds": self.seeds, "seed_formula": self.seed_formula, "group_by": self.group_by,
                "set": self.overrides, "compare": self.compare, "variants": self.variants,
                **({"random_constants": self.random_constants} if self.random_constants else {}),
                "digest": self.digest()}

    show = staticmethod(show)          #: a value as written (strings as they are, else JSON)

    def value_label(self, key, value):
        """A group's value of ``key`` as text ("heave 0.5 m", "run 2")."""
        return f"run {value}" if key == "seed" else value_label(self.labels, key, value, self.grid)

    def by_key(self, key):
        """The groups arranged against one group key: (x labels, lines) with
        lines = [(label of the other keys' values, {x index: group index})],
        both in the order the groups come (grid order)."""
        others = [k for k in self.group_by if k != key]
        xs, lines = {}, {}
        for gi, g in enumerate(self.groups):
            vals = g["values"]
            x = xs.setdefault(canonical(vals[key]), (len(xs), self.value_label(key, vals[key])))[0]
            line = tuple(canonical(vals[k]) for k in others)
            if line not in lines:
                lines[line] = (", ".join(self.value_label(k, vals[k]) for k in others), {})
            lines[line][1][x] = gi
        return [label for _, label in sorted(xs.values())], list(lines.values())


def _base_overrides(base, compare, fixed):
    out = {}
    if compare == "drop":
        out.update({"compare": None, "paper": None})
    out.update(fixed)
    return out


def _rewrap(exc, key, source, prefix=""):
    """A ScenarioError of a point, as one line about the campaign file."""
    inner = f"{exc.key}: {exc.reason}" if exc.key else exc.reason
    return ScenarioError(prefix + inner, key, source)


def _check_random_constants(preset, grid, fixed, seeds, source):
    """``random_constants``: a sensor preset; needs seeds (the draws); the
    campaign may not set the terms it draws."""
    where = "campaign.random_constants"
    if not isinstance(preset, str) or preset not in sensors.PRESETS:
        close = difflib.get_close_matches(str(preset), list(sensors.PRESETS), n=1)
        hint = f"did you mean {close[0]!r}? " if close else ""
        raise ScenarioError(f"{preset!r} is not a sensor preset; {hint}(presets: "
                            f"{', '.join(sensors.PRESETS)})", where, source)
    if not any(np.any(getattr(sensors.PRESETS[preset], t) != 0.0)
               for t, _, _ in sensors.RANDOM_CONSTANT_TERMS):
        raise ScenarioError(f"the preset {preset!r} has no random constants to draw", where, source)
    if seeds is None:
        raise ScenarioError("needs campaign.seeds: each seeds entry is one draw", where, source)
    drawn = {f"sensors.{t}" for t, _, _ in sensors.RANDOM_CONSTANT_TERMS}
    for table, keys in (("set", fixed), ("grid", grid)):
        for key in keys:
            if key in drawn or key in ("sensors", "sensors.preset"):
                raise ScenarioError(f"drawn by campaign.random_constants = {preset!r}: do not set it",
                                    qkey(table, key), source)


def _build(base, scenario_ref, grid, seeds, group_by, *, overrides=None, seed_formula=None,
           compare="auto", labels=None, name=None, title=None, description="", source="command line",
           random_constants=None):
    """Validate everything and expand the points (ScenarioError: one line).

    ``random_constants``: a sensor preset name (`pyins.sim.sensors`): every
    point sets ``sensors.preset`` to it and replaces its random constants
    (biases, scale-factor and installation errors) by draw ``run`` (the
    seeds entry) of `pyins.sim.sensors.random_constant_overrides`, so every
    grid point of one ``run`` has the same constants (paired comparisons)."""
    grid = dict(grid or {})
    fixed = dict(overrides or {})
    # 1. grid and fixed keys: scenario keys, not the campaign's own business
    for table, keys in (("set", fixed), ("grid", grid)):
        for key in keys:
            where = qkey(table, key)
            if key == "seed" and table == "grid":
                raise ScenarioError("the seeds of a campaign go in campaign.seeds (a count or a list), "
                                    "not in the grid", where, source)
            try:
                scenario_mod._check_key_path(key, where)
            except ScenarioError as exc:
                raise ScenarioError(exc.reason.replace(f"{key!r} ", "", 1) if exc.reason.startswith(
                    f"{key!r} ") else exc.reason, where, source) from None
            if key.split(".")[0] in ("compare", "paper", "name"):
                raise ScenarioError(f"{key!r} cannot be set by a campaign (use campaign.compare to "
                                    f"keep or drop the base's [compare])", where, source)
    for key, values in grid.items():
        where = qkey("grid", key)
        if key in fixed:
            raise ScenarioError("set both in campaign.set and in campaign.grid", where, source)
        if not isinstance(values, list) or not values:
            raise ScenarioError(f"must be a non-empty array of values, got {values!r}", where, source)
        canon = [canonical(v) for v in values]
        if len(set(canon)) != len(canon):
            dup = next(v for i, v in enumerate(values) if canon.index(canon[i]) != i)
            raise ScenarioError(f"the value {dup!r} is given twice", where, source)
    # 2. labels of grid values
    lab = {}
    for key, names in (labels or {}).items():
        where = qkey("labels", key)
        if key not in grid:
            raise ScenarioError(f"{key!r} is not a grid key (grid: {', '.join(grid) or 'none'})",
                                where, source)
        if not isinstance(names, list) or not all(isinstance(s, str) for s in names):
            raise ScenarioError("must be an array of strings, one per grid value", where, source)
        if len(names) != len(grid[key]):
            raise ScenarioError(f"{len(names)} labels for {len(grid[key])} values", where, source)
        if len(set(names)) != len(names):
            raise ScenarioError("labels must differ from each other", where, source)
        lab[key] = ([canonical(v) for v in grid[key]], list(names))
    # 3. seeds and their formula
    seeds = parse_seeds(seeds, "campaign.seeds", source)
    if random_constants is not None:
        _check_random_constants(random_constants, grid, fixed, seeds, source)
    formula = None
    names = formula_names(grid)
    if seed_formula is not None:
        if not isinstance(seed_formula, str) or not seed_formula.strip():
            raise ScenarioError(f"must be a formula as a string (e.g. '1000 * heading + run'), got "
                                f"{seed_formula!r}", "campaign.seed_formula", source)
        formula = compile_formula(seed_formula, set(names) | {"run", "point"},
                                   "campaign.seed_formula", source)
        if seeds is None:
            seeds = [0]
    # 4. what becomes of the base's [compare]
    if compare not in ("auto", "keep", "drop"):
        raise ScenarioError(f"unknown value {compare!r} (choose one of auto, keep, drop)",
                            "campaign.compare", source)
    ckey = (base.resolved().get("compare") or {}).get("key")
    if "seed" in fixed and seeds is not None:
        raise ScenarioError("the seed is set both here and by campaign.seeds", qkey("set", "seed"),
                            source)
    set_by_campaign = set(grid) | set(fixed) | ({"seed"} if seeds is not None else set())
    set_by_campaign |= {scenario_mod._ALTERNATIVES[k] for k in set_by_campaign
                        if k in scenario_mod._ALTERNATIVES}          # yaw <-> heading
    if ckey is None:
        compare = "drop" if compare == "auto" else compare
        if compare == "keep":
            compare = "drop"              # nothing to keep: one run per point either way
    elif compare == "auto":
        compare = "drop" if ckey in set_by_campaign else "keep"
    elif compare == "keep" and ckey in set_by_campaign:
        raise ScenarioError(f"the base scenario's [compare] varies {ckey!r}, which the campaign sets "
                            f"too: use compare = 'drop'", "campaign.compare", source)
    # 5. group_by
    if group_by is None:
        group_by = list(grid)
    elif isinstance(group_by, str):
        group_by = [s.strip() for s in group_by.split(",") if s.strip()]
    if not isinstance(group_by, (list, tuple)) or not all(isinstance(s, str) for s in group_by):
        raise ScenarioError(f"must be an array of grid keys, got {group_by!r}", "campaign.group_by", source)
    allowed = list(grid) + (["seed"] if seeds is not None else [])
    for key in group_by:
        if key not in allowed:
            close = difflib.get_close_matches(key, allowed, n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise ScenarioError(f"{key!r} is not a grid key{hint} (group by any of: "
                                f"{', '.join(allowed) or 'nothing: the campaign has no grid'})",
                                "campaign.group_by", source)
    if len(set(group_by)) != len(group_by):
        raise ScenarioError("a key is given twice", "campaign.group_by", source)
    group_by = list(group_by)

    # 6. the fixed overrides on the base, then every grid value alone (a message naming the value)
    common = _base_overrides(base, compare, fixed)
    try:
        base.with_overrides(common)
    except ScenarioError as exc:
        if exc.key in fixed:
            raise ScenarioError(exc.reason, qkey("set", exc.key), source) from None
        raise _rewrap(exc, "campaign.set", source) from None
    for key, values in grid.items():
        for i, v in enumerate(values):
            try:
                base.with_overrides({**common, key: v})
            except ScenarioError as exc:
                inner = exc.reason if exc.key == key else f"{exc.key}: {exc.reason}" if exc.key else exc.reason
                raise ScenarioError(inner, f"{qkey('grid', key)}[{i}]", source) from None

    # 7. the points (grid order, then seeds) and their groups
    points, groups, group_index = [], [], {}
    keys = list(grid)
    combos = list(itertools.product(*(range(len(grid[k])) for k in keys)))
    for ci, combo in enumerate(combos):
        values = {k: grid[k][i] for k, i in zip(keys, combo)}
        for run in (seeds if seeds is not None else [None]):
            ov = dict(common)
            ov.update(values)
            if random_constants is not None:
                ov.update(_drawn(random_constants, run))
            seed = run
            if formula is not None:
                env = {"run": run, "point": ci}
                for nm, (k, what) in names.items():
                    if what == "index":
                        env[nm] = combo[keys.index(k)]
                    else:
                        num = number_as_written(values[k])
                        env[nm] = num if num is not None else (
                            f"{nm} is {show(values[k])!r}, not a number: use {nm}_index")
                try:
                    seed = eval_formula(formula, env)
                except ValueError as exc:
                    raise ScenarioError(f"{seed_formula!r}: {exc}", "campaign.seed_formula",
                                        source) from None
                except (ZeroDivisionError, OverflowError) as exc:
                    raise ScenarioError(f"{seed_formula!r}: {exc}", "campaign.seed_formula",
                                        source) from None
                if isinstance(seed, float) and seed.is_integer():
                    seed = int(seed)
                if not isinstance(seed, int) or seed < 0:
                    raise ScenarioError(f"{seed_formula!r} gives {seed!r} for "
                                        f"{', '.join(f'{k} = {show(v)}' for k, v in values.items())}"
                                        f"{', ' if values else ''}run {run}: a seed must be an "
                                        f"integer >= 0", "campaign.seed_formula", source)
            if seed is not None:
                ov["seed"] = seed
            try:
                scn = base.with_overrides(ov)
            except ScenarioError as exc:
                at = ", ".join(f"{k} = {show(v)}" for k, v in values.items())
                at += (", " if at else "") + (f"seed {seed}" if seed is not None else "")
                raise _rewrap(exc, "campaign.grid", source, f"with {at}: ") from None
            gkey = tuple(canonical(values[k]) if k != "seed" else str(run) for k in group_by)
            if gkey not in group_index:
                group_index[gkey] = len(groups)
                gvals = {k: (values[k] if k != "seed" else run) for k in group_by}
                glabel = ", ".join(
                    value_label(lab, k, v, grid) if k != "seed" else f"run {v}"
                    for k, v in gvals.items()) or "all runs"
                groups.append({"values": gvals, "label": glabel})
            points.append(Point(index=len(points), values=values, run=run, seed=seed,
                                group=group_index[gkey], overrides=ov, digest=scn.digest()))
    if not isinstance(name, str) or not name:
        name = f"{base.name}_campaign"
    if not re.fullmatch(r"[A-Za-z0-9_.-]+", name):
        raise ScenarioError(f"{name!r} may hold only letters, digits, '_', '.' and '-'", "campaign.name",
                            source)
    return Campaign(name=name, title=title or name, description=description or "", base=base,
                    scenario_ref=scenario_ref, grid=grid, seeds=seeds, seed_formula=seed_formula,
                    group_by=group_by, overrides=fixed, compare=compare, labels=lab, source=source,
                    points=points, groups=groups, random_constants=random_constants)


def _drawn(preset, run, _cache={}):
    """The overrides of draw ``run`` of ``preset`` (cached: one per draw, not per point)."""
    key = (preset, run)
    if key not in _cache:
        _cache[key] = {"sensors.preset": preset, **sensors.random_constant_overrides(preset, run)}
    return copy.deepcopy(_cache[key])


def _flatten(table, where, source):
    """{"motion.heading": [...]} or {"motion": {"heading": [...]}} (unquoted
    dotted TOML keys) -> {"motion.heading": [...]}."""
    if not isinstance(table, dict):
        raise ScenarioError(f"must be a table, got {table!r}", where, source)
    out = {}
    for key, value in table.items():
        if isinstance(value, dict) and key in scenario_mod.TABLES:
            for sub, v in value.items():
                out[f"{key}.{sub}"] = v
        else:
            out[key] = value
    return out


def _load_base(ref, source, relative_to=None):
    """The base scenario: a path (relative to the campaign file first) or a built-in."""
    if not isinstance(ref, str) or not ref:
        raise ScenarioError(f"must be a built-in scenario name or a path, got {ref!r}",
                            "campaign.scenario", source)
    path = ref
    if relative_to is not None and not os.path.isabs(ref):
        cand = Path(relative_to).parent / ref
        if cand.is_file():
            path = str(cand)
    try:
        return scenario_mod.load(path)
    except ScenarioError as exc:
        if exc.source == path and not exc.key:          # no such file or built-in
            raise ScenarioError(f"{ref!r}: {exc.reason}", "campaign.scenario", source) from None
        raise ScenarioError(f"the base scenario {ref!r} is invalid: {exc}", "campaign.scenario",
                            source) from None


def loads_campaign(text, source="<string>", name=None, relative_to=None, seeds=None, group_by=None):
    """A Campaign from the TOML text of a campaign file; ``seeds`` and
    ``group_by`` (the command line's --seeds, --group-by), when given,
    stand for the file's own ``seeds`` and ``group_by``."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"malformed TOML: {exc}", "", source) from None
    if "campaign" not in data:
        if "motion" in data:
            raise ScenarioError("this is a scenario file, not a campaign: a campaign file has a "
                                "[campaign] table whose 'scenario' names the base scenario", "", source)
        raise ScenarioError("missing table [campaign] (required: scenario = '...', [campaign.grid], "
                            "seeds, group_by)", "campaign", source)
    for key in data:
        if key != "campaign":
            close = difflib.get_close_matches(key, ["campaign"], n=1)
            hint = f"; did you mean {close[0]!r}?" if close else " (a campaign file holds only [campaign])"
            raise ScenarioError(f"unknown key{hint}", key, source)
    c = data["campaign"]
    if not isinstance(c, dict):
        raise ScenarioError("must be a table", "campaign", source)
    for key in c:
        if key not in CAMPAIGN_KEYS:
            close = difflib.get_close_matches(key, CAMPAIGN_KEYS, n=1, cutoff=0.5)
            hint = f"did you mean {close[0]!r}?" if close else f"known keys: {', '.join(CAMPAIGN_KEYS)}"
            raise ScenarioError(f"unknown key; {hint}", f"campaign.{key}", source)
    if "scenario" not in c:
        raise ScenarioError("missing (required: the base scenario, a built-in name or a path)",
                            "campaign.scenario", source)
    for key in ("name", "title", "description", "compare"):
        if key in c and not isinstance(c[key], str):
            raise ScenarioError(f"must be a string, got {c[key]!r}", f"campaign.{key}", source)
    if seeds is not None:
        c = dict(c, seeds=seeds)
    elif "seeds" in c and isinstance(c["seeds"], str):
        raise ScenarioError(f"must be a count or an array of seeds, got the string {c['seeds']!r}",
                            "campaign.seeds", source)
    base = _load_base(c["scenario"], source, relative_to)
    grid = _flatten(c.get("grid", {}), "campaign.grid", source)
    fixed = _flatten(c.get("set", {}), "campaign.set", source)
    labels = _flatten(c.get("labels", {}), "campaign.labels", source)
    if not grid and "seeds" not in c:
        raise ScenarioError("a campaign needs a grid ([campaign.grid]) or seeds", "campaign", source)
    return _build(base, c["scenario"], grid, c.get("seeds"), group_by if group_by is not None else c.get("group_by"),
                  overrides=fixed,
                  seed_formula=c.get("seed_formula"), compare=c.get("compare", "auto"), labels=labels,
                  name=c.get("name", name), title=c.get("title"), description=c.get("description", ""),
                  source=source, random_constants=c.get("random_constants"))


def builtin_path(name):
    """The path of built-in campaign ``name`` (to copy and edit)."""
    return scenario_mod.find_builtin(BUILTIN_DIR, name, "campaign", [n for n, _ in list_builtin()])


def load_campaign(path_or_name, seeds=None, group_by=None):
    """A Campaign from a campaign .toml file, or the built-in of that name;
    ``seeds``, ``group_by`` (when given) stand for the file's own."""
    text, path = scenario_mod.read_toml_source(path_or_name, builtin_path)
    return loads_campaign(text, source=str(path), name=path.stem, relative_to=path, seeds=seeds,
                          group_by=group_by)


def list_builtin():
    """[(name, title)] of the built-in campaigns, sorted by name."""
    out = []
    for path in sorted(BUILTIN_DIR.glob("*.toml")):
        data = tomllib.loads(path.read_text(encoding="utf-8"))
        out.append((path.stem, data.get("campaign", {}).get("title", path.stem)))
    return out


def from_args(scenario, grid_strings=(), seeds=None, group_by=None, *, overrides=None,
              seed_formula=None, compare="auto", name=None, title=None, random_constants=None):
    """A Campaign from command-line style arguments.

    ``scenario``: a built-in name, a path or a Scenario; ``grid_strings``:
    ["motion.heading=0 deg,60 deg,120 deg", ...] (or a dict key -> list);
    ``seeds``: None (the base's seed), a count N (0..N-1), a list, or text
    ("5", "0,3,7", "2..6"); ``group_by``: grid keys (list or "a,b"; None:
    every grid key); ``overrides``: ["duration=30 s", ...] or a dict, set on
    every run; ``seed_formula``: e.g. "1000 * heading + run"; ``compare``:
    "auto", "keep" or "drop" (the base's [compare]); ``random_constants``: a
    sensor preset whose random constants each seeds entry draws (`_build`).
    """
    source = "command line"
    if isinstance(scenario, scenario_mod.Scenario):
        base, ref = scenario, scenario.name
    else:
        base, ref = _load_base(str(scenario), source), str(scenario)
    grid = dict(grid_strings) if isinstance(grid_strings, dict) else parse_grid(grid_strings)
    if not grid and seeds is None:
        raise ScenarioError("a campaign needs a grid (KEY=V1,V2,...) or seeds", "", source)
    return _build(base, ref, grid, seeds, group_by, overrides=parse_overrides(overrides),
                  seed_formula=seed_formula, compare=compare, name=name, title=title, source=source,
                  random_constants=random_constants)


def default_out_dir(camp):
    """runs/campaigns/<name>: where the CLI puts a campaign by default."""
    return os.path.join("runs", "campaigns", camp.name)
