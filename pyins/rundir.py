"""The run directory: its layout, reading it back, refusing another
scenario's, and the guard that holds Ctrl-C off while it is written.
Running a scenario into one (what ``pyins run`` does) is
`pyins.run_scenario`; the report of one is `pyins.report.run`.

A run directory holds::

    scenario.toml              the scenario as written (built-ins: their file)
    resolved_scenario.json     every value in SI units, as run
    summary.json               per variant: metrics (SI, units in the names),
                               ticks done, wall time, its duration as run and
                               as the scenario file writes it, whether its
                               scheme uses the flexible sums; the paper's
                               figures
    <variant>/records/         the firmware and plant records (fil.run_fil
                               record_dir: raw binary, checkpoints)
    <variant>/timeseries.npz   the records and the errors against the truth
    <variant>/timeseries.csv   the errors, at most records.CSV_MAX_ROWS rows
    *.png, report.html         written by pyins.report
    pyins.lock                 held while the directory is written

A directory being written is locked (`pyins.records.lock_dir`); one holding
another scenario's run is refused (`check_run_dir`). A stopped variant's
records are read back whole, past its last checkpoint (`load_written`), and
the Scenario a directory was written from is rebuilt from its summary
(`scenario_of`).
"""
import hashlib
import json
import os
import re
import shutil
import signal
import threading

import numpy as np

from pyins import records, scenario, sim
from pyins.reference import abi
from pyins.units import ScenarioError

__all__ = ["slug", "load_variant", "load_written", "check_run_dir", "clean_run_dir", "dir_digest", "read_summary",
           "write_summary", "scenario_of", "written_ticks", "written_durations", "uses_index_sums",
           "variant_facts", "hold_interrupts", "RunDirError", "SUMMARY", "RUN_FILES", "FORMAT",
           "summary_for_report"]

SUMMARY = "summary.json"
#: The layout of summary.json a run writes (``"format"``); a newer one is refused by the report
FORMAT = 1


def slug(label):
    """A directory name for a variant label."""
    s = re.sub(r"[^A-Za-z0-9._-]+", "_", label).strip("_")
    return s or "run"


def load_variant(run_dir, spec):
    """A variant's records (complete or partial) as a FilResult beside its
    records.json info, or (None, None)."""
    return records.load_variant(os.path.join(run_dir, slug(spec.label), "records"), spec.motion, spec.dt)


class RunDirError(ValueError):
    """A run directory that cannot be written: it holds another scenario's
    run, or files that are not a run's (one line)."""


#: What a run writes at the top of its directory (`clean_run_dir` removes only these)
RUN_FILES = (SUMMARY, "scenario.toml", "resolved_scenario.json", "report.html", "errors.png",
             "alignment.png", "table.png", "comparison.png")
#: What a directory may hold before a run without being a run's: its lock, a campaign's point.json
_FOREIGN_OK = (records.LOCK, "point.json")


def read_summary(run_dir):
    """summary.json of ``run_dir`` as a dict, or None (none, or unreadable)."""
    try:
        with open(os.path.join(run_dir, SUMMARY)) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def _summary_problem(summary):
    """What makes a parsed summary.json unreadable as a run's, or None."""
    if not isinstance(summary, dict):
        return f"holds a JSON {type(summary).__name__}, not a run's summary (an object)"
    fmt = summary.get("format", FORMAT)
    if isinstance(fmt, int) and fmt > FORMAT:
        return (f"was written by a newer pyins (summary format {fmt}; this one reads up to {FORMAT}): "
                "report it with that version")
    if "variants" not in summary:
        if "max_horizontal_error_m" in summary and "ship_time_h" in summary:
            return ("is the summary of `pyins demo`, which has no report: its figures are in that file and "
                    "navigation_errors.png beside it")
        return "has no 'variants': not the summary of a `pyins run` (damaged, or another program's)"
    vs = summary["variants"]
    if not isinstance(vs, list) or not all(isinstance(v, dict) and isinstance(v.get("label"), str)
                                           and isinstance(v.get("dir"), str) for v in vs):
        return "has a damaged 'variants' list (each variant needs its label and dir)"
    for key in ("title", "scenario", "digest"):
        if not isinstance(summary.get(key), str):
            return f"has no {key!r} (damaged)"
    for v in vs:
        if not isinstance(v.get("metrics", {}), dict) or not isinstance(v.get("ticks", 0), int):
            return f"has a damaged entry for variant {v['label']!r} (metrics, ticks)"
        al = v.get("aligned")
        if al is not None and not (isinstance(al, dict) and isinstance(al.get("method"), str)
                                   and isinstance(al.get("time_s"), (int, float))
                                   and isinstance(al.get("heading_sigma_arcmin"), (int, float, type(None)))):
            return f"has a damaged entry for variant {v['label']!r} (aligned)"
    return None


def summary_for_report(run_dir):
    """summary.json of ``run_dir`` for a report, or RunDirError (exit 2)
    naming the file, what is wrong with it and what can still be done."""
    if not os.path.exists(run_dir):
        raise RunDirError(f"{run_dir}: no such directory")
    if not os.path.isdir(run_dir):
        raise RunDirError(f"{run_dir}: a file, not a run directory (`pyins report` takes the directory "
                          "`pyins run` or `pyins replay` wrote)")
    path = os.path.join(run_dir, SUMMARY)
    started = os.path.exists(os.path.join(run_dir, "resolved_scenario.json"))
    again = (f"; `pyins run SCENARIO --out {run_dir} --resume` with the scenario it ran rewrites it from "
             "the records" if started else "")
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except FileNotFoundError:
        if started:
            raise RunDirError(f"{path}: missing: the run stopped before it wrote its summary, or it was "
                              f"deleted{again}") from None
        raise RunDirError(f"{run_dir}: not a run directory (no {SUMMARY})") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise RunDirError(f"{path}: cannot be read ({exc}){again}") from None
    try:
        summary = json.loads(text)
    except ValueError as exc:
        raise RunDirError(f"{path}: damaged: not valid JSON ({exc}; {len(text)} bytes){again}") from None
    problem = _summary_problem(summary)
    if problem is not None:
        raise RunDirError(f"{path}: {problem}")
    return summary


def dir_digest(run_dir):
    """The scenario digest of the run in ``run_dir`` (from summary.json, else
    from resolved_scenario.json the way `Scenario.digest` computes it), or None."""
    s = read_summary(run_dir)
    if s is not None and s.get("digest"):
        return s["digest"]
    try:
        with open(os.path.join(run_dir, "resolved_scenario.json")) as f:
            res = json.load(f)
    except (OSError, ValueError):
        return None
    res.pop("source", None)
    blob = json.dumps(res, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(blob.encode()).hexdigest()


def _variant_dirs(run_dir):
    """The variant directories of the run in ``run_dir`` (those with records)."""
    out = []
    for name in sorted(os.listdir(run_dir)):
        d = os.path.join(run_dir, name)
        if os.path.isdir(d) and (os.path.isdir(os.path.join(d, "records"))
                                 or os.path.exists(os.path.join(d, "timeseries.npz"))):
            out.append(d)
    return out


def _same_text(path, text):
    try:
        with open(path, encoding="utf-8") as f:
            return f.read() == text
    except (OSError, UnicodeDecodeError):
        return False


def check_run_dir(scn, run_dir, force=False):
    """Refuse (RunDirError) to write ``scn`` into a directory that holds
    another scenario's run or files that are not a run's; with ``force`` a
    run of another scenario is removed first (only the files a run writes).
    Returns "new" (nothing there) or "same" (a run of this scenario)."""
    if not os.path.isdir(run_dir):
        return "new"
    entries = [e for e in os.listdir(run_dir) if e not in _FOREIGN_OK and ".tmp" not in e]
    if not entries:
        return "new"
    if entries == ["scenario.toml"] and _same_text(os.path.join(run_dir, "scenario.toml"), scn.text):
        # a run of this scenario killed as it began (an older pyins wrote this file first):
        # nothing of anyone's is lost by starting it again
        return "new"
    old = dir_digest(run_dir)
    if old is None:
        raise RunDirError(f"{run_dir}: not empty and not a pyins run directory (it holds "
                          f"{', '.join(sorted(entries)[:3])}{', ...' if len(entries) > 3 else ''}); "
                          "give an empty or new --out")
    if old == scn.digest():
        return "same"
    if not force:
        s = read_summary(run_dir) or {}
        name = s.get("scenario")
        what = (f"{name!r} with other values" if name == scn.name else repr(name) if name
                else "another scenario")
        raise RunDirError(f"{run_dir}: holds a run of {what} (digest {old[:16]}), not of this {scn.name!r} "
                          f"(digest {scn.digest()[:16]}): give another --out, or --force to replace it")
    clean_run_dir(run_dir)
    return "new"


def clean_run_dir(run_dir):
    """Remove the run in ``run_dir``: the files a run writes and its variant
    directories; anything else stays."""
    for d in _variant_dirs(run_dir):
        shutil.rmtree(d)
    for name in RUN_FILES:
        path = os.path.join(run_dir, name)
        if os.path.exists(path):
            os.remove(path)


def uses_index_sums(config):
    """True when the indexing scheme of a firmware ``config`` (a RunSpec's)
    steers by the flexible sums A_c, A_s: the flexible schemes, and a custom
    one with a flexible step. The firmware adds them up under every rotating
    scheme; only these read them."""
    scheme = config.get("index_scheme", abi.PYINS_INDEX_NONE)
    if scheme in (abi.PYINS_INDEX_FLEXIBLE_TWO, abi.PYINS_INDEX_FLEXIBLE_DERIVED):
        return True
    return scheme == abi.PYINS_INDEX_CUSTOM and any(
        move != abi.PYINS_INDEX_FIXED for _, move, _ in config.get("index_steps", ()))


def written_durations(scn):
    """label -> duration [s] of each run of ``scn`` as its file writes it,
    before any override (``--hours``, ``--set duration=``): the length its
    [paper] figures are for. {} when the text does not load on its own."""
    try:
        base = scenario.loads(scn.text, source=str(scn.source), name=getattr(scn, "_stem", scn.name))
    except (ScenarioError, ValueError, TypeError, KeyError, OSError):
        return {}
    return {spec.label: spec.duration_ticks * spec.dt for spec in base.runs()}


def variant_facts(spec, written):
    """What a report reads of a variant beside its records: its duration as
    run and as written (``written``: `written_durations`), whether its scheme
    uses the flexible sums."""
    return dict(duration_s=spec.duration_ticks * spec.dt, written_duration_s=written.get(spec.label),
                uses_index_sums=uses_index_sums(spec.config))


def written_ticks(run_dir, spec):
    """The ticks the records on disk of a variant cover (up to where it
    stopped), 0 if none."""
    outputs, _ = records.load_written(os.path.join(run_dir, slug(spec.label), "records"))
    return 0 if outputs is None else int(outputs["tick"][-1])


def load_written(run_dir, spec):
    """Every record a stopped variant wrote (past its last checkpoint too)
    beside the truth, as a FilResult, or None: what a report of a partial
    run shows."""
    outputs, plant = records.load_written(os.path.join(run_dir, slug(spec.label), "records"))
    if outputs is None:
        return None
    truth = sim.truth_at(spec.motion, np.asarray(outputs["tick"]), dt=spec.dt)
    return records.FilResult(outputs=outputs, plant=plant, truth=truth, dt=spec.dt)


def scenario_of(run_dir, summary):
    """The Scenario a run directory was written from (with its overrides),
    rebuilt from summary.json's ``scenario_data`` (or scenario.toml when it
    has the run's digest), or None."""
    digest = summary.get("digest")
    path = os.path.join(run_dir, "scenario.toml")
    text = ""
    if os.path.exists(path):
        with open(path) as f:
            text = f.read()
    tries = []
    if summary.get("scenario_data") is not None:
        tries.append(lambda: scenario.Scenario(text, summary["scenario_data"], summary.get("source") or path,
                                               summary.get("scenario_stem") or summary.get("scenario")))
    if text:
        tries.append(lambda: scenario.loads(text, source=path, name=summary.get("scenario")))
    for make in tries:
        try:
            scn = make()
        except (ScenarioError, ValueError, TypeError, KeyError, OSError):
            continue
        if digest is None or scn.digest() == digest:
            return scn
    return None


def write_summary(run_dir, summary):
    """summary.json of ``run_dir``, written atomically."""
    # default=str: a TOML value JSON has no type for (a date) leaves scenario_data unusable, not the summary
    records.write_atomic(os.path.join(run_dir, SUMMARY), json.dumps(summary, indent=2, default=str))


class hold_interrupts:  # noqa: N801 - used as a context manager
    """Ctrl-C held off while a block that must not be cut writes (a summary,
    the lock and the first files of a run): ``defer=True`` raises the
    KeyboardInterrupt when the block ends, ``defer=False`` (already
    stopping) drops it. Only in the main thread (signal handlers can be set
    nowhere else: a Dask worker's thread runs without it)."""

    def __init__(self, defer=False):
        self.defer, self.old, self.caught, self.held = defer, None, False, False

    def _catch(self, signum, frame):
        self.caught = True

    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            self.old, self.held = signal.signal(signal.SIGINT, self._catch), True
        return self

    @property
    def interrupted(self):
        """A Ctrl-C came during the block that the handler before it would have raised."""
        return self.caught and callable(self.old)

    def __exit__(self, exc_type, *exc):
        if not self.held:
            return
        # None: a handler set outside Python, which signal.signal cannot put back; the default then
        signal.signal(signal.SIGINT, self.old if self.old is not None else signal.default_int_handler)
        if self.defer and self.interrupted and exc_type is None:
            self.old(signal.SIGINT, None)      # the handler it had: KeyboardInterrupt, as Ctrl-C gives
