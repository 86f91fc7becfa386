"""``pyins replay`` tried as a careful user tries it: bad values, logs that
are damaged or of another kind, pipes, a directory used twice (docs/cli.md,
"pyins replay LOG"). Each test failed on the code before its fix."""
import gzip
import json
import os
import subprocess
import sys

import numpy as np
import pytest

from pyins import __main__ as cli
from pyins import logs, sim
from pyins.sim.io import ImuData
from pyins.units import DEG_TO_RAD

LAT, LON = 34.246, 108.91
SITE = sim.Static(LAT * DEG_TO_RAD, LON * DEG_TO_RAD, 0.0, 0.0, 0.0, -90.8 * DEG_TO_RAD)
SITE_ARGS = ["--time-col", "first", "--axes", "frd", "--lat", str(LAT), "--lon", str(LON), "--height", "0"]
PSINS = os.path.join(os.path.dirname(__file__), "..", "data", "lasergyro_300s.imu.gz")
RATES = ["--kind", "rates", "--gyro-unit", "deg/s", "--accel-unit", "g", "--axes", "frd", "--time-col", "first"]


def _text_log(path, hz=100, seconds=60.0):
    dt = 1.0 / hz
    n = int(round(seconds * hz))
    th, dv, _ = sim.imu.exact_increments(SITE, n, dt=dt)
    data = ImuData(tick=np.arange(1, n + 1, dtype=np.int64), dtheta_p=th, dv_p=dv,
                   table_angle_rad=np.zeros(n), dt=dt, metadata={})
    logs.write_log(str(path), data, fmt="text", time_col="first", axes="frd", table=False)
    return path


@pytest.fixture(scope="module")
def log100(tmp_path_factory):
    return _text_log(tmp_path_factory.mktemp("log") / "log100.txt")


def _run(argv, capsys):
    rc = cli.main(argv)
    out = capsys.readouterr()
    return rc, out.out, out.err


def _refused(capsys, argv, *says):
    rc, _, err = _run(argv, capsys)
    assert rc == cli.EXIT_INPUT, err
    line = err.strip()
    assert len(line.splitlines()) == 1 and "Traceback" not in err and "internal error" not in err, err
    for s in says:
        assert s in line, line
    return line


# -- 1. a time that rounds to zero ticks ---------------------------------------------------------------
@pytest.mark.parametrize("extra, says", [
    (["--coarse", "60", "--coarse-every", "0.001"], ["--coarse-every", "0.001 s rounds to 0 ticks at 100 Hz"]),
    (["--coarse", "60", "--coarse-every", "0"], ["--coarse-every", "0 s is not an interval"]),
    (["--attitude", "0", "0", "-90.8", "--coarse", "0.004"], ["--coarse", "rounds to 0 ticks"]),
    (["--coarse", "40", "--fine", "0.001"], ["--fine", "rounds to 0 ticks"]),
    (["--coarse", "40", "--every", "0"], ["--every 0"]),
    (["--coarse", "40.005"], ["--coarse", "40.005 s is not a whole number of ticks at 100 Hz", "40 s or 40.01 s"]),
    (["--coarse", "40", "--every", "-3"], ["--every -3"]),
])
def test_a_time_that_rounds_to_zero_ticks_is_refused(tmp_path, log100, capsys, extra, says):
    """Before: --coarse-every 0.001 became 0 ticks, which the core reads as its
    1 s default (exit 0, no word); --every 0 became 1."""
    _refused(capsys, ["replay", str(log100), *SITE_ARGS, "--out", str(tmp_path / "o"), "--quiet", *extra], *says)


# -- 2. a 0 the core reads as "the default" --------------------------------------------------------------
@pytest.mark.parametrize("extra, option", [
    (["--gyro-arw", "0 deg/sqrt(h)"], "--gyro-arw"),
    (["--accel-vrw", "0 ug/sqrt(Hz)"], "--accel-vrw"),
    (["--fine-sigma0", "0'", "10'", "60'"], "--fine-sigma0"),
    (["--gyro-arw", "-0.001 deg/sqrt(h)"], "--gyro-arw"),
    (["--accel-vrw", "100 mg/sqrt(Hz)"], "--accel-vrw"),
])
def test_a_zero_noise_or_sigma_is_refused_not_defaulted(tmp_path, log100, capsys, extra, option):
    """Before: 0 passed through and the firmware used its default (exit 0); a
    scenario file refuses the same 0."""
    _refused(capsys, ["replay", str(log100), *SITE_ARGS, "--out", str(tmp_path / "o"), "--quiet",
                      "--coarse", "30", "--fine", "20", *extra], option, "must be more than", "and at most")


# -- 3. a PSINS header that lost a line ------------------------------------------------------------------
@pytest.mark.parametrize("lost, says", [(4, "header line 3 (the scale factors"), (3, "header line 2 gives g")])
def test_a_psins_file_that_lost_a_header_line_is_refused(tmp_path, capsys, lost, says):
    """Before: the first data line was read as the scale factors: exit 0, NaN
    attitude and position, "faults 0"."""
    kept, n = [], 0
    with gzip.open(PSINS, "rt") as f:
        for line in f:
            if not line.startswith("%"):
                n += 1
                if n == lost:
                    continue
            kept.append(line)
    bad = tmp_path / "lost.imu"
    bad.write_text("".join(kept))
    _refused(capsys, ["replay", str(bad), "--coarse", "120", "--reference", "parked", "--out",
                      str(tmp_path / "o"), "--quiet"], "lost.imu", says, "missing")


# -- 4. a directory that holds an earlier replay -------------------------------------------------------
def test_a_replay_replaces_an_earlier_replay_in_its_directory(tmp_path, log100, capsys):
    """Before: the earlier replay's errors.npz/errors.png stayed, and the new
    page drew them as the new replay's."""
    out = tmp_path / "o"
    base = ["replay", str(log100), *SITE_ARGS, "--out", str(out), "--quiet", "--coarse", "40"]
    assert cli.main(base + ["--reference", "parked"]) == 0
    assert (out / "errors.npz").exists() and (out / "errors.png").exists()
    assert cli.main(base) == 0                     # no reference this time
    assert not (out / "errors.npz").exists() and not (out / "errors.png").exists()
    assert "errors.png" not in (out / "report.html").read_text()
    # a directory with something else in it is not a replay's to clear
    (out / "notes.txt").write_text("mine")
    _refused(capsys, base, "--out", "notes.txt", "not a replay's")
    assert (out / "notes.txt").read_text() == "mine"
    # nor is the log being replayed, whatever its name
    (out / "notes.txt").unlink()
    log = out / "errors.npz"
    logs.write_log(str(log), logs.read_log(str(log100), time_col="first", axes="frd"))
    _refused(capsys, ["replay", str(log), "--lat", str(LAT), "--lon", str(LON), "--height", "0", "--coarse", "40",
                      "--out", str(out), "--quiet"], "holds the log being replayed")
    assert log.exists()


# -- 7. a rates log with a gap -------------------------------------------------------------------------
@pytest.fixture(scope="module")
def demo_rates(tmp_path_factory):
    """The demo scenario's 30 min log as deg/s and g, FRD, a time column; and
    the same with 10 samples removed after data line 1001 (0.11 s step)."""
    d = tmp_path_factory.mktemp("demo")
    subprocess.run([sys.executable, "-m", "pyins", "simulate", "demo", str(d / "demo.npz"), "--hours", "0.5",
                    "--quiet"], check=True)
    data = logs.read_log(str(d / "demo.npz"))
    out = {}
    for kind, kw in (("rates", dict(kind="rates", gyro_unit="deg/s", accel_unit="g")), ("increments", {})):
        full = d / f"{kind}.txt"
        logs.write_log(str(full), data, fmt="text", axes="frd", time_col="first", table=False, **kw)
        lines = full.read_text().splitlines(True)
        head = [ln for ln in lines if ln.startswith("%")]
        body = [ln for ln in lines if not ln.startswith("%")]
        gap = d / f"{kind}_gap.txt"
        gap.write_text("".join(head + body[:1001] + body[1011:]))
        out[kind] = (full, gap)
    return out


def _json(argv):
    r = subprocess.run([sys.executable, "-m", "pyins", *argv, "--json"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


@pytest.mark.parametrize("kind", ["rates", "increments"])
def test_a_gap_in_a_rates_log_is_bridged_like_one_in_an_increments_log(tmp_path, demo_rates, kind):
    """Before: the first rate after a 0.1 s gap became 11 ticks' worth and the
    bridge ramped towards it: 24.2 km and -184.9' after 30 min, against 0.70 km
    and 0.17' without the gap."""
    full, gap = demo_rates[kind]
    opts = (RATES if kind == "rates" else ["--axes", "frd", "--time-col", "first"]) + ["--scenario", "demo"]
    a = _json(["replay", str(full), *opts, "--out", str(tmp_path / "full")])["errors"]
    b = _json(["replay", str(gap), *opts, "--out", str(tmp_path / "gap"), "--allow-gaps"])["errors"]
    # What 10 interpolated ticks (0.1 s) can cost: the bridge misses the change of the
    # swing's specific force and rate within 0.1 s; a velocity error of ~0.01 m/s (0.1 m/s^2
    # of unmodelled change x 0.1 s) or a tilt of ~2" (1e-5 rad) drives a Schuler oscillation of
    # v/omega_s = 0.01/1.24e-3 ~ 8 m or R x tilt = 6.4e6 x 1e-5 ~ 64 m: 100 m covers both.
    # The heading: 0.1 s of a 6 deg/s swing mis-bridged by a tenth is 0.06 deg of transient
    # attitude, corrected by nothing in 30 min only to the extent it is azimuth: 1' bounds it.
    assert abs(b["horizontal_final_m"] - a["horizontal_final_m"]) < 100.0, (a, b)
    assert b["horizontal_max_m"] < 2.0 * a["horizontal_max_m"] + 100.0, (a, b)
    assert abs(b["heading_final_arcmin"] - a["heading_final_arcmin"]) < 1.0, (a, b)


# -- 9. the warnings printed are the warnings kept -------------------------------------------------------
def test_the_gap_warnings_are_kept_in_summary_json_and_page(tmp_path, log100):
    lines = log100.read_text().splitlines(True)
    body = [i for i, ln in enumerate(lines) if not ln.startswith("%")]
    gap = tmp_path / "gap.txt"
    gap.write_text("".join(ln for i, ln in enumerate(lines) if i not in body[1001:1011]))
    out = tmp_path / "o"
    r = subprocess.run([sys.executable, "-m", "pyins", "replay", str(gap), *SITE_ARGS, "--coarse", "40",
                        "--allow-gaps", "--out", str(out)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    printed = [ln.split("WARNING: ", 1)[1] for ln in r.stderr.splitlines() if "WARNING: " in ln]
    assert any("gap of" in w for w in printed) and any("bridged" in w for w in printed), r.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["warnings"] == printed
    page = (out / "report.html").read_text()
    assert "No warnings" not in page and "bridged" in page
    js = _json(["replay", str(gap), *SITE_ARGS, "--coarse", "40", "--allow-gaps", "--out", str(tmp_path / "j")])
    assert js["warnings"] == printed


# -- 15, 16. the messages name the command line's options and say what the file is ----------------------
def _binary(path, log100):
    data = logs.read_log(str(log100), time_col="first", axes="frd")
    logs.write_log(str(path), data, fmt="binary")
    return path


def test_a_binary_log_given_as_text_names_format(tmp_path, log100, capsys):
    for name in ("log.txt", "log.txt.gz"):
        bad = _binary(tmp_path / "x.bin", log100)
        os.replace(bad, tmp_path / name)
        line = _refused(capsys, ["replay", str(tmp_path / name), *SITE_ARGS, "--coarse", "40", "--out",
                                 str(tmp_path / "o"), "--quiet"], "--format binary")
        assert "fmt=" not in line
        if name.endswith(".gz"):
            assert "not a gzip file" in line
    os.replace(_binary(tmp_path / "x.bin", log100), tmp_path / "noext")
    line = _refused(capsys, ["replay", str(tmp_path / "noext"), "--coarse", "40", "--out", str(tmp_path / "o"),
                             "--quiet"], "--format")
    assert "fmt" not in line


def test_a_log_without_time_takes_its_rate_from_rate(tmp_path, log100, capsys):
    """--help says --rate is needed for a log with neither time nor dt; before,
    the reader asked for "dt" and ignored --rate."""
    data = logs.read_log(str(log100), time_col="first", axes="frd")
    plain = tmp_path / "plain.txt"
    logs.write_log(str(plain), data, fmt="text", time_col="none", table=False)
    base = ["replay", str(plain), "--time-col", "none", "--lat", str(LAT), "--lon", str(LON), "--height", "0",
            "--coarse", "40", "--out", str(tmp_path / "o"), "--quiet"]
    line = _refused(capsys, base, "--rate")
    assert "dt" not in line.replace("--dt", "")
    rc, _, err = _run(base + ["--rate", "100"], capsys)
    assert rc == 0, err
    assert json.loads((tmp_path / "o" / "summary.json").read_text())["rate_hz"] == 100


def test_a_long_coarse_interval_names_coarse_every(tmp_path, log100, capsys):
    line = _refused(capsys, ["replay", str(log100), *SITE_ARGS, "--coarse", "40", "--coarse-every", "100",
                             "--out", str(tmp_path / "o"), "--quiet"], "--coarse-every")
    assert "_ticks" not in line


def test_an_imu_file_that_is_not_psins_says_how_to_read_it(tmp_path, log100, capsys):
    other = tmp_path / "field.imu"
    other.write_text(log100.read_text())
    _refused(capsys, ["replay", str(other), *SITE_ARGS[4:], "--coarse", "40", "--out", str(tmp_path / "o"),
                      "--quiet"], "field.imu", "not a PSINS", "--format text")
    # with the options of its real layout: they do not apply to PSINS, and the way out is named
    line = _refused(capsys, ["replay", str(other), *SITE_ARGS, "--coarse", "40", "--out", str(tmp_path / "o"),
                             "--quiet"], "field.imu", "--time-col", "--format text")
    assert "time_col" not in line


# -- 17. a pipe is read once; '-' is standard input --------------------------------------------------------
def test_a_log_from_a_pipe_or_stdin_replays_as_the_file(tmp_path, log100):
    packed = tmp_path / "log.txt.gz"
    packed.write_bytes(gzip.compress(log100.read_bytes()))
    want = _json(["replay", str(log100), *SITE_ARGS, "--coarse", "40", "--out", str(tmp_path / "f")])
    for src in ("/dev/stdin", "-"):
        r = subprocess.run(f"gzip -dc {packed} | {sys.executable} -m pyins replay {src} --format text "
                           f"{' '.join(SITE_ARGS)} --coarse 40 --out {tmp_path / 'p'} --json",
                           shell=True, capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        got = json.loads(r.stdout)
        assert got["final"] == want["final"] and got["samples"] == want["samples"]
        assert got["log"] == ("standard input" if src == "-" else "/dev/stdin")
    r = subprocess.run(f"cat {log100} | {sys.executable} -m pyins replay - {' '.join(SITE_ARGS)} --coarse 40 "
                       f"--out {tmp_path / 'p'} --quiet", shell=True, capture_output=True, text=True)
    assert r.returncode == 2 and "standard input" in r.stderr and "--format" in r.stderr, r.stderr


# -- what it prints -------------------------------------------------------------------------------------
def test_what_it_prints_is_one_figure_and_names(tmp_path, log100, capsys):
    rc, out, err = _run(["replay", str(log100), *SITE_ARGS, "--coarse", "30", "--fine", "20", "--out",
                         str(tmp_path / "o")], capsys)
    assert rc == 0, err
    s = json.loads((tmp_path / "o" / "summary.json").read_text())
    sigma = f"{s['fine_alignment']['sigma_heading_arcmin']:.2f}'"
    assert f"heading sigma {sigma}" in out and f"heading sigma of {sigma}" in err, (out, err)
    assert "navigation, faults none" in out and "mode 3" not in out
    # an alignment over the whole log compares nothing: said, not "max horizontal 0.00 m"
    rc, out, err = _run(["replay", str(log100), *SITE_ARGS, "--coarse", "70", "--reference", "parked",
                         "--out", str(tmp_path / "a")], capsys)
    assert rc == 0, err
    assert "nothing compared" in out and "0.00 m" not in out and "coarse alignment, faults" in out, out
    assert "nothing compared" in (tmp_path / "a" / "report.html").read_text()


# -- 23. bad values and bad logs: one line, exit 2 -----------------------------------------------------
@pytest.mark.parametrize("extra, says", [
    (["--attitude", "1e30", "0", "0"], "--attitude"),
    (["--attitude", "100", "0", "0"], "--attitude"),
    (["--table-angle", "1e30"], "--table-angle"),
    (["--dt", "nan"], "--dt"),
    (["--gyro-scale", "0"], "--gyro-scale"),
    (["--coarse", "1e12"], "--coarse"),
    (["--every", "99999999999999999999"], "--every"),
])
def test_a_value_out_of_range_is_refused(tmp_path, log100, capsys, extra, says):
    """Before: --attitude 1e30, --table-angle 1e30 ran (exit 0); --every 1e20 was an
    internal error (OverflowError)."""
    _refused(capsys, ["replay", str(log100), *SITE_ARGS, "--coarse", "40", "--out", str(tmp_path / "o"),
                      "--quiet", *extra], says)


@pytest.mark.parametrize("content", [b"", b"PK\x03\x04 cut"])
def test_an_empty_or_cut_npz_is_refused_in_one_line(tmp_path, capsys, content):
    """Before: "internal error EOFError" / "BadZipFile", exit 1."""
    bad = tmp_path / "log.npz"
    bad.write_bytes(content)
    _refused(capsys, ["replay", str(bad), "--lat", "1", "--lon", "1", "--height", "0", "--coarse", "40",
                      "--out", str(tmp_path / "o"), "--quiet"], "log.npz", "not a readable .npz")


def test_an_npz_of_other_arrays_names_columns(tmp_path, capsys):
    other = tmp_path / "other.npz"
    np.savez(other, outputs=np.zeros(3))
    line = _refused(capsys, ["replay", str(other), "--lat", "1", "--lon", "1", "--height", "0", "--coarse", "40",
                             "--out", str(tmp_path / "o"), "--quiet"], "other.npz", "--columns gyro=NAME")
    assert "columns={" not in line


def test_axes_declared_wrong_are_warned_and_reader_names_are_options(tmp_path, log100, capsys):
    """Before: an FRD log read as RFU aligned upside down (roll -180 deg) with no
    word; --gyro-unit bogus was named gyro_unit and kind='increments'."""
    args = ["replay", str(log100), "--time-col", "first", "--lat", str(LAT), "--lon", str(LON), "--height", "0",
            "--coarse", "40", "--out", str(tmp_path / "o"), "--quiet"]
    rc, _, err = _run(args + ["--axes", "rfu"], capsys)
    assert rc == 0 and "upside down" in err and "--axes" in err, err
    s = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert any("upside down" in w for w in s["warnings"])
    line = _refused(capsys, args + ["--axes", "frd", "--gyro-unit", "bogus"], "--gyro-unit 'bogus'", "--kind increments")
    assert "gyro_unit" not in line and "kind=" not in line


def test_a_log_without_gravity_names_options_only(tmp_path, log100, capsys):
    """Before: "check accel_unit and kind (plausibility=False ...)": Python names,
    and a way out the command line does not have."""
    line = _refused(capsys, ["replay", str(log100), "--axes", "frd", "--time-col", "none", "--rate", "100000",
                             "--lat", str(LAT), "--lon", str(LON), "--height", "0", "--coarse", "40", "--out",
                             str(tmp_path / "o"), "--quiet"], "--accel-unit", "--kind")
    assert "plausibility" not in line and "accel_unit" not in line


def test_a_text_log_read_as_npz_and_columns_on_text_name_options(tmp_path, log100, capsys):
    """Before: numpy's 'pickled (object) data ... allow_pickle=' for a text file
    given --format npz, and 'columns= names CSV header columns' for --columns."""
    base = ["replay", str(log100), *SITE_ARGS, "--coarse", "40", "--out", str(tmp_path / "o"), "--quiet"]
    line = _refused(capsys, base + ["--format", "npz"], "log100.txt", "not a zip archive")
    assert "pickle" not in line
    line = _refused(capsys, base + ["--columns", "t=time"], "--columns", "--format text")
    assert "columns=" not in line
