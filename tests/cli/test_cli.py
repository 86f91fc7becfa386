"""The `pyins` command line: every command's help has an example, runs write
a valid run directory, bad input gives one line naming file, key and reason
with exit code 2, Ctrl-C leaves a valid partial result that --resume
completes, and simulate -> replay closes the loop through a log file."""
import json
import os
import pathlib
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from pyins import __main__ as cli
from pyins import campaign, scenario

COMMANDS = ["run", "simulate", "replay", "report", "campaign", "list", "bench", "demo", "version"]

SHORT = """
name = "short"
title = "a short static run"
duration = "150 s"
seed = 3
record_every = "1 s"
[motion]
kind = "static"
lat = "34 deg"
lon = "108 deg"
height = "0 m"
heading = "30 deg"
[sensors]
preset = "seed003"
[indexing]
scheme = "single_position"
"""


def test_every_command_has_help_with_an_example(capsys):
    for c in COMMANDS:
        with pytest.raises(SystemExit) as e:
            cli.main([c, "--help"])
        assert e.value.code == 0
        out = capsys.readouterr().out
        assert "example" in out and f"pyins {c}" in out, c


def test_run_writes_a_run_directory(tmp_path, capsys):
    scn = tmp_path / "short.toml"
    scn.write_text(SHORT)
    out = tmp_path / "run"
    assert cli.main(["run", str(scn), "--out", str(out), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["complete"] and summary["scenario"] == "short"
    m = summary["variants"][0]["metrics"]
    # 150 s of a static ship with seed 003's errors: metres, not kilometres
    assert 0 < m["horizontal_error_max"] < 100.0
    for f in ("scenario.toml", "resolved_scenario.json", "summary.json", "report.html", "errors.png",
              "table.png", "short/timeseries.npz", "short/timeseries.csv"):
        assert (out / f).exists(), f
    assert (out / "scenario.toml").read_text() == SHORT
    with np.load(out / "short" / "timeseries.npz") as z:
        assert len(z["time_s"]) == 150 and z["outputs"]["tick"][-1] == 15_000
    # the report renders again from the directory alone
    os.remove(out / "report.html")
    assert cli.main(["report", str(out), "--quiet"]) == 0 and (out / "report.html").exists()


MISTAKES = [
    ("unknown key", SHORT.replace('lon = "108 deg"', 'lonn = "108 deg"'), "motion.lonn", "unknown key"),
    ("wrong unit", SHORT.replace('"34 deg"', '"34 m"'), "motion.lat", "unit"),
    ("missing unit", SHORT.replace('"34 deg"', '34'), "motion.lat", "unit"),
    ("out of range", SHORT.replace('"34 deg"', '"95 deg"'), "motion.lat", "range"),
    ("wrong type", SHORT.replace('seed = 3', 'seed = "three"'), "seed", ""),
    ("malformed TOML", SHORT.replace('kind = "static"', 'kind = "static'), "line", ""),
    ("unknown preset", SHORT.replace('"seed003"', '"seed009"'), "sensors.preset", "seed009"),
    ("unknown scheme", SHORT.replace('"single_position"', '"spin"'), "indexing.scheme", "spin"),
    ("negative heave period", SHORT.replace('heading = "30 deg"\n', 'heading = "30 deg"\n'
     'heave = [{ amplitude = "0.5 m", period = "-8 s" }]\n'), "motion.heave[0].period", "range"),
    ("lever arm too long", SHORT.replace('heading = "30 deg"\n', 'heading = "30 deg"\n'
     'lever_b = ["80 m", "80 m", "0 m"]\n'), "motion.lever_b", "100 m"),
    ("spectrum and heave", SHORT.replace('heading = "30 deg"\n', 'heading = "30 deg"\n'
     'heave = [{ amplitude = "0.5 m", period = "8 s" }]\nspectrum = { hs = "1 m", tp = "8 s" }\n'),
     "motion.spectrum", "not both"),
    ("spectrum hs 0", SHORT.replace('heading = "30 deg"\n', 'heading = "30 deg"\n'
     'spectrum = { hs = "0 m", tp = "8 s" }\n'), "motion.spectrum.hs", "range"),
    ("unknown lever", SHORT.replace('[indexing]', '[firmware]\nlever = "guessed"\n[indexing]'),
     "firmware.lever", "guessed"),
]


@pytest.mark.parametrize("what,text,key,reason", MISTAKES, ids=[m[0] for m in MISTAKES])
def test_bad_scenario_files_give_one_line_and_exit_2(tmp_path, capsys, what, text, key, reason):
    scn = tmp_path / "bad.toml"
    scn.write_text(text)
    assert cli.main(["run", str(scn), "--out", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert str(scn) in err and key in err and reason in err, err
    assert not (tmp_path / "r").exists()        # validated up front: nothing ran


def test_bad_inputs_of_other_commands(tmp_path, capsys):
    assert cli.main(["report", str(tmp_path)]) == 2
    assert "not a run directory" in capsys.readouterr().err
    assert cli.main(["replay", str(tmp_path / "none.npz")]) == 2
    assert "none.npz" in capsys.readouterr().err
    bad = tmp_path / "log.txt"
    bad.write_text("0.01 0 0 0 0 0 x\n")
    assert cli.main(["replay", str(bad), "--lat", "34", "--lon", "108", "--height", "0"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "log.txt" in err and "line 1" in err, err
    assert cli.main(["run", "demo", "--set", "duration=-1 h", "--out", str(tmp_path / "x")]) == 2
    assert "duration" in capsys.readouterr().err


def test_debug_shows_the_traceback(tmp_path):
    with pytest.raises(ValueError):
        cli.main(["--debug", "run", str(tmp_path / "missing.toml")])


def test_ctrl_c_leaves_a_partial_result_that_resume_completes(tmp_path):
    out = tmp_path / "r"
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    proc = subprocess.Popen([sys.executable, "-m", "pyins", "run", "seed003", "--out", str(out), "--quiet"],
                            env=env, stderr=subprocess.PIPE, text=True,
                            # a job started in the background inherits SIGINT ignored, and Python
                            # then installs no KeyboardInterrupt handler: restore the default
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    # the first chunk's records on disk: the first variant is under way (its first checkpoint, and
    # records.json with it, comes only 2 s of wall time in: run_scenario.CHECKPOINT_WALL_S)
    rec = out / "no_rotation" / "records" / "outputs.bin"
    t0 = time.monotonic()
    while not (rec.exists() and rec.stat().st_size > 0) and time.monotonic() - t0 < 120:
        assert proc.poll() is None, proc.stderr.read()
        time.sleep(0.02)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert "--resume" in err
    summary = json.loads((out / "summary.json").read_text())
    assert not summary["complete"]
    v = summary["variants"][0]
    assert 0 < v["ticks_done"] < v["ticks"]
    # the metrics of the stopped variant are the report's (Ctrl-C does not wait for them)
    assert cli.main(["report", str(out), "--quiet"]) == 0
    assert (out / "report.html").exists()
    done_before = v["ticks_done"]
    assert cli.main(["run", "seed003", "--out", str(out), "--resume", "--quiet"]) == 0
    resumed = json.loads((out / "summary.json").read_text())
    assert resumed["complete"] and resumed["variants"][0]["ticks_done"] == v["ticks"] > done_before
    # an uninterrupted run gives the same figures, bit for bit
    ref = tmp_path / "ref"
    assert cli.main(["run", "seed003", "--out", str(ref), "--quiet"]) == 0
    whole = json.loads((ref / "summary.json").read_text())
    assert [x["metrics"] for x in resumed["variants"]] == [x["metrics"] for x in whole["variants"]]


def test_simulate_then_replay(tmp_path, capsys):
    log = tmp_path / "imu.bin"
    assert cli.main(["simulate", "demo", str(log), "--hours", "0.05", "--quiet"]) == 0
    assert log.stat().st_size == 18_000 * 56          # (t, dtheta[3], dv[3]) float64 records
    out = tmp_path / "rp"
    # a binary log has no metadata: the initial state comes from the scenario
    assert cli.main(["replay", str(log), "--scenario", "demo", "--out", str(out), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["samples"] == 18_000
    # 3 min of the demo ship with seed 002 errors and its 10 m initial position error
    assert summary["errors"]["horizontal_max_m"] < 30.0
    npz = tmp_path / "imu.npz"
    assert cli.main(["simulate", "demo", str(npz), "--hours", "0.05", "--quiet"]) == 0
    assert cli.main(["replay", str(npz), "--out", str(tmp_path / "rp2"), "--json"]) == 0
    again = json.loads(capsys.readouterr().out)
    assert again["errors"] == summary["errors"]        # same samples, same firmware: same bits


def test_list_and_version(capsys):
    assert cli.main(["list", "--json"]) == 0
    items = json.loads(capsys.readouterr().out)
    names = [n for n, _ in items["scenarios"]]
    assert {"demo", "seed000_static", "seed001_fine5", "seed002_exp1", "seed002_exp2", "seed003"} <= set(names)
    assert cli.main(["version"]) == 0
    assert "core" in capsys.readouterr().out


def test_list_paths_shows_every_builtin_file(capsys):
    """`pyins list --paths`: each built-in scenario and campaign with the path of
    its TOML file (the data under pyins/builtin/, beside the code that reads it)."""
    assert cli.main(["list", "--paths"]) == 0
    out = capsys.readouterr().out
    shown = set()
    for line in out.splitlines():
        if line.startswith("  ") and line.endswith("]") and "  [" in line:
            path = pathlib.Path(line.rsplit("  [", 1)[1][:-1])
            shown.add((path.parent.name, line.split()[0], path))
    want = {(kind, name) for kind, names in (("scenarios", scenario.list_builtin()),
                                             ("campaigns", campaign.list_builtin())) for name, _ in names}
    assert {(kind, name) for kind, name, _ in shown} == want and len(shown) == len(want)
    assert {kind for kind, _ in want} == {"scenarios", "campaigns"}
    for kind, name, path in shown:
        assert path.is_file() and path.name == f"{name}.toml"
        assert path.parent.parent.name == "builtin" and path.parent.parent.parent.name == "pyins"


def test_campaign_from_the_command_line(tmp_path, capsys):
    out = tmp_path / "c"
    assert cli.main(["campaign", "--scenario", "seed000_static", "--grid", "motion.heading=0 deg,90 deg",
                     "--seeds", "2", "--workers", "1", "--out", str(out), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert len(list((out / "runs").iterdir())) == 4 and (out / "aggregate.md").exists()
    assert len(result["groups"]) == 2
    bad = tmp_path / "bad.toml"
    bad.write_text('[campaign]\nscenario = "seed000_static"\nseedz = 3\n')
    assert cli.main(["campaign", str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "bad.toml" in err and "seedz" in err, err
