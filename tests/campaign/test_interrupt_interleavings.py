"""Ctrl-C at every moment around the end of a campaign's run: a run that
finished (its last variant's metrics and time series written) is complete
on disk and is never run again when the campaign is resumed.

Deterministic: the campaign runs in this process (workers=1) under a line
tracer over the modules that finish a run and tell it (run_scenario,
rundir, records, campaign.execute); at the k-th line the tracer raises a
real SIGINT (so the blocks that hold Ctrl-C off hold it off, as a
terminal's would be), for every k in the window from the run's last
variant's metrics to the start of the next run (a line that begins with a
NOP, as `try:` does, passes it to the next line: CPython takes a signal
only at an instruction that checks for one, and never at a NOP, which may
lie outside the enclosing try's range)."""
import dis
import json
import os
import signal
import sys

import pytest

from pyins import campaign, records
from pyins.campaign import execute

MODULES = {"pyins.run_scenario", "pyins.rundir", "pyins.records", "pyins.campaign.execute"}


def _camp():
    return campaign.from_args("seed003", [], 2, overrides={"duration": "0.01 h", "record_every": "1 s"})


class _Tracer:
    """Counts line events in MODULES; raises SIGINT at event ``at``; notes
    the event index at which each run's last variant wrote its time series."""

    def __init__(self, at=None):
        self.at, self.n, self.fired_at = at, 0, None

    def local(self, frame, event, arg):
        if event == "line":
            self.n += 1
            if self.at is not None and self.n >= self.at and self.fired_at is None:
                if frame.f_code.co_code[frame.f_lasti] == dis.opmap["NOP"]:
                    return self.local    # a NOP (a `try:` line) never takes a signal: the next line does
                self.fired_at = self.n
                signal.raise_signal(signal.SIGINT)
        return self.local

    def __call__(self, frame, event, arg):
        if frame.f_globals.get("__name__") in MODULES:
            return self.local
        return None


def _traced(tracer, fn, *a, **k):
    sys.settrace(tracer)
    try:
        return fn(*a, **k)
    finally:
        sys.settrace(None)


def _complete_on_disk(out):
    done = set()
    for d in (out / "runs").iterdir() if (out / "runs").exists() else ():
        try:
            s = json.loads((d / "summary.json").read_text())
        except (OSError, ValueError):
            continue
        if s.get("complete") is True:
            done.add(d.name)
    return done


def test_no_finished_run_is_run_again_whenever_the_ctrl_c_comes(tmp_path, monkeypatch):
    """Before: a Ctrl-C just after a run's last variant ended left its
    summary saying "incomplete" (the interrupt handler marked the finished
    variant stopped, or came between the variant's end and the summary's
    write and left the summary of the variant before), so the resumed
    campaign ran it again (seen as one or two recomputed runs)."""
    camp = _camp()
    dirs = {p.digest: p.dir.split("/")[-1] for p in camp.points}
    # 1. a full campaign, traced: where each run's last variant is done (its time series written)
    marks = []
    write_ts = records.score_variant
    tracer = _Tracer()

    def noting(vdir, spec, *a, **k):
        out = write_ts(vdir, spec, *a, **k)
        marks.append((os.path.basename(os.path.dirname(vdir)), tracer.n))
        return out
    monkeypatch.setattr(records, "score_variant", noting)
    _traced(tracer, campaign.run_campaign, camp, tmp_path / "full", workers=1, plots=False)
    n_variants = len(camp.variants or [None])
    ends = {}
    for run, n in marks:
        ends.setdefault(run, []).append(n)
    first_run = dirs[camp.points[0].digest]
    assert len(ends[first_run]) == n_variants
    end = ends[first_run][-1]
    second_start = min(n for run, ns in ends.items() if run != first_run for n in ns[:1])
    window = range(max(1, end - 30), min(second_start, end + 150))   # ~180 lines, ~60 s
    # 2. a Ctrl-C at every line of the window; then resume and see what runs again
    ran_again = []
    real_run_point = execute._run_point
    for k in window:
        out = tmp_path / f"k{k}"
        marks.clear()
        tracer = _Tracer(at=k)
        try:
            _traced(tracer, campaign.run_campaign, camp, out, workers=1, plots=False)
        except KeyboardInterrupt:
            pass
        runs = [r for r, _ in marks]
        finished = {r for r in runs if runs.count(r) == n_variants}
        on_disk = _complete_on_disk(out)
        # a run whose last variant was done before the Ctrl-C is complete on disk
        missing = finished - on_disk
        recomputed = []

        def counting(task, recomputed=recomputed):
            recomputed.append(os.path.basename(task["run_dir"]))
            return real_run_point(task)
        monkeypatch.setattr(execute, "_run_point", counting)
        try:
            campaign.run_campaign(camp, out, workers=1, plots=False)
        finally:
            monkeypatch.setattr(execute, "_run_point", real_run_point)
        again = set(recomputed) & (finished | on_disk)
        if missing or again:
            ran_again.append((k, sorted(missing), sorted(again)))
    assert not ran_again, f"Ctrl-C at line k: (k, finished but not complete on disk, run again): {ran_again[:8]}"
