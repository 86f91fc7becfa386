"""Ctrl-C, kill -9 and two writers, as a user meets them (docs/cli.md, "pyins
run SCENARIO": Ctrl-C and kills, the lock, another scenario's directory):
real signals to real ``python -m pyins`` processes. Ctrl-C stops a run or a
campaign within seconds and leaves a summary ``pyins report``
reads; after kill -9 the report reads what is there; a run directory being
written is locked; a directory of another scenario is refused, never mixed.

Each test waits for a state of the directory (records written, a run
finished), never for a fixed time, so a busy machine slows it but does not
change what it checks."""
import json
import os
import signal
import subprocess
import sys
import time

import pytest

from pyins import __main__ as cli
from pyins import rundir, scenario
from pyins.records import PLANT_RECORD_DTYPE

from budget_campaign import BUDGET_CAMPAIGN

#: How long after SIGINT a command may take to exit. The brief is "a second
#: or two"; 5 s leaves room for a machine shared with other jobs (the stop
#: itself is a summary write, measured at 0.1-1.1 s); the defect was > 60 s
#: (a campaign finishing its runs) or a failure (exit 2, no summary).
STOP_S = 5.0
WAIT_S = 60.0      #: the longest a test waits for a directory state it needs


def _start(*args):
    """``python -m pyins ARGS`` in its own process group (as a terminal's job),
    SIGINT at its default (a background job would inherit it ignored)."""
    return subprocess.Popen([sys.executable, "-m", "pyins", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True,
                            env=dict(os.environ, PYTHONUNBUFFERED="1"),
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


def _wait_for(proc, cond, what):
    t0 = time.monotonic()
    while not cond():
        if proc.poll() is not None:
            pytest.fail(f"ended (rc {proc.returncode}) before {what}: {proc.stderr.read()}")
        if time.monotonic() - t0 > WAIT_S:
            proc.kill()
            pytest.fail(f"no {what} after {WAIT_S} s")
        time.sleep(0.01)


def _json(path):
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError):
        return None


def _stop(proc, sig=signal.SIGINT, group=True):
    """Send ``sig`` (to the process group, as a terminal does, or to the
    process alone); returns (rc, stderr, seconds to exit)."""
    t0 = time.monotonic()
    (os.killpg if group else os.kill)(proc.pid, sig)
    try:
        _, err = proc.communicate(timeout=120)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        _, err = proc.communicate()
    return proc.returncode, err, time.monotonic() - t0


def _group_gone(pgid):
    try:
        os.killpg(pgid, 0)
    except ProcessLookupError:
        return True
    return False


def _report(run_dir, capsys):
    capsys.readouterr()
    rc = cli.main(["report", str(run_dir), "--json"])
    return rc, (json.loads(capsys.readouterr().out) if rc == 0 else None)


def test_ctrl_c_while_metrics_are_written_leaves_a_summary_the_report_reads(tmp_path, capsys):
    """Before: exit 2 "summary.json: No such file or directory", no summary,
    no report (the interrupt hit the metrics after the firmware finished)."""
    out = tmp_path / "r"
    proc = _start("run", "seed003", "--out", str(out), "--quiet")
    rec = out / "no_rotation" / "records" / "records.json"
    # the firmware has finished the first variant; 0.5 s later the run is inside its metrics
    # (loading the records takes a few tenths, the metrics of 24 h some seconds)
    _wait_for(proc, lambda: (_json(rec) or {}).get("complete"), "first variant's records")
    time.sleep(0.5)
    rc, err, took = _stop(proc)
    assert rc == 130, err
    assert took < STOP_S, f"{took:.1f} s to stop"
    assert "pyins report" in err and "--resume" in err
    summary = _json(out / "summary.json")
    assert summary is not None and summary["complete"] is False and summary["state"] == "interrupted"
    assert summary["variants"][0]["ticks_done"] == summary["variants"][0]["ticks"]
    assert not (out / "pyins.lock").exists()
    rc, rep = _report(out, capsys)
    assert rc == 0 and rep["complete"] is False
    # the report computed the stopped variant's metrics from its records
    assert rep["variants"][0]["metrics"]["horizontal_error_max"] > 0
    assert "PARTIAL" in (out / "report.html").read_text()


def test_kill_9_leaves_a_directory_the_report_reads_and_resume_completes(tmp_path, capsys):
    """Before: after kill -9 ``pyins report`` refused the directory (no
    summary.json) although docs/cli.md promised a partial result."""
    out = tmp_path / "r"
    args = ("run", "seed003", "--hours", "12", "--out", str(out), "--quiet")
    proc = _start(*args)
    rec_dir = out / "no_rotation" / "records"
    # a whole record in both files (outputs.bin is written first: a kill
    # between the two writes leaves no record the report can pair)
    plant_bin = rec_dir / "plant.bin"
    _wait_for(proc, lambda: (rec_dir / "outputs.bin").exists() and plant_bin.exists()
              and plant_bin.stat().st_size >= PLANT_RECORD_DTYPE.itemsize, "records on disk")
    rc, _, _ = _stop(proc, signal.SIGKILL)
    assert rc == -signal.SIGKILL
    rc, rep = _report(out, capsys)
    assert rc == 0 and rep["complete"] is False and "killed" in rep["stopped"]
    v = rep["variants"][0]
    assert 0 < v["ticks_done"] < v["ticks"] and v["metrics"]["horizontal_error_max"] > 0
    assert "PARTIAL" in (out / "report.html").read_text()
    # the lock of the killed run is stale: the resume takes it over, says so, and completes
    assert (out / "pyins.lock").exists()
    res = subprocess.run([sys.executable, "-m", "pyins", *args, "--resume"], capture_output=True,
                         text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    assert f"taking over the stale lock of pid {proc.pid}" in res.stderr
    summary = _json(out / "summary.json")
    assert summary["complete"] is True and summary["state"] == "complete"
    assert not (out / "pyins.lock").exists()


def test_a_second_writer_is_refused_naming_the_holder(tmp_path, capsys):
    """Before: no lock; the second run wrote into the first's directory and
    the directory mixed seed 5's scenario with seed 1's summary."""
    out = tmp_path / "r"
    first = _start("run", "seed003", "--seed", "1", "--out", str(out), "--quiet")
    bin_ = out / "no_rotation" / "records" / "outputs.bin"
    _wait_for(first, lambda: bin_.exists() and bin_.stat().st_size > 0, "the first run's records")
    second = subprocess.run([sys.executable, "-m", "pyins", "run", "seed003", "--seed", "5", "--out", str(out),
                             "--quiet"], capture_output=True, text=True, timeout=60)
    assert second.returncode == 2
    lines = second.stderr.strip().splitlines()
    assert len(lines) == 1, second.stderr
    assert f"pid {first.pid}" in lines[0] and os.uname().nodename in lines[0] and "started" in lines[0]
    assert _json(out / "resolved_scenario.json")["seed"] == 1       # nothing of seed 5 written
    rc, rep = _report(out, capsys)                                  # a report of the run so far
    assert rc == 0 and rep["complete"] is False and f"being written by pid {first.pid}" in rep["stopped"]
    rc, err, took = _stop(first)
    assert rc == 130 and took < STOP_S, err
    assert _json(out / "summary.json")["digest"] != ""
    assert _json(out / "resolved_scenario.json")["seed"] == 1


def test_a_directory_of_another_scenario_is_refused_unless_force(tmp_path, capsys):
    """Before: the second scenario ran into the directory and left the first
    one's variant directory (demo's) beside its own."""
    out = tmp_path / "r"
    assert cli.main(["run", "demo", "--hours", "0.01", "--out", str(out), "--quiet"]) == 0
    before = sorted(os.listdir(out))
    capsys.readouterr()
    assert cli.main(["run", "seed000_static", "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "holds a run of 'demo'" in err and "--force" in err and len(err.strip().splitlines()) == 1
    assert sorted(os.listdir(out)) == before and _json(out / "summary.json")["scenario"] == "demo"
    # the same scenario with other values is another scenario too
    assert cli.main(["run", "demo", "--hours", "0.02", "--out", str(out), "--quiet"]) == 2
    # a file of the user's is not a run: the directory is refused, not written into
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("mine")
    assert cli.main(["run", "demo", "--hours", "0.01", "--out", str(mine), "--quiet"]) == 2
    assert os.listdir(mine) == ["notes.txt"]
    # --force replaces the run, and only the run's files
    (out / "notes.txt").write_text("mine")
    assert cli.main(["run", "seed000_static", "--out", str(out), "--quiet", "--force"]) == 0
    summary = _json(out / "summary.json")
    assert summary["scenario"] == "seed000_static" and summary["complete"]
    dirs = {p.name for p in out.iterdir() if p.is_dir()}
    assert dirs == {v["dir"] for v in summary["variants"]}          # demo's variant directory is gone
    assert (out / "notes.txt").read_text() == "mine"


def _campaign_args(out):
    # seed003's two variants, 12 h each: ~2-6 s a run on this machine, 6 runs on 2 workers
    return ("campaign", "--scenario", "seed003", "--grid", "duration=12 h", "--seeds", "6",
            "--workers", "2", "--out", str(out))


def _finished_runs(out):
    runs = out / "runs"
    if not runs.exists():
        return []
    return [d for d in runs.iterdir() if (_json(d / "summary.json") or {}).get("complete") is True]


@pytest.mark.parametrize("group", [True, False], ids=["terminal", "main-process-only"])
def test_ctrl_c_stops_a_campaign_keeping_finished_runs_and_a_partial_aggregate(tmp_path, capsys, group):
    """Before: the campaign went on with its runs after SIGINT (the pool
    workers picked up the queued runs), and left no aggregate of the runs
    that had finished (campaign.json still said "running")."""
    out = tmp_path / "c"
    proc = _start(*_campaign_args(out))
    _wait_for(proc, lambda: len(_finished_runs(out)) >= 1, "a finished run")
    rc, err, took = _stop(proc, group=group)
    assert rc == 130, err
    assert took < STOP_S, f"{took:.1f} s to stop"
    time.sleep(0.2)
    assert _group_gone(proc.pid), "pool workers left running"
    camp = _json(out / "campaign.json")
    assert camp["complete"] is False and camp["execution"]["interrupted"] is True
    finished = _finished_runs(out)
    assert len(finished) >= 1 and camp["execution"]["computed"] == len(finished)
    assert (out / "aggregate.md").exists() and "Incomplete" in (out / "aggregate.md").read_text()
    # the points in the partial aggregate are the runs that had finished
    with_metrics = {p["digest"][:16] for p in camp["points"] if p["metrics"] is not None}
    assert with_metrics == {d.name for d in finished}
    # every run that started holds a summary the report reads (a directory the Ctrl-C met
    # before its run began holds only point.json); no lock is left
    for d in (out / "runs").iterdir():
        assert _json(d / "summary.json") is not None or os.listdir(d) == ["point.json"], d
        assert not (d / "pyins.lock").exists(), d
    assert not (out / "pyins.lock").exists()
    stopped = [d for d in (out / "runs").iterdir() if d not in finished and (d / "summary.json").exists()]
    if stopped:
        rc, rep = _report(stopped[0], capsys)
        assert rc == 0 and rep["complete"] is False


def test_ctrl_c_as_a_finished_run_is_told_counts_it(tmp_path, monkeypatch):
    """Before: a Ctrl-C that reached the campaign between taking a finished
    run off the pool's list and counting it left the run complete on disk
    and missing from execution.computed (seen once in CI: 2 runs finished,
    computed 1). The user's Ctrl-C tends to come just as a run ends. Here
    the SIGINT is sent inside that window, on the first finished run."""
    from concurrent.futures import Future

    from pyins import campaign

    fired = []
    exception = Future.exception

    def exception_then_ctrl_c(self, timeout=None):
        exc = exception(self, timeout)
        if not fired and exc is None:
            fired.append(True)
            os.kill(os.getpid(), signal.SIGINT)     # handled at the next bytecode: the window
        return exc

    monkeypatch.setattr(Future, "exception", exception_then_ctrl_c)
    camp = campaign.from_args("seed003", [], 3, overrides={"duration": "0.05 h"})
    out = tmp_path / "c"
    # a Ctrl-C that reaches Python: a shell starts a background job (`cmd &`)
    # with SIGINT ignored, and the interpreter then never raises it
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(campaign.CampaignInterrupted) as info:
            campaign.run_campaign(camp, out, workers=2, plots=False)
    finally:
        signal.signal(signal.SIGINT, old)
    assert fired
    finished = _finished_runs(out)
    assert len(finished) >= 1 and info.value.result["execution"]["computed"] == len(finished)
    assert json.loads((out / "campaign.json").read_text())["execution"]["computed"] == len(finished)


def test_a_second_campaign_into_the_same_directory_is_refused(tmp_path):
    """Before: nothing stopped two campaigns writing the same directory (the
    docs only asked users not to); the second ran the same runs beside the
    first and failed on its checkpoints."""
    out = tmp_path / "c"
    proc = _start(*_campaign_args(out))
    _wait_for(proc, lambda: (out / "campaign.json").exists(), "the campaign's start")
    other = subprocess.run([sys.executable, "-m", "pyins", *_campaign_args(out)], capture_output=True,
                           text=True, timeout=60)
    assert other.returncode == 2, other.stderr
    lines = other.stderr.strip().splitlines()
    assert len(lines) == 1 and f"pid {proc.pid}" in lines[0] and "started" in lines[0], other.stderr
    rc, err, took = _stop(proc)
    assert rc == 130 and took < STOP_S, err


def test_a_run_killed_as_it_began_is_started_again_and_a_users_file_is_kept(tmp_path):
    """A kill between a run's first file and the file that names it (seen in
    a campaign killed with SIGKILL: the resume refused the directory as "not
    a pyins run directory"): the resolved scenario is now written first, and
    a directory holding only this scenario's scenario.toml is started again;
    one holding a different scenario.toml (a user's file) is still refused,
    untouched."""
    scn = scenario.load("seed000_static")
    d = tmp_path / "run"
    d.mkdir()
    (d / "scenario.toml").write_text(scn.text)
    assert rundir.check_run_dir(scn, str(d)) == "new"
    (d / "scenario.toml").write_text("# my own notes\n")
    with pytest.raises(rundir.RunDirError, match="not a pyins run directory"):
        rundir.check_run_dir(scn, str(d))
    assert (d / "scenario.toml").read_text() == "# my own notes\n"
    # the resolved scenario alone names the run: a resume recognises it
    (d / "scenario.toml").unlink()
    (d / "resolved_scenario.json").write_text(scn.resolved_json())
    assert rundir.check_run_dir(scn, str(d)) == "same"



def _budget_at_its_first_check(tmp_path):
    """(campaign file, OUT, process): `pyins campaign --budget 200 --checks 8`
    started, once the first check's line is on its terminal."""
    f = tmp_path / "c.toml"
    f.write_text(BUDGET_CAMPAIGN.replace('"2 h"', '"24 h"'))      # checks of about a second each
    out = tmp_path / "out"
    proc = _start("campaign", str(f), "--budget", "200", "--checks", "8", "--workers", "2", "--out", str(out))
    t0 = time.monotonic()
    while True:
        line = proc.stdout.readline()
        if not line:
            pytest.fail(f"ended (rc {proc.wait()}) before a check finished: {proc.stderr.read()}")
        if "check 1/8" in line:
            return f, out, proc
        if time.monotonic() - t0 > WAIT_S:
            proc.kill()
            pytest.fail(f"no check after {WAIT_S} s")


def test_a_budget_killed_in_its_checks_resumes_them(tmp_path, capsys):
    """kill -9 in the checks: no budget.md, but the checks done are on disk
    (budget_checks.json, written after each) and the same command keeps
    them."""
    f, out, proc = _budget_at_its_first_check(tmp_path)
    rc, _, _ = _stop(proc, signal.SIGKILL)
    assert rc == -signal.SIGKILL and not (out / "budget.md").exists()
    done = _json(out / "budget_checks.json")
    assert done is not None and 1 <= len(done["checks"]) < 8
    assert cli.main(["campaign", str(f), "--budget", "200", "--checks", "8", "--out", str(out)]) == 0
    assert f"{len(done['checks'])} of 8 check(s) kept from the run that stopped" in capsys.readouterr().out
    assert _json(out / "budget.json")["complete"] is True and not (out / "budget_checks.json").exists()


def test_ctrl_c_in_the_budgets_checks_keeps_the_draws_and_the_checks_done(tmp_path, capsys):
    """`pyins campaign --budget N --checks M` stopped by Ctrl-C once its
    first check has finished: within seconds, exit 130, and budget.md /
    budget.json written with every draw placed, the checks that finished,
    "complete": false and the interruption as a kept warning (before, the
    draws and the checks done were lost). The same command again keeps the
    checks done (budget_checks.json) and runs the others: the same
    figures as a run never stopped."""
    f, out, proc = _budget_at_its_first_check(tmp_path)
    rc, err, seconds = _stop(proc)
    assert rc == 130 and seconds < STOP_S, (rc, seconds, err)
    res = _json(out / "budget.json")
    assert res is not None and res["complete"] is False and res["checks_planned"] == 8
    assert 1 <= len(res["checks"]) < 8, len(res["checks"])
    assert all(len(p["final_m"]) == 200 for p in res["points"])
    assert any("interrupted (Ctrl-C) after" in w for w in res["warnings"])
    assert "interrupted (Ctrl-C) after" in err
    assert "**Incomplete:** interrupted after" in (out / "budget.md").read_text()
    assert _group_gone(proc.pid)
    assert (out / "budget_checks.json").exists()
    # resumed: the checks done kept, the others run
    capsys.readouterr()
    args = ["campaign", str(f), "--budget", "200", "--checks", "8", "--workers", "2"]
    assert cli.main([*args, "--out", str(out)]) == 0
    assert f"{len(res['checks'])} of 8 check(s) kept from the run that stopped" in capsys.readouterr().out
    resumed = _json(out / "budget.json")
    assert resumed["complete"] is True and len(resumed["checks"]) == 8 and not (out / "budget_checks.json").exists()
    assert resumed["checks"][:len(res["checks"])] == res["checks"]
    # the same as a run never stopped, bit for bit (seconds aside)
    assert cli.main([*args, "--out", str(tmp_path / "fresh")]) == 0
    fresh = _json(tmp_path / "fresh" / "budget.json")
    def figures(r):
        return [{k: v for k, v in c.items() if k != "seconds"} for c in r["checks"]], r["points"]
    assert figures(resumed) == figures(fresh)
