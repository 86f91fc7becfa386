"""The front door's defects as a careful user finds them (`pyins run`,
`pyins report`, `pyins demo`, `pyins simulate`): bad input, interruptions,
reuse and damaged files. Every case runs the command line as a user runs it
(`pyins.__main__.main`) and checks the exit code and the one line it prints:
never a silent wrong answer, never "internal error"."""
import json
import os
import shutil

import pytest

from pyins import __main__ as cli

#: A finished run of the cheapest built-in: seed003 for 36 s (two variants, 0.01 h)
SHORT = ["seed003", "--hours", "0.01"]


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    out = tmp_path_factory.mktemp("finished") / "run"
    assert cli.main(["run", *SHORT, "--out", str(out), "--quiet"]) == 0
    return out


def _files(root):
    return sorted(os.path.relpath(os.path.join(d, f), root) for d, _, fs in os.walk(root) for f in fs)


def _damage(path, how):
    data = path.read_bytes()
    if how == "truncate":
        path.write_bytes(data[:len(data) // 2])
    elif how == "corrupt":
        b = bytearray(data)
        for i in range(0, len(b), max(1, len(b) // 20)):
            b[i] ^= 0x5A
        path.write_bytes(bytes(b))
    else:
        path.unlink()


def _report(capsys, d, *extra):
    rc = cli.main(["report", str(d), *extra])
    out, err = capsys.readouterr()
    return rc, out, err


def _files_of_a_finished_run():
    # the layout of a seed003 run (every file it holds; the fixture checks it is the whole list)
    top = ["comparison.png", "errors.png", "report.html", "resolved_scenario.json", "scenario.toml",
           "summary.json", "table.png"]
    per = ["records/checkpoint.json", "records/outputs.bin", "records/plant.bin", "records/records.json",
           "timeseries.csv", "timeseries.npz"]
    return top + [f"{v}/{f}" for v in ("no_rotation", "single-position_fwd_rev_seed_003") for f in per]


def test_the_damage_list_is_every_file_of_a_run(finished):
    assert _files(finished) == sorted(_files_of_a_finished_run())


# ACCEPTANCE: "internal error" never appears on a damaged input file
@pytest.mark.parametrize("how", ["truncate", "corrupt", "delete"])
@pytest.mark.parametrize("rel", _files_of_a_finished_run())
def test_report_of_a_damaged_run_directory_never_fails_inside(finished, tmp_path, capsys, rel, how):
    d = tmp_path / "run"
    shutil.copytree(finished, d)
    _damage(d / rel, how)
    rc, out, err = _report(capsys, d)
    assert "internal error" not in err and "Traceback" not in err
    assert rc in (0, 2), err
    if rc == 2:
        assert len(err.strip().splitlines()) == 1 and os.path.basename(rel) in err, err
    elif rel.endswith("timeseries.npz") and how != "delete" or rel == "summary.json":
        # what could not be read is said, on the command line and on the page
        assert os.path.basename(rel) in err and "WARNING" in err, err
        assert "timeseries.npz" in (d / "report.html").read_text()


@pytest.mark.parametrize("text, says", [
    ("[]", "not a run's summary"),
    ("{}", "no 'variants'"),
    ('{"variants": [1, 2], "title": "x", "scenario": "x", "digest": "x"}', "damaged 'variants'"),
    ('{"format": 99, "variants": []}', "newer pyins"),
    ('{"scenario": "seed 002", "ship_time_h": 2, "max_horizontal_error_m": 3}', "pyins demo"),
])
def test_report_of_a_summary_of_another_shape_names_it(finished, tmp_path, capsys, text, says):
    d = tmp_path / "run"
    shutil.copytree(finished, d)
    (d / "summary.json").write_text(text)
    rc, _, err = _report(capsys, d)
    assert rc == 2 and "summary.json" in err and says in err and "internal error" not in err, err


def test_report_of_a_damaged_summary_does_not_say_the_run_stopped(finished, tmp_path, capsys):
    d = tmp_path / "run"
    shutil.copytree(finished, d)
    (d / "summary.json").write_text('{"variants": [')
    rc, _, err = _report(capsys, d)
    assert rc == 2 and "not valid JSON" in err and "stopped before" not in err, err
    assert "--resume" in err and str(d) in err           # what can still be done, with the real directory


def test_report_json_of_an_interrupted_replay_says_partial(tmp_path, capsys):
    # item 6: a replay stopped by Ctrl-C writes complete=false, state=interrupted and a first warning
    log = tmp_path / "imu.bin"
    assert cli.main(["simulate", "demo", str(log), "--hours", "0.01", "--quiet"]) == 0
    out = tmp_path / "rp"
    assert cli.main(["replay", str(log), "--scenario", "demo", "--out", str(out), "--quiet"]) == 0
    s = json.loads((out / "summary.json").read_text())
    s.update(complete=False, state="interrupted")
    s.setdefault("warnings", []).insert(0, "interrupted (Ctrl-C) at 20 s after 2000 samples: the log was "
                                           "not replayed to its end")
    (out / "summary.json").write_text(json.dumps(s))
    capsys.readouterr()
    rc, text, _ = _report(capsys, out, "--json")
    got = json.loads(text)
    assert rc == 0 and got["complete"] is False and "interrupted" in got["stopped"]
    rc, text, _ = _report(capsys, out)
    assert rc == 0 and "PARTIAL" in text


def _run(capsys, *argv):
    rc = cli.main(["run", *argv])
    out, err = capsys.readouterr()
    return rc, out, err


def test_resume_with_another_engine_is_refused_before_touching_the_run(finished, tmp_path, capsys):
    # item 13: it deleted the finished run's time series, marked the summary running, then refused
    d = tmp_path / "run"
    shutil.copytree(finished, d)
    before = {f: (d / f).read_bytes() for f in _files(d) if not f.endswith((".png", ".html"))}
    rc, out, err = _run(capsys, *SHORT, "--out", str(d), "--resume", "--engine", "reference")
    assert rc == 2 and "--engine native" in err and "--engine reference" in err, err
    assert "pyins run seed003" not in out           # refused first: no title line, no "-> DIR"
    assert {f: (d / f).read_bytes() for f in before} == before


def test_run_of_a_directory_says_it_is_one(finished, tmp_path, capsys):
    # item 18: "no such file or built-in scenario"
    rc, _, err = _run(capsys, str(finished))
    assert rc == 2 and "a directory" in err and f"pyins report {finished}" in err and "--resume" in err, err
    rc, _, err = _run(capsys, str(tmp_path))
    assert rc == 2 and "a directory" in err and "no such file" not in err, err


def test_a_lever_arm_message_offers_only_what_is_accepted(tmp_path, capsys):
    # item 19: two components were answered with "one value for all three axes", which a single
    # length then refuses; both messages now ask for the list of 3
    for value in ('["0.5 m", "1 m"]', '"0.5 m"'):
        f = tmp_path / "lever.toml"
        f.write_text(f'title = "x"\nduration = "60 s"\n[motion]\nkind = "static"\nlever_b = {value}\n')
        rc, _, err = _run(capsys, str(f), "--out", str(tmp_path / "out"))
        assert rc == 2 and "motion.lever_b" in err and "list of 3" in err, err
        assert "one value for all three" not in err, err


def test_a_refused_run_prints_no_title(finished, tmp_path, capsys):
    d = tmp_path / "mine"
    d.mkdir()
    (d / "notes.txt").write_text("mine")
    rc, out, err = _run(capsys, *SHORT, "--out", str(d))
    assert rc == 2 and "not a pyins run directory" in err and out == "", (out, err)
    assert (d / "notes.txt").read_text() == "mine"


def test_demo_and_run_demo_do_not_share_a_directory(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert cli.main(["demo", "--hours", "0.01", "--quiet"]) == 0
    assert cli.main(["run", "demo", "--hours", "0.01", "--quiet"]) == 0
    capsys.readouterr()
    rc, _, err = _report(capsys, tmp_path / "runs" / "demo")
    assert rc == 0, err
    # and the demo never overwrites a run's summary
    rc = cli.main(["demo", "--hours", "0.01", "--out", str(tmp_path / "runs" / "demo")])
    assert rc == 2 and "pyins run" in capsys.readouterr().err


def test_the_ctrl_c_line_prints_the_real_resume_command(tmp_path, capsys, monkeypatch):
    from pyins import run_scenario

    def stop(*a, **k):
        raise KeyboardInterrupt
    monkeypatch.setattr(run_scenario, "execute", stop)
    d = tmp_path / "x"
    rc, _, err = _run(capsys, *SHORT, "--out", str(d), "--set", "seed=4")
    assert rc == 130
    assert f"pyins run seed003 --out {d} --hours 0.01 --set seed=4 --resume" in err, err
    assert "..." not in err


def test_simulate_ignores_a_firmware_key_it_does_not_use_and_says_so(tmp_path, capsys):
    # item 22: refused for "firmware.fine_time: the alignment is longer than the duration"
    f = tmp_path / "s.toml"
    f.write_text('title = "x"\nduration = "60 s"\n[motion]\nkind = "static"\n[firmware]\nfine_time = "100 s"\n')
    rc = cli.main(["simulate", str(f), str(tmp_path / "imu.bin"), "--json"])
    out, err = capsys.readouterr()
    assert rc == 0, err
    assert "firmware.fine_time" in err and "ignored" in err
    assert any("firmware.fine_time" in n for n in json.loads(out)["notes"])     # kept in what it prints


def test_paper_notes_hold_no_figure_of_ours(tmp_path, capsys):
    # item 12: "(ours 1.039')" beside a run with other sensor errors whose table said 0.0035'
    d = tmp_path / "run"
    assert cli.main(["run", *SHORT, "--set", "sensors.gyro_bias=0.003deg/h", "--out", str(d), "--quiet"]) == 0
    page = (d / "report.html").read_text()
    assert "ours 1.039" not in page and "ours 0.185" not in page
    import re
    from pyins import scenario
    for name, _ in scenario.list_builtin():
        for f in (scenario.load(name).paper or {}).get("figures", []):
            assert not re.search(r"\bours\b[^.;:]*\d", f.get("note") or ""), (name, f["note"])


def _labels(d):
    return [v["label"] for v in json.loads((d / "summary.json").read_text())["variants"]]


def test_set_on_the_compared_key_wins_and_says_so(tmp_path, capsys):
    # item 8: --set indexing.scheme=... printed the four default variants' figures
    d = tmp_path / "run"
    rc, _, err = _run(capsys, "seed002_exp1", "--hours", "0.005", "--set", "indexing.scheme=heading_isolation",
                      "--out", str(d), "--quiet")
    assert rc == 0, err
    assert _labels(d) == ["indexing.scheme = heading_isolation"]
    assert "[compare]" in err and "indexing.scheme" in err
    s = json.loads((d / "summary.json").read_text())
    assert any("[compare]" in n for n in s["notes"])                 # kept in the summary
    assert "replaces [compare]" in (d / "report.html").read_text()   # and on the page
    # compare.values with the file's [paper] labels for other values: the labels follow the values
    d2 = tmp_path / "run2"
    rc, _, err = _run(capsys, "seed002_exp1", "--hours", "0.005", "--set", 'compare.values=["none", "two_position"]',
                      "--out", str(d2), "--quiet")
    assert rc == 0, err
    assert _labels(d2) == ["indexing.scheme = none", "indexing.scheme = two_position"]


def test_run_variant_runs_one_variant_with_its_label(tmp_path, capsys):
    d = tmp_path / "run"
    rc, _, err = _run(capsys, "seed002_exp1", "--hours", "0.005", "--variant", "1", "--out", str(d), "--quiet")
    assert rc == 0, err
    assert _labels(d) == ["traditional two-position"]
    rc, _, err = _run(capsys, "seed002_exp1", "--variant", "4", "--out", str(tmp_path / "x"))
    assert rc == 2 and "--variant 4" in err and "0..3" in err, err


def test_attitude_maxima_are_judged_from_the_end_of_the_alignment(tmp_path, capsys):
    # item 10: level_error_max 4.668e4" and heading_error_max 7941' were the unaligned start.
    # moored_general aligns for 300 s; 0.1 h leaves 60 s of navigation after it
    d = tmp_path / "run"
    rc, _, err = _run(capsys, "moored_general", "--hours", "0.1", "--out", str(d), "--quiet")
    assert rc == 0, err
    arcsec, arcmin = 4.84813681109536e-06, 2.908882086657216e-04
    for v in json.loads((d / "summary.json").read_text())["variants"]:
        m = v["metrics"]
        # after the alignment the level error is tens of arc-seconds (final 30-40" here) and 60 s
        # of navigation adds little (a Schuler period is 84 min): 300" is far below the start's 4.7e4"
        assert m["level_error_max"] < 300 * arcsec, (v["label"], m["level_error_max"] / arcsec)
        # TRIAD's heading ends near 81'; the start was 7941'
        assert m["heading_error_max"] < 200 * arcmin, (v["label"], m["heading_error_max"] / arcmin)
    from pyins import metrics
    assert "end of the alignment" in metrics.describe("level_error_max")
    assert "end of the alignment" in (d / "report.html").read_text()


def test_an_alignment_only_run_reports_no_horizontal_error(tmp_path, capsys):
    # item 11: the ship's own surge and sway (0.4 m) were reported as the horizontal error
    d = tmp_path / "run"
    rc, out, err = _run(capsys, "moored_general", "--out", str(d))
    assert rc == 0, err
    assert "max horizontal" not in out and "alignment only" in out
    for v in json.loads((d / "summary.json").read_text())["variants"]:
        assert not any(k.startswith(("horizontal_error", "velocity_error")) for k in v["metrics"])
    assert not (d / "comparison.png").exists()


def test_comparison_draws_a_paper_bound_as_a_bound(finished, tmp_path, capsys, monkeypatch):
    # workflow: seed003's "< 1.1 nmi" was drawn as a 1.1 nmi bar beside ours
    import matplotlib.axes
    bars = []
    real = matplotlib.axes.Axes.bar
    monkeypatch.setattr(matplotlib.axes.Axes, "bar",
                        lambda self, *a, **k: bars.append(k.get("label")) or real(self, *a, **k))
    d = tmp_path / "run"
    shutil.copytree(finished, d)
    rc, _, err = _report(capsys, d)
    assert rc == 0, err
    assert bars and not any(str(b).startswith("paper") for b in bars), bars


@pytest.mark.parametrize("argv, says", [
    (["run", "seed003", "--hours", "0"], "--hours 0"),
    (["run", "seed003", "--hours", "nan"], "--hours nan"),
    (["run", "seed003", "--hours", "1e9"], "--hours 1e+09"),
    (["simulate", "seed003", "LOG.bin", "--hours", "inf"], "--hours inf"),
    (["simulate", "seed003", "LOG.bin", "--format", "bogus"], "--format bogus"),
    (["demo", "--hours", "1e12"], "--hours 1e+12"),
    (["demo", "--seed", "-1"], "--seed -1"),
    (["run", "seed003", "--out", "AFILE"], "--out"),
    (["demo", "--out", "AFILE"], "--out"),
])
def test_a_bad_option_value_is_one_line_naming_the_option(tmp_path, capsys, argv, says):
    # item 23: "fmt 'bogus'" (a Python argument), "expected non-negative integer", a demo of 1e12 h
    # that ran, "File exists" for an --out that is a file
    (tmp_path / "afile").write_text("mine")
    argv = [str(tmp_path / "afile") if a == "AFILE" else str(tmp_path / "x.bin") if a == "LOG.bin" else a
            for a in argv]
    rc = cli.main(argv)
    err = capsys.readouterr().err
    assert rc == 2 and says in err and len(err.strip().splitlines()) == 1, err
    assert (tmp_path / "afile").read_text() == "mine"


def test_simulate_says_what_it_is_doing_while_it_writes(tmp_path, capsys):
    """A long `pyins simulate` (72 h of seed002_exp1 took 98 s) printed
    nothing until it ended: it names the step on stderr and draws its bar
    there as the chunks come; --quiet keeps it silent."""
    log = tmp_path / "x.npz"
    assert cli.main(["simulate", "demo", str(log), "--hours", "0.01"]) == 0
    err = capsys.readouterr().err
    assert "simulating 0.01 h of demo" in err
    assert cli.main(["simulate", "demo", str(tmp_path / "y.npz"), "--hours", "0.01", "--quiet"]) == 0
    assert capsys.readouterr().err == ""


def test_demo_keeps_quiet_and_json_as_every_subcommand(tmp_path, capsys):
    """`pyins demo --quiet` printed its four lines all the same, and
    `--json` printed them and no JSON: --quiet prints nothing, --json one
    JSON object, the summary.json it wrote."""
    assert cli.main(["demo", "--hours", "0.01", "--out", str(tmp_path / "q"), "--quiet"]) == 0
    assert capsys.readouterr().out == ""
    assert cli.main(["demo", "--hours", "0.01", "--out", str(tmp_path / "j"), "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed == json.loads((tmp_path / "j" / "summary.json").read_text())
