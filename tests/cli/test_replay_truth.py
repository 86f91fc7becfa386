"""``pyins replay --truth FILE`` (docs/cli.md, "pyins replay LOG": where the
user gives a reference, the errors against it): a reference trajectory on the
log's clock, interpolated at the records, north/east and heading errors.

The log is simulated (the demo ship: seed 002's heading swing, 6 deg/s at
its peak, seed 002's sensor errors), so the scenario's own truth is an
independent reference: the errors against the track written from that truth
must be the errors against the scenario."""
import json
import os

import numpy as np
import pytest

from pyins import __main__ as cli
from pyins import logs, scenario, sim
from pyins.units import ARCMIN_TO_RAD, DEG_TO_RAD

SECONDS = 180.0


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    d = tmp_path_factory.mktemp("truth")
    log = d / "demo.txt"
    assert cli.main(["simulate", "demo", str(log), "--hours", str(SECONDS / 3600), "--quiet"]) == 0
    spec = list(scenario.load("demo").with_overrides({"duration": f"{SECONDS} s"}).runs())[0]
    return d, log, spec


def _track(path, spec, log, every=10, heading_offset_deg=0.0, north_offset_m=0.0, span=None):
    """The scenario's truth at 10 Hz epochs as a track file on the log's clock."""
    t_first = logs.LogReader(str(log)).metadata["t_first"]
    n = int(round(SECONDS / spec.dt))
    ticks = np.unique(np.r_[np.arange(1, n + 1, every), n])     # the last sample too
    if span is not None:
        ticks = ticks[(ticks * spec.dt >= span[0]) & (ticks * spec.dt <= span[1])]
    tr = sim.truth_at(spec.motion, ticks, dt=spec.dt)
    lat = np.degrees(tr.lat) + np.degrees(north_offset_m / 6_356_000.0)
    heading = np.mod(-np.degrees(tr.euler[:, 2]) + heading_offset_deg, 360.0)
    t = t_first + (ticks - 1) * spec.dt
    with open(path, "w") as f:
        f.write("# the demo's truth\nt, lat_deg, lon_deg, height_m, heading_deg\n")
        for row in zip(t, lat, np.degrees(tr.lon), tr.height, heading):
            f.write(", ".join(f"{v:.12f}" for v in row) + "\n")
    return path


def _replay(d, log, name, *extra):
    out = d / name
    rc = cli.main(["replay", str(log), "--out", str(out), "--quiet", *extra])
    s = json.loads((out / "summary.json").read_text()) if rc == 0 else None
    e = dict(np.load(out / "errors.npz")) if rc == 0 else None
    return rc, s, e


def test_the_track_of_the_truth_gives_the_scenarios_errors(demo, tmp_path):
    d, log, spec = demo
    rc, s_scn, e_scn = _replay(tmp_path, log, "scn", "--scenario", "demo")
    assert rc == 0
    for off in (0.0, 30.0):
        track = _track(tmp_path / f"track{off}.csv", spec, log, heading_offset_deg=off, north_offset_m=2 * off)
        # the same firmware start (the scenario's), the errors against the track instead
        rc, s, e = _replay(tmp_path, log, f"trk{off}", "--scenario", "demo", "--truth", str(track))
        assert rc == 0
        assert s["errors"]["compared"] == len(e["time_s"]) == len(e_scn["time_s"])
        np.testing.assert_array_equal(e["time_s"], e_scn["time_s"])
        # 1 mm: the track is the truth to 1e-12 deg in print; a track 2 x off m north gives an error
        # 2 x off m less; an east error independent of it
        np.testing.assert_allclose(e["north_m"], e_scn["north_m"] - 2 * off, atol=1e-3)
        np.testing.assert_allclose(e["east_m"], e_scn["east_m"], atol=1e-3)
        # heading: the firmware's heading less the track's. 0.05': what 10 Hz epochs leave of a
        # 6 deg/s swing between them (<= 0.02'); one tick off in time would give 3.6'
        assert s["errors"]["heading_final_arcmin"] == pytest.approx(
            e["heading_rad"][-1] / ARCMIN_TO_RAD)
        if off == 0.0:
            base = e["heading_rad"]
            assert np.max(np.abs(base)) < 1.0 * ARCMIN_TO_RAD       # the firmware is aligned to arc-minutes
        else:
            np.testing.assert_allclose(e["heading_rad"], base - off * DEG_TO_RAD, atol=0.05 * ARCMIN_TO_RAD)
    assert s["warnings"] == []


def test_records_outside_the_track_are_counted_and_said(demo, tmp_path):
    d, log, spec = demo
    track = _track(tmp_path / "half.csv", spec, log, span=(0.0, 90.0))
    rc, s, e = _replay(tmp_path, log, "half", "--scenario", "demo", "--truth", str(track))
    assert rc == 0
    # records every 100 ticks; the track's last epoch is tick 8991 (<= 90 s): 89 records inside
    assert s["errors"]["compared"] == len(e["time_s"]) == 89
    assert any("91 of 180 records lie outside the time span" in w for w in s["warnings"])


@pytest.mark.parametrize("text, message", [
    ("t, lat_deg\n0, 34\n1, 34\n", "missing: lon_deg"),
    ("t, lat_deg, lon_deg, speed\n0, 34, 108, 1\n", "unknown: speed"),
    ("t lat_deg lon_deg\n0 34 108\n1 34 108\n1 34 108\n", "line 4: time 1 s does not increase"),
    ("t, lat_deg, lon_deg\n0, 34, 108\n1, 34\n", "line 3: 2 values for 3 columns"),
    ("t, lat_deg, lon_deg\n0, 34, 108\n1, 91, 108\n", "line 3: latitude 91 deg"),
    ("t, lat_deg, lon_deg\n0, 34, 108\n", "at least two epochs"),
])
def test_a_track_it_cannot_take_is_refused_naming_the_line(demo, tmp_path, capsys, text, message):
    d, log, spec = demo
    bad = tmp_path / "bad.csv"
    bad.write_text(text)
    rc = cli.main(["replay", str(log), "--out", str(tmp_path / "o"), "--quiet", "--truth", str(bad),
                   "--attitude", "1", "-2", "15", "--lat", "34.246", "--lon", "108.91", "--height", "380"])
    assert rc == cli.EXIT_INPUT
    assert message in capsys.readouterr().err


def test_one_reference_at_a_time(demo, tmp_path, capsys):
    d, log, spec = demo
    track = _track(tmp_path / "t.csv", spec, log)
    rc = cli.main(["replay", str(log), "--out", str(tmp_path / "o"), "--quiet", "--truth", str(track),
                   "--reference", "parked", "--lat", "34.246", "--lon", "108.91", "--attitude", "1", "-2", "15"])
    assert rc == cli.EXIT_INPUT
    assert "one reference at a time" in capsys.readouterr().err


def test_the_real_log_against_a_track_of_its_site_is_the_parked_reference(tmp_path):
    """Real data: PSINS's laser-gyro log of a parked vehicle (tests/data),
    120 s of coarse alignment, then navigation. A track holding the site at
    two epochs spanning the log gives the north/east errors that
    ``--reference parked`` gives (the same site, the same formula), to 1 mm;
    its heading column (90.8 deg: the vehicle's heading written to 0.1 deg,
    i.e. +-3') gives a final heading error within 30' (measured -1.3'): a
    sign or clock error in the track's heading would give 180 deg or the
    vehicle's whole heading."""
    log = os.path.join(os.path.dirname(__file__), os.pardir, "data", "lasergyro_300s.imu.gz")
    site = ["--lat", "34.246048", "--lon", "108.909664", "--height", "380", "--coarse", "120"]
    track = tmp_path / "site.txt"
    track.write_text("t lat_deg lon_deg height_m heading_deg\n"
                     "0 34.246048 108.909664 380 90.8\n400 34.246048 108.909664 380 90.8\n")
    out_p, out_t = tmp_path / "parked", tmp_path / "track"
    assert cli.main(["replay", log, *site, "--reference", "parked", "--out", str(out_p), "--quiet"]) == 0
    assert cli.main(["replay", log, *site, "--truth", str(track), "--out", str(out_t), "--quiet"]) == 0
    ep, et = np.load(out_p / "errors.npz"), np.load(out_t / "errors.npz")
    np.testing.assert_array_equal(ep["time_s"], et["time_s"])
    np.testing.assert_allclose(et["north_m"], ep["north_m"], atol=1e-3)
    np.testing.assert_allclose(et["east_m"], ep["east_m"], atol=1e-3)
    s = json.loads((out_t / "summary.json").read_text())
    assert abs(s["errors"]["heading_final_arcmin"]) < 30.0
    assert s["errors"]["compared"] == len(et["time_s"]) == 300


def test_a_track_that_covers_no_record_is_not_a_success(demo, tmp_path, capsys):
    # another day's track (its clock 1e6 s later): nothing can be compared,
    # so the errors the user asked for do not exist; the records stay written
    d, log, spec = demo
    track = _track(tmp_path / "t.csv", spec, log)
    lines = track.read_text().splitlines()
    shifted = [lines[0], lines[1]] + [", ".join([f"{float(r.split(',')[0]) + 1e6:.6f}"] + r.split(",")[1:])
                                      for r in lines[2:]]
    track.write_text("\n".join(shifted) + "\n")
    out = tmp_path / "o"
    rc = cli.main(["replay", str(log), "--out", str(out), "--quiet", "--scenario", "demo", "--truth", str(track)])
    assert rc == cli.EXIT_INPUT
    err = capsys.readouterr().err
    assert "no record lies within the time span" in err and "the records span" in err
    assert (out / "navigation.npz").exists() and (out / "summary.json").exists()
