"""Running: a scenario into a run directory (what ``pyins run`` does) and
one run of a scenario. A recorded log through the firmware (``pyins
replay``) is `pyins.replay`.

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
    <variant>/timeseries.csv   the errors, at most CSV_MAX_ROWS rows
    *.png, report.html         written by pyins.report
    pyins.lock                 held while the directory is written

Runs are checkpointed (every CHECKPOINT_S of ship time): ``execute(...,
resume=True)`` after a kill or Ctrl-C continues each unfinished variant from
its last checkpoint and skips the finished ones. summary.json is written at
the start (``"state": "running"``), after every variant and at the end,
atomically; Ctrl-C writes it at once (``"complete": false``, ``"state":
"interrupted"``) and leaves the stopped variant's metrics to the report
(`pyins.report.run.load` reads its records on disk), so a stop takes under
a second. A directory being written is locked (`pyins.records.lock_dir`);
one holding another scenario's run is refused (`check_run_dir`).

Every entry point takes ``engine``: "native" (the compiled firmware and
plant) or "reference" (their NumPy mirrors, `pyins.engine`).
"""
import hashlib
import json
import os
import re
import shutil
import signal
import threading
import time

import numpy as np

from pyins import engine as engines
from pyins import fil, metrics, native, records, scenario, sim
from pyins.metrics import group_metrics
from pyins.progress import phase
from pyins.reference import abi
from pyins.records import CSV_MAX_ROWS
from pyins.units import ARCMIN_TO_RAD, ScenarioError

__all__ = ["execute", "run", "load_variant", "load_written", "paper_rows", "slug",
           "group_metrics", "check_run_dir", "clean_run_dir", "dir_digest", "read_summary", "scenario_of",
           "written_ticks", "written_durations", "not_judged", "span", "uses_index_sums", "variant_facts",
           "hold_interrupts", "RunDirError", "CHECKPOINT_S", "CSV_MAX_ROWS", "SUMMARY", "RUN_FILES"]

CHECKPOINT_S = 1800.0          # ship time between checkpoints: 30 min = 180,000 ticks
SUMMARY = "summary.json"


def slug(label):
    """A directory name for a variant label."""
    s = re.sub(r"[^A-Za-z0-9._-]+", "_", label).strip("_")
    return s or "run"


def run(spec, engine="native", **kwargs):
    """One run of a scenario (a pyins.scenario.RunSpec) through the firmware
    in the loop; ``kwargs`` go to ``fil.run_fil`` (record_dir, resume,
    progress, ...). Returns a records.FilResult."""
    return fil.run_fil(spec.motion, spec.duration_ticks, config=spec.config, errors=spec.errors,
                       seed=spec.seed, table=spec.table, every=spec.every, dt=spec.dt, engine=engine,
                       **kwargs)


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


def _entry(spec, written):
    return dict(label=spec.label, dir=slug(spec.label), ticks=spec.duration_ticks, ticks_done=0,
                complete=False, wall_s=0.0, metrics={}, **variant_facts(spec, written))


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


def _write_summary(run_dir, summary):
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


def execute(scn, run_dir, progress=None, resume=False, log=None, engine="native", force=False,
            notice=None):
    """Run every variant of ``scn`` (a pyins.scenario.Scenario) into
    ``run_dir``; returns the summary dict (also written to summary.json).

    ``progress(label)`` returns a callable progress(done, total) per variant
    (e.g. ``lambda label: TextProgress()``; one with a ``phase`` method, as
    TextProgress has, also gets a line for the variant's metrics and time
    series); ``log(text)`` gets one line per
    finished variant, ``notice(text)`` the takeover of a stale lock.

    The directory is locked while written (`pyins.records.lock_dir`: a
    second writer gets LockedError naming the holder). A directory holding
    another scenario's run is refused (RunDirError) unless ``force``.
    summary.json is written at the start (``"state": "running"``), after
    every variant and at the end, each time atomically, so a kill leaves
    one that `pyins report` reads. KeyboardInterrupt is caught anywhere in
    the variants: the summary of what was done is written at once
    (``"complete": false``, ``"state": "interrupted"``; the stopped
    variant's ticks done, its metrics left to the report) and the interrupt
    re-raised.
    """
    # the guarded prefix
    engines.check(engine)
    # the lock and the first files together, Ctrl-C held off: a run that started has a summary
    lock = None
    try:
        with hold_interrupts() as held:
            lock = records.lock_dir(run_dir, notice=notice)
            summary, specs, resume = _start(scn, run_dir, resume, engine, force)
        return _variants(summary, specs, run_dir, progress, resume, log, engine,
                         KeyboardInterrupt() if held.interrupted else None)
    finally:
        if lock is not None:
            with hold_interrupts():          # a second Ctrl-C must not leave the lock file behind
                lock.release()


def _start(scn, run_dir, resume, engine, force):
    # 1. the run directory: refused if another's; the scenario as written and as resolved
    if check_run_dir(scn, run_dir, force) == "new":
        resume = False
    src = scn.source if scn.source and os.path.exists(str(scn.source)) else None
    # the resolved scenario first: it names the run (its digest), so a kill after it
    # leaves a directory a resume recognises
    records.write_atomic(os.path.join(run_dir, "resolved_scenario.json"), scn.resolved_json())
    records.write_atomic(os.path.join(run_dir, "scenario.toml"), scn.text)
    specs = list(scn.runs())
    written = written_durations(scn)
    summary = dict(scenario=scn.name, title=scn.title, source=str(scn.source) if src else scn.source,
                   digest=scn.digest(), core_version=native.version(), paper=scn.paper,
                   variants=[_entry(spec, written) for spec in specs], complete=False, state="running",
                   scenario_data=scn.data, scenario_stem=getattr(scn, "_stem", scn.name))
    if engine != "native":
        summary["engine"] = engine
    _write_summary(run_dir, summary)
    return summary, specs, resume


def _variants(summary, specs, run_dir, progress, resume, log, engine, interrupted):
    # 2. each variant: the checkpointed run, its records, metrics and time series
    for i, spec in enumerate(specs):
        vdir = os.path.join(run_dir, slug(spec.label))
        entry = summary["variants"][i]
        t0 = time.perf_counter()
        try:
            if interrupted is not None:
                raise interrupted
            if not resume and os.path.exists(vdir):
                shutil.rmtree(vdir)
            os.makedirs(vdir, exist_ok=True)
            for name in ("timeseries.npz", "timeseries.csv"):      # derived: rewritten at the end
                if os.path.exists(os.path.join(vdir, name)):
                    os.remove(os.path.join(vdir, name))
            checkpoint = int(round(CHECKPOINT_S / spec.dt))
            bar = progress(spec.label) if progress else None
            run(spec, engine, record_dir=os.path.join(vdir, "records"), resume=resume,
                checkpoint_ticks=checkpoint, chunk_ticks=min(500_000, checkpoint), progress=bar)
            with phase(bar, "metrics and time series"):       # a line: seconds for a 72 h run
                res, info = load_variant(run_dir, spec)
                mm = metrics.run_metrics(spec, res) if res is not None else {}
                if res is not None and len(res.outputs):
                    records.write_timeseries(vdir, res)
            entry.update(wall_s=time.perf_counter() - t0, ticks_done=int(info["ticks_done"]) if info else 0,
                         complete=bool(info and info.get("complete")), metrics=mm)
        except KeyboardInterrupt as exc:
            # at once: the ticks on disk; the metrics of a stopped variant are the report's
            interrupted = interrupted or exc.with_traceback(None)
            with hold_interrupts():
                entry.update(wall_s=time.perf_counter() - t0, complete=False, metrics={},
                             ticks_done=written_ticks(run_dir, spec) if os.path.isdir(vdir) else 0)
            continue
        if log is not None:
            log(f"  {spec.label}: {entry['ticks_done'] * spec.dt / 3600:.3g} h, "
                f"max horizontal error {mm.get('horizontal_error_max', float('nan')):.1f} m, "
                f"heading error {mm.get('heading_error_final', float('nan')) / ARCMIN_TO_RAD:.3g}' "
                f"({entry['wall_s']:.1f} s)")
        try:
            with hold_interrupts(defer=True):
                _write_summary(run_dir, summary)
        except KeyboardInterrupt as exc:       # during the write (raised after it) or just before
            interrupted = exc.with_traceback(None)

    # 3. the summary, over the variants
    with hold_interrupts(defer=interrupted is None):
        summary["group_metrics"] = group_metrics(summary["variants"])
        summary["complete"] = all(v["complete"] for v in summary["variants"])
        summary["state"] = "interrupted" if interrupted is not None else (
            "complete" if summary["complete"] else "partial")
        _write_summary(run_dir, summary)
    if interrupted is not None:
        raise interrupted
    return summary


def span(seconds):
    """A duration as a report writes it: 6 h, 12 min, 150 s."""
    if seconds >= 3600:
        return f"{seconds / 3600:.3g} h"
    if seconds >= 60:
        return f"{seconds / 60:.3g} min"
    return f"{seconds:.3g} s"


def not_judged(variants):
    """Why the paper's figures cannot be judged on these summary entries
    (one variant, or all of a group metric), or "" when they can: a variant
    that stopped (its metrics cover part of the run), or one run for another
    length than the scenario file gives it (``--hours``, ``--set duration``):
    the paper's figures are for the run as written (a final error at 6 h is
    not the error at 72 h, nor the largest over 6 h the largest over 72 h)."""
    for v in variants:
        dur = v.get("duration_s")
        if not v.get("complete"):
            if dur and v.get("ticks"):
                return (f"not judged: the run stopped at {span(dur * v.get('ticks_done', 0) / v['ticks'])}"
                        f" of {span(dur)}")
            return "not judged: the run stopped before its end"
        written = v.get("written_duration_s")
        if dur is not None and written is not None and abs(dur - written) > 1e-6 * max(written, 1.0):
            how = "shortened" if dur < written else "lengthened"
            return (f"not judged: run {how} to {span(dur)}; the paper's figure is for the "
                    f"{span(written)} the scenario runs")
    return ""


def paper_rows(summary):
    """The paper's figures beside ours, a dict per row: metric, variant,
    relation, paper (value), unit, ours (our value in the paper's unit, None
    if none), verdict ("within"/"above" a bound, "xR" the ratio to a value,
    or "not judged: why" for a partial or re-timed run: `not_judged`),
    judged (bool), note. For the report and the CLI."""
    rows = []
    paper = summary.get("paper") or {}
    for fig in paper.get("figures", []):
        metric = fig["metric"]
        targets = [v for v in summary["variants"] if fig.get("variant") in (None, v["label"])]
        if metric in summary.get("group_metrics", {}):
            ours = [("all", summary["group_metrics"][metric], summary["variants"])]
        else:
            ours = [(v["label"], v["metrics"].get(metric), [v]) for v in targets]
        for label, val, over in ours:
            mine = None if val is None else scenario.in_figure_unit(val, fig)
            why = not_judged(over)
            verdict = why
            if why or mine is None:
                pass
            elif fig["relation"] == "<":
                verdict = "within" if mine < fig["value"] else "above"
            elif fig["value"]:
                verdict = f"x{mine / fig['value']:.2f}"
            rows.append(dict(metric=metric, variant=label, relation=fig["relation"], paper=fig["value"],
                             unit=fig["unit"], ours=mine, verdict=verdict, judged=not why and mine is not None,
                             note=fig.get("note", "")))
    return rows
