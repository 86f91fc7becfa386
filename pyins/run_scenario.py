"""Running a scenario: one run of it through the firmware in the loop
(`run`) and every variant into a run directory (`execute`, what ``pyins
run`` does). The directory's layout and reading it back are
`pyins.rundir`; a recorded log through the firmware (``pyins replay``) is
`pyins.replay`.

Runs are checkpointed (every CHECKPOINT_S of ship time, at most one every
CHECKPOINT_WALL_S of wall time): ``execute(...,
resume=True)`` after a kill or Ctrl-C continues each unfinished variant from
its last checkpoint and skips the finished ones. summary.json is written at
the start (``"state": "running"``), after every variant and at the end,
atomically; Ctrl-C writes it at once (``"complete": false``, ``"state":
"interrupted"``) and leaves the stopped variant's metrics to the report
(`pyins.report.run.load` reads its records on disk), so a stop takes under
a second. A directory being written is locked (`pyins.records.lock_dir`);
one holding another scenario's run is refused (`pyins.rundir.check_run_dir`).

Every entry point takes ``engine``: "native" (the compiled firmware and
plant) or "reference" (their NumPy mirrors, `pyins.engine`).
"""
import os
import shutil
import time

from pyins import engine as engines
from pyins import fil, records
from pyins.metrics import group_metrics
from pyins.progress import phase
from pyins.rundir import (FORMAT, RunDirError, check_run_dir, read_summary, hold_interrupts, slug, variant_facts, write_summary,
                          written_durations, written_ticks)
from pyins.units import ARCMIN_TO_RAD

__all__ = ["execute", "run", "CHECKPOINT_S", "CHECKPOINT_WALL_S"]

CHECKPOINT_S = 1800.0          # ship time between checkpoints: 30 min = 180,000 ticks
#: Wall time at least between two checkpoints of a variant: a 72 h run (3 s) wrote 130
#: checkpoints, two fsyncs each, 8 % of its time; a kill now loses at most this much work.
CHECKPOINT_WALL_S = 2.0


def run(spec, engine="native", **kwargs):
    """One run of a scenario (a pyins.scenario.RunSpec) through the firmware
    in the loop; ``kwargs`` go to ``fil.run_fil`` (record_dir, resume,
    progress, ...). Returns a records.FilResult."""
    return fil.run_fil(spec.motion, spec.duration_ticks, config=spec.config, errors=spec.errors,
                       seed=spec.seed, table=spec.table, every=spec.every, dt=spec.dt, engine=engine,
                       refs=spec.refs, avail_tick=spec.avail_tick, **kwargs)


def _entry(spec, written):
    return dict(label=spec.label, dir=slug(spec.label), ticks=spec.duration_ticks, ticks_done=0,
                complete=False, wall_s=0.0, metrics={}, **variant_facts(spec, written))


def execute(scn, run_dir, progress=None, resume=False, log=None, engine="native", force=False,
            notice=None, started=None):
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
        if started is not None:             # the directory taken: the caller's title line, after any refusal
            started()
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
    old = read_summary(run_dir) if resume else None
    if old is not None and old.get("engine", "native") != engine:
        # refused before anything is written: the records on disk are the other engine's
        raise RunDirError(f"{run_dir}: holds a run through --engine {old.get('engine', 'native')}; a resume "
                          f"with --engine {engine} would be another run: resume with --engine "
                          f"{old.get('engine', 'native')}, or run without --resume (it reruns every "
                          "variant), or give another --out")
    src = scn.source if scn.source and os.path.exists(str(scn.source)) else None
    # the resolved scenario first: it names the run (its digest), so a kill after it
    # leaves a directory a resume recognises
    records.write_atomic(os.path.join(run_dir, "resolved_scenario.json"), scn.resolved_json())
    records.write_atomic(os.path.join(run_dir, "scenario.toml"), scn.text)
    specs = list(scn.runs())
    written = written_durations(scn)
    summary = dict(scenario=scn.name, title=scn.title, source=str(scn.source) if src else scn.source,
                   digest=scn.digest(), core_version=engines.core_version(), paper=scn.paper,
                   variants=[_entry(spec, written) for spec in specs], complete=False, state="running",
                   scenario_data=scn.data, scenario_stem=getattr(scn, "_stem", scn.name), format=FORMAT,
                   notes=list(getattr(scn, "notes", [])))
    if engine != "native":
        summary["engine"] = engine
    write_summary(run_dir, summary)
    return summary, specs, resume


def _variants(summary, specs, run_dir, progress, resume, log, engine, interrupted):
    # 2. each variant: the checkpointed run, its records, metrics and time series
    # a Ctrl-C between the variants' blocks (the loop's head, before the last write) stops
    # the run here too: the summary below is written whatever line it came at
    last = hold_interrupts(defer=True)
    try:
        for i, spec in enumerate(specs):
            vdir = os.path.join(run_dir, slug(spec.label))
            entry = summary["variants"][i]
            t0 = time.perf_counter()
            finished = False          # the variant's time series written: it is done, whatever comes after
            try:
                if interrupted is not None:
                    raise interrupted
                if not resume and os.path.exists(vdir):
                    shutil.rmtree(vdir)
                os.makedirs(vdir, exist_ok=True)
                # a resumed variant's time series (derived) are rewritten, atomically, when it ends: a
                # resume refused or stopped leaves a finished variant's as they were
                checkpoint = int(round(CHECKPOINT_S / spec.dt))
                bar = progress(spec.label) if progress else None
                run(spec, engine, record_dir=os.path.join(vdir, "records"), resume=resume,
                    checkpoint_ticks=checkpoint, chunk_ticks=min(fil.CHUNK_TICKS, checkpoint), progress=bar,
                    keep_result=False, checkpoint_wall_s=CHECKPOINT_WALL_S)
                with phase(bar, "metrics and time series"):       # a line: seconds for a 72 h run
                    # read back in chunks (bounded memory at any record rate); the time series
                    # and "finished" together
                    with hold_interrupts(defer=True):
                        mm, al, info = records.score_variant(vdir, spec)
                        finished = True
                entry.update(wall_s=time.perf_counter() - t0, ticks_done=int(info["ticks_done"]) if info else 0,
                             complete=bool(info and info.get("complete")), metrics=mm)
                if al is not None:
                    entry["aligned"] = al
            except KeyboardInterrupt as exc:
                # at once: the ticks on disk; the metrics of a stopped variant are the report's
                interrupted = interrupted or exc.with_traceback(None)
                with hold_interrupts():
                    if finished:                 # it ended as the Ctrl-C came: kept whole, as done
                        entry.update(wall_s=time.perf_counter() - t0, metrics=mm, complete=bool(
                            info and info.get("complete")), ticks_done=int(info["ticks_done"]) if info else 0)
                    else:
                        entry.update(wall_s=time.perf_counter() - t0, complete=False, metrics={},
                                     ticks_done=written_ticks(run_dir, spec) if os.path.isdir(vdir) else 0)
                if not finished:
                    continue
            try:
                if log is not None and interrupted is None:
                    log(f"  {spec.label}: {entry['ticks_done'] * spec.dt / 3600:.3g} h, "
                        + (f"max horizontal error {mm['horizontal_error_max']:.1f} m, "
                           if "horizontal_error_max" in mm else "alignment only, ")
                        + f"heading error {mm.get('heading_error_final', float('nan')) / ARCMIN_TO_RAD:.3g}' "
                        f"({entry['wall_s']:.1f} s)")
                with hold_interrupts(defer=True):
                    write_summary(run_dir, summary)
            except KeyboardInterrupt as exc:       # during the write (raised after it) or just before
                interrupted = exc.with_traceback(None)
        last.__enter__()
    except KeyboardInterrupt as exc:
        interrupted = interrupted or exc.with_traceback(None)
        last.__enter__()

    # 3. the summary, over the variants (Ctrl-C held off since the loop's end)
    try:
        summary["group_metrics"] = group_metrics(summary["variants"])
        summary["complete"] = all(v["complete"] for v in summary["variants"])
        summary["state"] = "interrupted" if interrupted is not None else (
            "complete" if summary["complete"] else "partial")
        write_summary(run_dir, summary)
    finally:
        last.defer = interrupted is None
        try:
            last.__exit__(None, None, None)
        except KeyboardInterrupt as exc:
            interrupted = exc.with_traceback(None)
    if interrupted is not None:
        raise interrupted
    return summary
