"""``pyins replay`` as a user with a field log meets it (docs/cli.md, "pyins
replay LOG"): the rate
is the log's, an attitude nobody gave is refused, the firmware's limits are
stated in the user's options, a log that ends mid-alignment says so."""
import json

import numpy as np
import pytest

from pyins import __main__ as cli
from pyins import logs, sim
from pyins.sim.io import ImuData
from pyins.units import ARCSEC_TO_RAD, DEG_TO_RAD

LAT, LON = 34.246, 108.91
#: a parked vehicle facing 90.8 deg (PSINS's real laser-gyro log sits so)
SITE = sim.Static(LAT * DEG_TO_RAD, LON * DEG_TO_RAD, 0.0, 0.0, 0.0, -90.8 * DEG_TO_RAD)
SITE_ARGS = ["--time-col", "first", "--axes", "frd", "--lat", str(LAT), "--lon", str(LON),
             "--height", "0"]


def _text_log(path, hz, seconds=60.0):
    """The parked vehicle's exact increments at ``hz`` as a time-first,
    forward-right-down text log (the KF-GINS layout)."""
    dt = 1.0 / hz
    n = int(round(seconds * hz))
    th, dv, _ = sim.imu.exact_increments(SITE, n, dt=dt)
    data = ImuData(tick=np.arange(1, n + 1, dtype=np.int64), dtheta_p=th, dv_p=dv,
                   table_angle_rad=np.zeros(n), dt=dt, metadata={})
    logs.write_log(str(path), data, fmt="text", time_col="first", axes="frd", table=False)
    return path


def _replay(tmp_path, log, *extra, name="out"):
    out = tmp_path / name
    rc = cli.main(["replay", str(log), *SITE_ARGS, "--out", str(out), "--quiet", *extra])
    summary = json.loads((out / "summary.json").read_text()) if rc == 0 else None
    return rc, summary


@pytest.fixture(scope="module")
def two_rates(tmp_path_factory):
    d = tmp_path_factory.mktemp("rates")
    return _text_log(d / "log100.txt", 100), _text_log(d / "log200.txt", 200)


def test_a_200_hz_log_aligns_as_the_same_motion_at_100_hz(tmp_path, two_rates):
    """Defect 1: the rate comes from the log's time column. Before, the 200 Hz
    log ran as 100 Hz (half the time, the wrong Earth rate) and drifted off."""
    got = {}
    for log in two_rates:
        rc, summary = _replay(tmp_path, log, "--coarse", "40", name=log.stem)
        assert rc == 0
        got[log.stem] = summary
    a, b = got["log100"]["aligned"], got["log200"]["aligned"]
    assert a["time_s"] == b["time_s"] == 40.0
    # 1": the acceptance figure; error-free increments of the same motion differ
    # only in how the tick splits the same integrals, far below it
    for k in ("pitch_deg", "roll_deg", "heading_deg"):
        assert abs(a[k] - b[k]) * DEG_TO_RAD < 1.0 * ARCSEC_TO_RAD, k
    # and the vehicle stays parked: 20 s of navigation from an attitude good
    # to arc-seconds moves it by centimetres, not the metres a wrong rate gives
    for s in got.values():
        assert s["warnings"] == []
        assert abs(s["final"]["lat_deg"] - LAT) * DEG_TO_RAD * 6.4e6 < 1.0     # 1 m
        assert abs(s["final"]["lon_deg"] - LON) * DEG_TO_RAD * 6.4e6 < 1.0


def test_a_rate_that_disagrees_or_is_not_whole_is_refused(tmp_path, two_rates, capsys):
    rc, _ = _replay(tmp_path, two_rates[1], "--coarse", "40", "--rate", "100")
    assert rc == cli.EXIT_INPUT
    assert "--rate 100 Hz disagrees with the log" in capsys.readouterr().err
    odd = _text_log(tmp_path / "odd.txt", 150.5, seconds=30.0)
    rc, _ = _replay(tmp_path, odd, "--coarse", "25")
    assert rc == cli.EXIT_INPUT
    assert "not a whole number of Hz" in capsys.readouterr().err


def test_no_attitude_and_no_alignment_is_refused(tmp_path, two_rates, capsys):
    """Defect 2: without --attitude or --coarse the firmware would start level
    facing north and report kilometres with exit 0."""
    rc, _ = _replay(tmp_path, two_rates[0])
    assert rc == cli.EXIT_INPUT
    err = capsys.readouterr().err
    assert "no initial attitude" in err and "--attitude" in err and "--coarse" in err
    rc, _ = _replay(tmp_path, two_rates[0], "--attitude", "0", "0", "-90.8")
    assert rc == 0


@pytest.mark.parametrize("extra, says", [
    (["--coarse", "300"], "lasts at most 255 s, not 300 s: a 2 s interval (--coarse-every) allows 510 s, "
                          "and --coarse-method fit has no length limit"),
    (["--coarse", "10"], "--coarse: a coarse alignment of 10 s ends before its first solution at 20 s"),
    (["--coarse", "40", "--lat", "95"], "--lat: 95 deg is outside +-89.9 deg"),
    (["--coarse", "40", "--coarse-method", "fit", "--coarse-every", "5"], "FIT needs 8 output intervals"),
    (["--coarse", "40", "--fine-sigma0", "10", "10", "60"], "--fine-sigma0 '10': missing unit"),
])
def test_firmware_limits_are_stated_in_the_users_options(tmp_path, two_rates, capsys, extra, says):
    """Defect 7: not "PYINS_E_CONFIG_ALIGN_LONG ... 255 output intervals"."""
    rc, _ = _replay(tmp_path, two_rates[0], *extra)
    assert rc == cli.EXIT_INPUT
    err = capsys.readouterr().err
    assert says in err and "PYINS_E" not in err, err


def test_the_options_reach_the_firmware(tmp_path, two_rates):
    """FIT beyond TRIAD's 255 intervals, the 8-state filter with its sigma0:
    each option changes what the firmware does."""
    rc, s = _replay(tmp_path, two_rates[0], "--coarse", "30", "--coarse-method", "fit", "--fine", "20",
                    "--fine-states", "8", "--fine-sigma0", "10'", "10'", "60'")
    assert rc == 0 and s["aligned"]["time_s"] == 50.0
    # 20 s of fine alignment cannot bring the heading sigma under 10': said, not hidden
    assert len(s["warnings"]) == 1 and "the fine alignment left a heading sigma of" in s["warnings"][0]
    rec = np.load(tmp_path / "out" / "navigation.npz")["outputs"]
    # the fine phase ran the 8-state filter: its kf_x holds 8 states (5 would leave 5..7 at zero)
    fine = rec[rec["mode"] == 2]
    assert len(fine) and np.any(fine["kf_x"][:, 5:8] != 0.0)


def test_a_log_that_ends_mid_alignment_says_so(tmp_path, two_rates, capsys):
    rc, s = _replay(tmp_path, two_rates[0], "--coarse", "50", "--fine", "30")
    assert rc == 0 and "aligned" not in s
    assert any("ended during fine alignment" in w for w in s["warnings"])
    assert "WARNING: the log ended during fine alignment" in capsys.readouterr().err


def test_a_reader_that_closes_the_pipe_is_not_an_error():
    """Defect 8: ``pyins list | head`` printed "Broken pipe" and exited 2."""
    import subprocess
    import sys
    # a reader that takes one line and goes: many lines so the writer meets the closed pipe
    p = subprocess.run(f"'{sys.executable}' -m pyins list --paths | head -c 1 >/dev/null; "
                       f"'{sys.executable}' -m pyins list --paths --json | head -c 1 >/dev/null; "
                       "echo ${PIPESTATUS[0]}", shell=True, executable="/bin/bash",
                       capture_output=True, text=True, cwd="/")
    assert "Broken pipe" not in p.stderr and "Error" not in p.stderr, p.stderr
    assert p.stdout.split()[-1] in ("0", str(cli.EXIT_BROKEN_PIPE))


def test_make_samples_takes_the_columns_of_a_text_log(two_rates):
    """Defect 8: the documented path make_samples(d.dtheta_p, ...) raised
    "array is not C-contiguous" for every text log."""
    from pyins import native
    d = logs.read_log(str(two_rates[0]), time_col="first", axes="frd")
    s = native.make_samples(d.dtheta_p, d.dv_p, d.table_angle_rad)
    assert len(s) == len(d.tick) and np.array_equal(s["dv_p_mps"], d.dv_p)


def test_a_replay_writes_a_report_with_the_alignment_and_the_errors_against_the_site(tmp_path, two_rates):
    """Defect 10 (first part): replay wrote no report and no plots. With
    ``--reference parked`` the errors are against the site and zero velocity."""
    rc, s = _replay(tmp_path, two_rates[1], "--coarse", "30", "--fine", "25", "--reference", "parked")
    assert rc == 0
    out = tmp_path / "out"
    for f in ("report.html", "attitude.png", "alignment.png", "errors.png", "errors.npz"):
        assert (out / f).exists(), f
    page = (out / "report.html").read_text(encoding="utf-8")
    assert "aligned attitude" in page and "heading sigma" in page and "against the site" in page
    fa = s["fine_alignment"]
    assert fa["states"] == 5 and fa["sigma_heading_arcmin"] > 0 and len(fa["drift_nu_dph"]) == 2
    # error-free increments of a parked vehicle: it stays within centimetres of
    # the site over 55 s (a wrong rate or attitude gives metres to kilometres)
    er = s["errors"]
    assert er["reference"].startswith("the site") and er["horizontal_max_m"] < 0.1
    with np.load(out / "errors.npz") as z:
        assert set(z.files) == {"time_s", "north_m", "east_m", "vel_n_mps"}
    # pyins report re-renders a replay directory
    (out / "report.html").unlink()
    assert cli.main(["report", str(out), "--quiet"]) == 0 and (out / "report.html").exists()


def test_a_log_shorter_than_one_record_is_a_clear_error(tmp_path, capsys):
    """Was an IndexError ("internal error", exit 1) at the first record."""
    log = _text_log(tmp_path / "short.txt", 100, seconds=0.5)
    rc, _ = _replay(tmp_path, log, "--attitude", "0", "0", "-90.8")
    assert rc == cli.EXIT_INPUT
    assert "fewer than one record interval" in capsys.readouterr().err


def test_a_psins_log_names_its_site(tmp_path, capsys):
    """PSINS's .imu header holds the site: used when the user gives none, and
    said; the real log (tests/data) aligns and stays parked there."""
    from pathlib import Path
    log = Path(__file__).resolve().parents[1] / "data" / "lasergyro_300s.imu.gz"
    out = tmp_path / "real"
    assert cli.main(["replay", str(log), "--coarse", "60", "--reference", "parked", "--out", str(out)]) == 0
    said = capsys.readouterr().out
    assert "site from the log's header: 34.246048 N 108.909664 E 380.0 m" in said
    s = json.loads((out / "summary.json").read_text())
    # 240 s of free inertial navigation after a 60 s coarse alignment of a
    # navigation-grade RLG: metres, not the kilometres of a wrong site or rate
    # (g eps t^3 / 6 with eps ~ 0.5 deg/h over 240 s is ~50 m)
    assert s["errors"]["horizontal_max_m"] < 50.0 and s["aligned"]["time_s"] == 60.0
