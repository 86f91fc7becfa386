"""Running a campaign: its missing runs, on a local process pool or a Dask cluster.

Runs are content addressed: point ``p`` runs with `pyins.run_scenario.execute` into
``OUT/<p.dir>`` = ``OUT/runs/<digest[:16]>``, so a campaign that is run
again (after a kill, a Ctrl-C, or with more seeds) runs only what has no
complete summary.json of that digest (`pending`). Each run writes only its
own directory, its summary.json last and atomically, so a kill loses at
most the runs in flight.

Execution: a local process pool using every core (``workers``), or a Dask
distributed cluster (``scheduler``: its address, or a ``distributed.Client``)
whose workers see ``out_dir`` at the same path (one machine, or a shared
file system) and have the same pyins installed; dask is imported only then.

`run_campaign`:
1. the runs with no complete summary.json (`pending`), and campaign.json
   marked "running";
2. every missing run (`_run_point`: rebuild the scenario from the base's data
   and the overrides, check its digest, run it), locally or on Dask, each
   recorded as it finishes or fails;
3. the aggregates (`pyins.campaign.aggregate`), and campaign.json with what
   was computed, skipped or failed.

The campaign directory is locked while a campaign runs into it
(`pyins.records.lock_dir`): a second campaign into the same directory is
refused with the holder's pid, host and start time. Ctrl-C (SIGINT to the
whole process group, as a terminal sends it, or to this process alone)
stops the campaign within a few seconds: no further run is started, the
runs in flight are interrupted (each writes its partial summary and keeps
its checkpoint), the finished runs are kept, the aggregates of what
finished are written (campaign.json ``"complete": false``, its
``execution.interrupted`` true; no plots) and `CampaignInterrupted` (a
KeyboardInterrupt) is raised. Running the campaign again resumes it.
"""
import copy
import json
import os
import signal
import time
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool

from pyins import records, run_scenario, rundir
from pyins import scenario as scenario_mod
from pyins.campaign.aggregate import aggregate, plan, read_summary, write_json

__all__ = ["CampaignError", "CampaignInterrupted", "run_campaign", "pending", "DASK_CONNECT_TIMEOUT",
           "STOP_GRACE_S", "check_scheduler_address"]

DASK_CONNECT_TIMEOUT = "20s"   #: how long to wait for a Dask scheduler
#: After Ctrl-C: how long the runs in flight get to write their partial
#: summaries (each takes well under a second) before the pool is killed
STOP_GRACE_S = (1.0, 3.0)      # (wait for the terminal's own SIGINT, then after forwarding it)


class CampaignError(RuntimeError):
    """A campaign that cannot run (no dask, no scheduler) or whose runs
    failed (``result``: the campaign.json written with what did finish)."""

    def __init__(self, message, result=None):
        super().__init__(message)
        self.result = result


#: The address schemes dask.distributed connects by (``inproc`` is one process's own)
DASK_SCHEMES = ("tcp", "tls", "ws", "wss", "ucx", "inproc")


def check_scheduler_address(address):
    """Refuse a Dask scheduler address that cannot name one (CampaignError
    naming what is wrong), before anything is written or dask imported: "0"
    or "host" with no port would otherwise fail only after dask's import, or
    wait out DASK_CONNECT_TIMEOUT. Accepts ``[scheme://]host:port`` with a
    scheme of DASK_SCHEMES and a port 1..65535 (``inproc://`` as it is)."""
    text = str(address).strip()
    scheme, sep, rest = text.partition("://")
    if not sep:
        scheme, rest = "tcp", text
    if scheme not in DASK_SCHEMES:
        raise CampaignError(f"--scheduler {address}: the scheme {scheme}:// is not one dask connects by "
                            f"({', '.join(s + '://' for s in DASK_SCHEMES)})")
    if scheme == "inproc":
        return
    host, colon, port = rest.rstrip("/").rpartition(":")
    if not colon or not host or not port.isdigit() or not 1 <= int(port) <= 65535:
        raise CampaignError(f"--scheduler {address}: not a scheduler address; give host:port with a port "
                            f"of 1 to 65535, e.g. tcp://127.0.0.1:8786")


class CampaignInterrupted(KeyboardInterrupt):
    """Ctrl-C during a campaign; ``result``: the campaign.json written with
    what had finished (``execution``: computed, interrupted, not started)."""

    def __init__(self, result=None):
        super().__init__("campaign interrupted")
        self.result = result


def _is_done(run_dir, digest):
    s = read_summary(run_dir)
    return s is not None and s.get("complete") is True and s.get("digest") == digest


def _run_point(task):
    """Run one point into its run directory (in a pool process or on a Dask
    worker): rebuild the scenario from the base's data and the overrides,
    check its digest, `pyins.run_scenario.execute` it (resume=True: an earlier
    killed attempt continues from its checkpoint). Returns
    {"digest", "wall_s", "summary"}."""
    t0 = time.perf_counter()
    base = scenario_mod.Scenario(task["text"], copy.deepcopy(task["data"]), task["source"], task["stem"])
    scn = base.with_overrides(task["overrides"])
    digest = scn.digest()
    if digest != task["digest"]:
        raise CampaignError(f"this worker's pyins resolves the scenario differently (digest "
                            f"{digest[:16]}, not {task['digest'][:16]}): install the same pyins on "
                            f"every worker")
    run_dir = task["run_dir"]
    point_json = os.path.join(run_dir, "point.json")
    with rundir.hold_interrupts(defer=True):      # point.json whole or not at all
        os.makedirs(run_dir, exist_ok=True)
        if os.path.exists(point_json):
            with open(point_json) as f:
                old = json.load(f)
            if old.get("digest") != digest:
                raise CampaignError(f"{run_dir} belongs to another scenario (digest {old.get('digest')})")
        else:
            write_json(point_json, {"digest": digest, "base": base.name, "base_source": str(task["source"]),
                                    "overrides": task["overrides"]})
    notices = []           # a stale lock taken over (a killed earlier attempt), told by run_campaign
    try:
        summary = run_scenario.execute(scn, run_dir, resume=True, notice=notices.append)
    except ValueError as exc:
        if "checkpoint belongs to another run" not in str(exc):
            raise
        summary = run_scenario.execute(scn, run_dir, resume=False)   # a checkpoint of an older pyins
    return {"digest": digest, "wall_s": time.perf_counter() - t0, "summary": summary, "notices": notices}


def _pool_init():
    """A pool worker ignores Ctrl-C while idle (a KeyboardInterrupt there
    would kill it outside any task); `_pool_point` takes it during a run."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _pool_point(task):
    """`_run_point` in a pool worker: Ctrl-C interrupts the run (which then
    writes its partial summary), not the idle worker."""
    signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        return _run_point(task)
    finally:
        signal.signal(signal.SIGINT, signal.SIG_IGN)


def pending(camp, out_dir):
    """The digests (in point order, each once) of the runs of ``camp`` that
    have no complete summary.json in ``out_dir``, and how many runs it has."""
    seen, todo = set(), []
    for p in camp.points:
        if p.digest in seen:
            continue
        seen.add(p.digest)
        if not _is_done(os.path.join(out_dir, p.dir), p.digest):
            todo.append(p.digest)
    return todo, len(seen)


def _tasks(camp, out_dir, digests):
    by_digest = {}
    for p in camp.points:
        by_digest.setdefault(p.digest, p)
    data = camp.base.data
    out = []
    for d in digests:
        p = by_digest[d]
        out.append({"text": camp.base.text, "data": data, "source": camp.base.source,
                    "stem": getattr(camp.base, "_stem", camp.base.name), "overrides": p.overrides,
                    "digest": d, "run_dir": os.path.abspath(os.path.join(out_dir, p.dir)),
                    "label": p.label(camp.labels)})
    return out


def _first_line(exc):
    text = f"{type(exc).__name__}: {exc}"
    return text.splitlines()[0] if text else type(exc).__name__


def _run_local(tasks, workers, on_done, on_stopped):
    """Run ``tasks`` in this process (workers == 1) or on a pool of
    ``workers`` processes, at most ``workers`` at a time (so that nothing
    waits in the pool's queue to start after a Ctrl-C)."""
    if workers == 1:
        for t in tasks:
            try:
                on_done(t, _run_point(t), None)
            except KeyboardInterrupt:
                on_stopped(t)
                raise
            except Exception as exc:             # noqa: BLE001 - recorded, the others go on
                on_done(t, None, exc)
        return "local, in process"
    ex = ProcessPoolExecutor(max_workers=workers, initializer=_pool_init)
    waiting = iter(tasks)
    running = {}
    try:
        for t in waiting:
            running[ex.submit(_pool_point, t)] = t
            if len(running) >= workers:
                break
        while running:
            done, _ = wait(running, return_when=FIRST_COMPLETED)
            for f in done:
                # a Ctrl-C waits until the run is told (a run taken off
                # `running` and not yet told would be finished on disk and
                # missing from the counts: the user's Ctrl-C tends to come
                # just as a run ends)
                with rundir.hold_interrupts(defer=True):
                    t = running.pop(f)
                    exc = f.exception()
                    if isinstance(exc, KeyboardInterrupt):   # the terminal's Ctrl-C reached the worker first
                        on_stopped(t)
                        raise KeyboardInterrupt
                    on_done(t, None if exc else f.result(), exc)
                    nxt = next(waiting, None)
                    if nxt is not None:
                        running[ex.submit(_pool_point, nxt)] = nxt
    except KeyboardInterrupt:
        with rundir.hold_interrupts():
            _stop_pool(ex, running, on_done, on_stopped)
        raise
    except BaseException:
        ex.shutdown(wait=False, cancel_futures=True)
        raise
    ex.shutdown(wait=True)
    return f"local process pool, {workers} worker(s)"


def _stop_pool(ex, running, on_done, on_stopped):
    """After Ctrl-C: let the runs in flight write their partial summaries
    (a terminal's SIGINT reached them too; else it is forwarded), keep any
    that finished meanwhile, then end the pool (killing what still runs)."""
    _, left = wait(running, timeout=STOP_GRACE_S[0])
    if left:
        # concurrent.futures offers no public list of its worker processes
        for pid in list(getattr(ex, "_processes", None) or {}):
            try:
                os.kill(pid, signal.SIGINT)
            except OSError:
                pass
        _, left = wait(left, timeout=STOP_GRACE_S[1])
    if left:
        for proc in list((getattr(ex, "_processes", None) or {}).values()):
            proc.kill()
            proc.join(timeout=5.0)
    ex.shutdown(wait=not left, cancel_futures=True)
    # told after the workers are gone, so that what is on disk is final: a run
    # that finished as the Ctrl-C came counts as computed (on_stopped reads its
    # summary), and a worker killed in its run leaves no stale lock behind
    for f, t in running.items():
        exc = None if f.cancelled() or not f.done() else f.exception()
        if f.done() and not f.cancelled() and not isinstance(exc, (KeyboardInterrupt, BrokenProcessPool)):
            on_done(t, None if exc else f.result(), exc)
        else:                       # stopped, or its worker killed (the pool is then broken)
            on_stopped(t)
        records.drop_stale_lock(t["run_dir"])


def _run_dask(tasks, scheduler, on_done, on_stopped):
    try:
        import distributed
    except ImportError:
        raise CampaignError("running on a Dask cluster needs dask.distributed: "
                            "pip install 'pyins[campaign]' (or \"dask[distributed]\")") from None
    own = not isinstance(scheduler, distributed.Client)
    if own:
        try:
            client = distributed.Client(scheduler, timeout=DASK_CONNECT_TIMEOUT)
        except (OSError, TimeoutError, ValueError) as exc:
            raise CampaignError(f"cannot connect to the Dask scheduler {scheduler}: "
                                f"{_first_line(exc)}") from None
    else:
        client = scheduler
    try:
        address = client.scheduler.address
        futs = client.map(_run_point, tasks, pure=False)
        index = {f.key: t for f, t in zip(futs, tasks)}
        told = set()
        try:
            for f in distributed.as_completed(futs):
                with rundir.hold_interrupts(defer=True):   # told whole, as in _run_local
                    if f.status == "error":
                        on_done(index[f.key], None, f.exception())
                    else:
                        on_done(index[f.key], f.result(), None)
                    told.add(f.key)
                    f.release()
        except BaseException:
            client.cancel(futs)
            for f in futs:
                # every run not told, whether it ended or not: on_stopped
                # counts one that finished on disk as computed
                if f.key not in told:
                    on_stopped(index[f.key])
            raise
    finally:
        if own:
            client.close()
    return f"dask {address}"


def run_campaign(camp, out_dir, workers=None, scheduler=None, progress=None, log=None, plots=True,
                 notice=None):
    """Run the campaign's missing runs into ``out_dir`` and aggregate.

    ``workers``: processes of the local pool (default os.cpu_count(); 1 runs
    in this process); ``scheduler``: a Dask scheduler address
    ("tcp://host:8786") or a ``distributed.Client``, instead of the local
    pool. ``progress(done, total, skipped)`` is called once before running
    (done = skipped: the runs found complete) and after every run;
    ``log(line)`` gets a line per finished or failed run, ``notice(line)``
    the takeover of a stale lock. Returns the campaign.json dict (its
    ``execution`` entry says what was computed, skipped or failed, and the
    wall time: everything else is the same whichever way and in however
    many pieces the campaign ran). If runs failed, every result is still
    written and CampaignError is raised (``.result``: that dict). Ctrl-C:
    the partial aggregates are written and CampaignInterrupted raised.
    ``out_dir`` is locked while the campaign runs (LockedError names the
    holder).
    """
    t0 = time.perf_counter()
    out_dir = str(out_dir)
    if scheduler is not None and isinstance(scheduler, str):
        check_scheduler_address(scheduler)
    notes = []                  # every notice told is kept in campaign.json (execution.notes)

    def noting(text):
        notes.append(text)
        if notice is not None:
            notice(text)
    lock = records.lock_dir(out_dir, what="campaign directory", notice=noting)
    try:
        return _run_campaign(camp, out_dir, workers, scheduler, progress, log, plots, noting, t0, notes)
    finally:
        lock.release()


def _run_campaign(camp, out_dir, workers, scheduler, progress, log, plots, notice, t0, notes):
    os.makedirs(os.path.join(out_dir, "runs"), exist_ok=True)
    # 1. what is missing
    todo, total = pending(camp, out_dir)
    skipped = total - len(todo)
    write_json(os.path.join(out_dir, "campaign.json"),
               dict(plan(camp), complete=False, note="running: aggregates are written at the end"))
    if progress:
        progress(skipped, total, skipped)
    state = {"done": skipped, "computed": 0, "failed": [], "interrupted": []}
    tasks = _tasks(camp, out_dir, todo)

    def on_done(task, result, exc):
        state["done"] += 1
        if exc is not None:
            state["failed"].append({"digest": task["digest"], "label": task["label"],
                                    "error": _first_line(exc)})
            if log:
                log(f"  FAILED {task['label']}: {_first_line(exc)}")
        else:
            state["computed"] += 1
            for text in result.get("notices", ()) if notice else ():
                notice(text)
            if not _is_done(task["run_dir"], task["digest"]):
                # a Dask worker without the shared file system: keep its summary here
                os.makedirs(task["run_dir"], exist_ok=True)
                write_json(os.path.join(task["run_dir"], "summary.json"), result["summary"])
            if log:
                log(f"  {task['label']}: {result['wall_s']:.2f} s")
        if progress:
            progress(state["done"], total, skipped)

    def on_stopped(task):
        if _is_done(task["run_dir"], task["digest"]):     # it finished as the Ctrl-C came
            state["done"] += 1
            state["computed"] += 1
        else:
            state["interrupted"].append({"digest": task["digest"], "label": task["label"]})

    # 2. run it, locally or on Dask
    how, interrupted = "nothing to run", False
    try:
        if tasks:
            if scheduler is not None:
                how = _run_dask(tasks, scheduler, on_done, on_stopped)
            else:
                n = workers or os.cpu_count() or 1
                how = _run_local(tasks, max(1, min(n, len(tasks))), on_done, on_stopped)
    except KeyboardInterrupt:
        interrupted = True
        how = "interrupted (Ctrl-C)"
    # 3. the aggregates (of what finished, without plots, after a Ctrl-C)
    with rundir.hold_interrupts():
        result = aggregate(camp, out_dir, plots=plots and not interrupted)
        ended = state["computed"] + len(state["failed"]) + len(state["interrupted"])
        result["execution"] = {"scheduler": how, "runs": total, "computed": state["computed"],
                               "skipped": skipped, "failed": state["failed"],
                               "wall_s": time.perf_counter() - t0, "notes": list(notes)}
        if interrupted:
            result["execution"].update(interrupted=True, stopped=state["interrupted"],
                                       not_started=len(tasks) - ended)
        write_json(os.path.join(out_dir, "campaign.json"), result)
    if interrupted:
        raise CampaignInterrupted(result)
    if state["failed"]:
        f = state["failed"][0]
        raise CampaignError(f"{len(state['failed'])} of {total} runs failed (first: {f['label']}: "
                            f"{f['error']}); the results cover the others. Run the campaign again "
                            f"to retry them.", result)
    return result
