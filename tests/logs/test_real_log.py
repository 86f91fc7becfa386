"""A real recorded log through the front door, so that the tests hold data
the simulator did not make: the first 300 s of PSINS's data/lasergyro.imu
(tests/data/README.md), a ring-laser-gyro IMU in a parked vehicle at
34.246 N, read by the PSINS reader, replayed through the CLI, its coarse
alignment checked against an independent inertial-frame alignment written
here, and the same records rewritten into every layout the readers take."""
import bz2
import gzip
import json
import lzma
import os

import numpy as np
import pytest

from pyins import __main__ as cli
from pyins import logs
from pyins.logs import ImuData
from pyins.units import ARCSEC_TO_RAD, DEG_TO_RAD, DPH_TO_RPS

LOG = os.path.join(os.path.dirname(__file__), os.pardir, "data", "lasergyro_300s.imu.gz")
LAT, LON, HEIGHT = 34.246048, 108.909664, 380.0      # the file's header
SITE = ["--lat", str(LAT), "--lon", str(LON), "--height", str(HEIGHT)]
WIE = 7.2921151467e-5        # [rad/s] WGS-84 Earth rate
COARSE_S = 120.0


def same_bits(a, b):
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    return a.shape == b.shape and np.array_equal(a.view(np.int64), b.view(np.int64))


@pytest.fixture(scope="module")
def real():
    return logs.read_log(LOG)


def _replay(out, log, *extra):
    rc = cli.main(["replay", str(log), *SITE, "--out", str(out), "--quiet", *extra])
    assert rc == 0
    summary = json.loads((out / "summary.json").read_text())
    return summary, np.load(out / "navigation.npz")["outputs"]


@pytest.fixture(scope="module")
def coarse_run(real, tmp_path_factory):
    """120 s of coarse alignment (TRIAD, 1 s grid), then 180 s of navigation."""
    return _replay(tmp_path_factory.mktemp("real") / "run", LOG, "--coarse", str(COARSE_S),
                   "--fine", "0")


def test_the_psins_reader_reads_the_header_and_the_counts(real):
    h = real.metadata["psins_header"]
    assert (h["lat0_deg"], h["lon0_deg"], h["height0_m"]) == (LAT, LON, HEIGHT)
    assert h["ts_ms"] == 10.0 and real.dt == 0.01
    np.testing.assert_array_equal(real.tick, np.arange(1, 30001))
    # pulse counts: integers of 0.1" and of 125 ug*s (ug = 1e-6 of the header's g)
    gyro = real.dtheta_p / (0.1 * ARCSEC_TO_RAD)
    accel = real.dv_p / (125e-6 * h["g_mps2"])
    # 1e-9 counts: the scale multiplication rounds to 1 ulp, 1e-13 of a count
    assert np.max(np.abs(gyro - np.round(gyro))) < 1e-9
    assert np.max(np.abs(accel - np.round(accel))) < 1e-9
    assert np.array_equal(np.round(gyro[:2]), [[0, 0, 2], [0, 0, 7]])       # the file's lines 15-16
    assert np.array_equal(np.round(accel[:2]), [[0, 0, 80], [0, 0, 80]])
    # physics, independent of the reader's arithmetic: a parked IMU measures
    # local gravity and the Earth rate. Normal gravity at 34.246 N, 380 m is
    # 9.7955 m/s^2; 0.01 m/s^2 (1 mg) is ten times a navigation-grade
    # accelerometer bias and far below a unit mix-up (a factor 9.8 or 1000)
    t = len(real.tick) * real.dt
    f = np.linalg.norm(real.dv_p.sum(axis=0)) / t
    assert abs(f - 9.7955) < 0.01
    # 15.04 deg/h; 3 deg/h: the first minutes of this log carry rocking (people
    # or engine: |mean w| is 17.3 deg/h over the first 120 s), while arcsec read
    # as 0.1 arcmin or a wrong scale would be off by a factor of 6 or more
    w = np.linalg.norm(real.dtheta_p.sum(axis=0)) / t / DPH_TO_RPS
    assert abs(w - WIE / DPH_TO_RPS) < 3.0


def _rot(phi):
    a = np.linalg.norm(phi)
    if a == 0.0:
        return np.eye(3)
    k = phi / a
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(a) * K + (1.0 - np.cos(a)) * K @ K


def _frame(u, v):
    e1 = u / np.linalg.norm(u)
    e2 = np.cross(u, v)
    e2 /= np.linalg.norm(e2)
    return np.column_stack([e1, e2, np.cross(e1, e2)])


def inertial_frame_alignment(dtheta, dv, dt, lat):
    """Coarse alignment in the inertial frame (the method of PSINS's
    aligni0.m and of seed 000, written here from the equations, not from the
    firmware): the body attitude in the launch-time body-inertial frame ib0
    integrated from the increments, the specific force integrated in ib0 into
    velocities, and these matched at T/2 and T with the velocity gravity gives
    in the launch-time Earth-centred inertial frame i0 (double vector). Returns
    pitch, roll, heading [deg] in East-North-Up."""
    C, v = np.eye(3), np.zeros(3)
    n = len(dtheta)
    vb = np.empty((n, 3))
    for k in range(n):
        v = v + C @ (dv[k] + 0.5 * np.cross(dtheta[k], dv[k]))   # rotation compensation
        C = C @ _rot(dtheta[k])
        vb[k] = v
    t = dt * np.arange(1, n + 1)
    cl, sl = np.cos(lat), np.sin(lat)
    vi = np.column_stack([cl * np.sin(WIE * t) / WIE, cl * (1 - np.cos(WIE * t)) / WIE, sl * t])
    k1, k2 = n // 2 - 1, n - 1
    c_i0_ib0 = _frame(vi[k1], vi[k2]) @ _frame(vb[k1], vb[k2]).T
    s, c = np.sin(WIE * t[-1]), np.cos(WIE * t[-1])
    c_n_i0 = np.array([[-s, c, 0], [-sl * c, -sl * s, cl], [cl * c, cl * s, sl]])
    cnb = c_n_i0 @ c_i0_ib0 @ C
    return (np.degrees(np.arcsin(cnb[2, 1])), np.degrees(np.arctan2(-cnb[2, 0], cnb[2, 2])),
            np.degrees(-np.arctan2(-cnb[0, 1], cnb[1, 1])) % 360.0)


def test_coarse_alignment_of_the_real_log_matches_an_independent_one(real, coarse_run):
    summary, _ = coarse_run
    al = summary["aligned"]
    assert al["time_s"] == COARSE_S
    n = int(round(COARSE_S / real.dt))
    pitch, roll, heading = inertial_frame_alignment(real.dtheta_p[:n], real.dv_p[:n], real.dt,
                                                    LAT * DEG_TO_RAD)
    # Both use the same 12 000 samples, so the sensor noise is common to both
    # and cancels; what is left is how each discretises (the firmware's coning
    # and sculling terms, its own trig; single-sample rotation vectors here):
    # measured 0.06" in pitch, 0.001" in roll, 0.014" in heading. 1" level and
    # 5" heading: over ten times that, and far below what a real error of the
    # method would give (a wrong sign or frame: degrees; a 1 s misplaced
    # velocity sample: ~20" of heading)
    assert abs(al["pitch_deg"] - pitch) * 3600 < 1.0
    assert abs(al["roll_deg"] - roll) * 3600 < 1.0
    assert abs(al["heading_deg"] - heading) * 3600 < 5.0
    # and against the vehicle: level within 2 deg of flat (a parked car), the
    # heading within 1 deg of the recorder's yaw0 = -90.6 deg (heading 90.6):
    # an east gyro error of 0.2 deg/h, the excess of this log's mean rate over
    # the Earth rate, moves a gyrocompass heading by eps / (w_ie cos L) =
    # 0.2 / 12.4 rad = 0.9 deg
    assert abs(al["pitch_deg"]) < 2.0 and abs(al["roll_deg"]) < 2.0
    assert abs(al["heading_deg"] - 90.6) < 1.0
    assert summary["warnings"] == []


def test_the_parked_vehicle_stays_at_the_site(coarse_run):
    """180 s of free navigation after 120 s of coarse alignment. A residual
    gyro error eps of up to 0.5 deg/h (2.4e-6 rad/s) tilts the platform by
    eps t and gives a velocity error g eps t^2 / 2 = 0.38 m/s and a position
    error g eps t^3 / 6 = 23 m at t = 180 s; the vibration (800 ug/sqrt(Hz))
    adds a random walk of 0.1 m/s. Bounds 0.5 m/s and 50 m: a parked vehicle,
    where a wrong rate, axis or unit drifts by kilometres."""
    summary, recs = coarse_run
    nav = recs[recs["mode"] == 3]
    assert len(nav) >= 180
    r = 6.378e6
    north = (nav["lat_rad"] - LAT * DEG_TO_RAD) * r
    east = (nav["lon_rad"] - LON * DEG_TO_RAD) * r * np.cos(LAT * DEG_TO_RAD)
    assert np.max(np.hypot(north, east)) < 50.0
    assert np.max(np.linalg.norm(nav["vel_n_mps"], axis=1)) < 0.5
    assert summary["final"]["fault_flags"] == 0


LAYOUTS = [
    ("psins_last.txt", dict(fmt="text")),                                 # PSINS [wm vm t]
    ("kfgins.txt", dict(time_col="first", axes="frd", header=False)),     # KF-GINS imu.txt
    ("i2nav.bin", dict(axes="frd")),                                      # i2Nav binary
    ("project.csv", dict()),
    ("project.npz", dict()),
    ("rates.dat", dict(time_col="first", kind="rates", gyro_unit="deg/h", accel_unit="g")),
]


@pytest.mark.parametrize("name, options", LAYOUTS, ids=[n for n, _ in LAYOUTS])
@pytest.mark.parametrize("compression", [None, "gz", "xz", "bz2"])
def test_the_real_log_rewritten_into_every_layout_reads_back_the_same(real, tmp_path, name,
                                                                      options, compression):
    path = tmp_path / name
    logs.write_log(path, real, **options)
    if compression:
        opener = {"gz": gzip.open, "xz": lzma.open, "bz2": bz2.open}[compression]
        packed = tmp_path / f"{name}.{compression}"
        with opener(packed, "wb") as f:
            f.write(path.read_bytes())
        path = packed
    read = {k: v for k, v in options.items() if k != "header"}
    got = logs.read_log(path, dt=0.01 if name.endswith(".csv") else None, **read)
    np.testing.assert_array_equal(got.tick, real.tick)
    if options.get("kind") == "rates":
        # deg/h and g: one division when writing, one multiplication back, and
        # the rectangular rule's interval: within 4 ulp (docs/log-formats.md)
        for a, b in ((got.dtheta_p, real.dtheta_p), (got.dv_p, real.dv_p)):
            assert np.all(np.abs(a - b) <= 4 * np.spacing(np.abs(b)))
    else:
        assert same_bits(got.dtheta_p, real.dtheta_p) and same_bits(got.dv_p, real.dv_p)
    assert same_bits(got.table_angle_rad, real.table_angle_rad)


def _peer_csv(real, path):
    """The layout PSINS-based tools exchange: a '#' comment, named columns
    time-first, gzip-compressed (written here, not by pyins)."""
    lines = ["# lasergyro.imu excerpt, increments rad and m/s, x right y forward z up",
             "t,dtheta_x,dtheta_y,dtheta_z,dv_x,dv_y,dv_z"]
    for k, th, dv in zip(real.tick.tolist(), real.dtheta_p.tolist(), real.dv_p.tolist()):
        lines.append("%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g" % (k * 0.01, *th, *dv))
    with gzip.open(path, "wt") as f:
        f.write("\n".join(lines) + "\n")
    return path


def test_the_same_log_in_other_layouts_replays_to_the_same_bits(real, coarse_run, tmp_path):
    """The CLI run of the .imu.gz, of a peer CSV (.csv.gz: refused three ways
    before) and of an i2Nav-style binary log give the same records."""
    peer = _peer_csv(real, tmp_path / "peer.csv.gz")
    binary = tmp_path / "i2nav.bin"
    logs.write_log(binary, real, axes="frd")
    _, want = coarse_run
    for log, extra in ((peer, ()), (binary, ("--axes", "frd"))):
        _, got = _replay(tmp_path / log.name.replace(".", "_"), log, "--coarse", str(COARSE_S),
                         "--fine", "0", *extra)
        for field in ("lat_rad", "lon_rad", "vel_n_mps", "quat_nb"):
            assert same_bits(got[field], want[field]), (log.name, field)


def test_a_200_hz_split_of_the_real_log_aligns_as_the_100_hz_log(real, coarse_run, tmp_path):
    """200 Hz by halving every increment: x / 2 is exact in binary floating
    point, so the two halves add back to the 100 Hz record bit for bit (a rate
    change that loses nothing; 50 Hz by adding pairs would round). Through the
    CLI the coarse attitude agrees within 1" (the acceptance figure): the
    firmware sees the same integrals, only its coning and sculling terms see
    the rate held constant over each 10 ms."""
    n = len(real.tick)
    half = ImuData(np.arange(1, 2 * n + 1, dtype=np.int64), np.repeat(real.dtheta_p / 2, 2, axis=0),
                   np.repeat(real.dv_p / 2, 2, axis=0), np.zeros(2 * n), 0.005, {})
    path = tmp_path / "kfgins200.txt"
    logs.write_log(path, half, time_col="first", axes="frd", header=False)
    got = logs.read_log(path, time_col="first", axes="frd")
    assert got.dt == 0.005
    assert same_bits(got.dtheta_p[0::2] + got.dtheta_p[1::2], real.dtheta_p)
    assert same_bits(got.dv_p[0::2] + got.dv_p[1::2], real.dv_p)
    summary, _ = _replay(tmp_path / "r200", path, "--time-col", "first", "--axes", "frd",
                         "--coarse", str(COARSE_S), "--fine", "0")
    want = coarse_run[0]["aligned"]
    assert summary["aligned"]["time_s"] == want["time_s"]
    for k in ("pitch_deg", "roll_deg", "heading_deg"):
        assert abs(summary["aligned"][k] - want[k]) * 3600 < 1.0, k


def test_compact_records_every_tick_of_the_real_log_are_the_full_records_fields(real):
    """The recorded log in one pyins_run_nav call with a record every tick
    (120 s of coarse alignment through step(), then 180 s of navigation
    whose records run_plain's loop writes): every record is the full
    record's fields of the same names, bit for bit, and the navigation
    comes out aligned and without a fault."""
    from pyins import native
    cfg = dict(lat_rad=LAT * DEG_TO_RAD, lon_rad=LON * DEG_TO_RAD, height_m=HEIGHT,
               coarse_ticks=int(COARSE_S * 100), fine_ticks=0)
    s = native.make_samples(real.dtheta_p, real.dv_p)
    full = native.Firmware(cfg).run(s)
    compact = native.Firmware(cfg).run_nav(s, every=1)
    assert len(compact) == len(full) == len(s)
    for field in native.NAV_DTYPE.names:
        assert np.ascontiguousarray(compact[field]).tobytes() == np.ascontiguousarray(full[field]).tobytes(), field
    # the alignment's last sample ends it: its record is the first in NAVIGATE
    nav = compact["mode"] == 3
    assert np.count_nonzero(nav) == len(s) - int(COARSE_S * 100) + 1 and compact["fault_flags"][-1] == 0
