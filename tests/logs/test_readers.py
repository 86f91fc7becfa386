"""The readers users have (docs/log-formats.md, "Formats"): PSINS's .imu,
CSV with named columns, compressed files (gzip, xz, bzip2, by extension and by
magic bytes), pulse counts with a scale factor in arcsec and ug*s; each bad
input refused in one line naming the file, the line or record and what was
expected; and a log with a missing sample replayed with --allow-gaps
(docs/log-formats.md, "Gaps in the CLI")."""
import bz2
import gzip
import json
import lzma

import numpy as np
import pytest

from pyins import __main__ as cli
from pyins import logs
from pyins.sim import imu, motion
from pyins.logs import ImuData
from pyins.units import ARCSEC_TO_RAD, DEG_TO_RAD, UG_TO_MPS2

LAT, LON = 34.246, 108.91
SITE = ["--lat", str(LAT), "--lon", str(LON), "--height", "0"]


def parked(n=3000, dt=0.01):
    mo = motion.Static(LAT * DEG_TO_RAD, LON * DEG_TO_RAD, 0.0, 0.0, 0.0, -90.8 * DEG_TO_RAD)
    th, dv, _ = imu.exact_increments(mo, n, dt=dt)
    return ImuData(np.arange(1, n + 1, dtype=np.int64), th, dv, np.zeros(n), dt, {})


PSINS_HEAD = ("% PSINS-format SIMU log file. (DO NOT EDIT!)\n% test\n\n"
              "0 0 -90.6 0 0 0\n34.246 108.91 380 0 10 9.780327\n0.1 0.1 0.1 125 125 125\n")


def expect_error(path, *parts, **options):
    with pytest.raises(logs.LogError) as info:
        logs.read_log(path, **options)
    msg = str(info.value)
    assert "\n" not in msg and msg.startswith(str(path)), msg
    for part in parts:
        assert part in msg, (part, msg)


def test_psins_imu_counts_scaled_by_its_header(tmp_path):
    path = tmp_path / "a.imu"
    path.write_text(PSINS_HEAD + "0 0 2 0 0 80\n1 -3 7 0 2 80\n")
    d = logs.read_log(path, plausibility=False)
    assert d.dt == 0.01 and list(d.tick) == [1, 2]
    np.testing.assert_array_equal(d.dtheta_p[1], np.array([1, -3, 7]) * (0.1 * ARCSEC_TO_RAD))
    np.testing.assert_array_equal(d.dv_p[0], np.array([0, 0, 80]) * (125 * (1e-6 * 9.780327)))
    # the 7th column: the sampling-time dither [us]; 1500 us late makes a
    # 1.15-tick step, irregular (over 1 %): a warning, not silence
    path.write_text(PSINS_HEAD + "0 0 2 0 0 80 0\n0 0 2 0 0 80 1500\n0 0 2 0 0 80 -1500\n")
    expect_error(path, "line 8", "irregular time step 0.0115 s", plausibility=False)


@pytest.mark.parametrize("text, parts", [
    ("% some other file\n0 0 0 0 0 0\n", ["line 1", "not a PSINS-format SIMU file"]),
    (PSINS_HEAD.replace("0.1 0.1 0.1 125 125 125", "0.1 0.1 125"),
     ["line 6", "header line 3 of 3 expected 6 numbers (gf_x_arcsec"]),
    (PSINS_HEAD + "0 0 2 0 0 80\n0 0 2 0 80\n", ["line 8", "expected 6 columns like the first"]),
    (PSINS_HEAD + "0 0 2 0 0 x80\n", ["line 7", "'x80' is not a number"]),
    (PSINS_HEAD, ["no data lines after the PSINS header"]),
])
def test_psins_bad_input(tmp_path, text, parts):
    path = tmp_path / "bad.imu"
    path.write_text(text)
    expect_error(path, *parts, plausibility=False)


@pytest.mark.parametrize("suffix", [".gz", ".xz", ".bz2"])
def test_compressed_by_extension_and_by_magic(tmp_path, suffix):
    opener = {".gz": gzip.open, ".xz": lzma.open, ".bz2": bz2.open}[suffix]
    data = parked(200)
    plain = tmp_path / "log.txt"
    logs.write_log(plain, data)
    packed = tmp_path / f"log.txt{suffix}"
    with opener(packed, "wb") as f:
        f.write(plain.read_bytes())
    misnamed = tmp_path / "misnamed.txt"          # compressed, but named as plain text
    misnamed.write_bytes(packed.read_bytes())
    for path in (packed, misnamed):
        got = logs.read_log(path)
        np.testing.assert_array_equal(got.dtheta_p, data.dtheta_p)
    # cut short: named, not a bare decompression traceback
    cut = tmp_path / f"cut.txt{suffix}"
    cut.write_bytes(packed.read_bytes()[:-20])
    expect_error(cut, "not a complete", "cut or damaged")


def test_named_csv_columns_variants_and_a_user_mapping(tmp_path):
    data = parked(300)
    rows = ["%.17g;%.17g;%.17g;%.17g;%.17g;%.17g;%.17g;0" % (k * 0.01, *th, *dv)
            for k, th, dv in zip(data.tick, data.dtheta_p.tolist(), data.dv_p.tolist())]
    path = tmp_path / "peer.csv"
    path.write_text("# exported\nTime [s];Gyro_X [rad];gyro_y;gz;acc_x;ay;dv_z;temp\n"
                    + "\n".join(rows) + "\n")
    got = logs.read_log(path)
    np.testing.assert_array_equal(got.dtheta_p, data.dtheta_p)
    np.testing.assert_array_equal(got.dv_p, data.dv_p)
    assert got.dt == 0.01
    path.write_text("stamp,a,b,c,d,e,f\n" + "\n".join(r.replace(";", ",")[:r.rfind(";")]
                                                     for r in rows) + "\n")
    mapping = dict(t="stamp", gyro_x="a", gyro_y="b", gyro_z="c", accel_x="d", accel_y="e",
                   accel_z="f")
    got = logs.read_log(path, columns=mapping)
    np.testing.assert_array_equal(got.dv_p, data.dv_p)
    expect_error(path, "line 1", "names no column for gyro_x", "columns=")
    path.write_text("t,dtheta_x,dtheta_y,dtheta_z,dv_x,dv_y,dv_z\n0.01,0,0,0,0,0,0.098\n"
                    "0.02,0,0,zero,0,0,0.098\n")
    expect_error(path, "line 3, column 4 (dtheta_z, read as gyro_z)", "'zero' is not a number")
    path.write_text("t,dtheta_x,dtheta_y,dtheta_z,dv_x,dv_y,dv_z\n0.01,0,0,0,0,0\n")
    expect_error(path, "line 2", "expected 7 fields like the header")
    path.write_text("0.01,0,0,0,0,0,0.098\n")
    expect_error(path, "line 1", "expected a header line naming the columns")


def test_pulse_counts_with_a_scale_factor(tmp_path):
    """A text log of counts: 0.1" a gyro pulse, 125 ug*s an accelerometer pulse."""
    path = tmp_path / "pulses.txt"
    path.write_text("0 0 2 0 0 80 0.01\n3 -1 7 0 2 80 0.02\n")
    d = logs.read_log(path, gyro_unit="arcsec", gyro_scale=0.1, accel_unit="ug*s",
                      accel_scale=125.0)
    np.testing.assert_allclose(d.dtheta_p[1], np.array([3, -1, 7]) * 0.1 * ARCSEC_TO_RAD,
                               rtol=1e-15)
    np.testing.assert_allclose(d.dv_p[0], [0, 0, 80 * 125 * UG_TO_MPS2], rtol=1e-15)
    # without the scale the counts read as whole arcsec: 10x the rate, still
    # plausible for a gyro; the accelerometer's gravity catches a missing scale
    expect_error(path, "median specific force", gyro_unit="arcsec", accel_unit="ug*s")


def test_the_peer_csv_is_replayed_through_the_cli(tmp_path, capsys):
    """Before: '.gz' unknown, --format csv a bare decode error, --format text
    'a binary log?'."""
    data = parked(3000)
    path = tmp_path / "peer.csv.gz"
    with gzip.open(path, "wt") as f:
        f.write("# parked\nt,dtheta_x,dtheta_y,dtheta_z,dv_x,dv_y,dv_z\n")
        for k, th, dv in zip(data.tick, data.dtheta_p.tolist(), data.dv_p.tolist()):
            f.write("%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n" % (k * 0.01, *th, *dv))
    for fmt in ((), ("--format", "csv")):
        out = tmp_path / f"out{len(fmt)}"
        rc = cli.main(["replay", str(path), *fmt, *SITE, "--coarse", "20", "--out", str(out),
                       "--quiet"])
        assert rc == 0, capsys.readouterr().err
        assert json.loads((out / "summary.json").read_text())["samples"] == 3000
    rc = cli.main(["replay", str(path), "--format", "text", *SITE, "--coarse", "20", "--out",
                   str(tmp_path / "t"), "--quiet"])
    err = capsys.readouterr().err
    assert rc == cli.EXIT_INPUT and err.count("\n") == 1
    assert "line 1" not in err and "line 2: expected 7 or 8 columns" in err
    assert "a CSV with a header line is --format csv" in err


def test_one_missing_sample_replays_with_allow_gaps(tmp_path, capsys):
    data = parked(3000)
    keep = np.ones(3000, dtype=bool)
    keep[2500] = False                      # one sample lost in navigation
    gappy = ImuData(data.tick[keep], data.dtheta_p[keep], data.dv_p[keep], data.table_angle_rad[keep],
                    0.01, {})
    path = tmp_path / "gap.txt"
    logs.write_log(path, gappy, time_col="first", axes="frd")
    args = ["replay", str(path), "--time-col", "first", "--axes", "frd", *SITE, "--coarse", "20"]
    rc = cli.main(args + ["--out", str(tmp_path / "a"), "--quiet"])
    err = capsys.readouterr().err
    assert rc == cli.EXIT_INPUT
    assert "1 missing tick" in err and "--allow-gaps" in err and "strict=False" not in err
    rc = cli.main(args + ["--allow-gaps", "--out", str(tmp_path / "b"), "--quiet"])
    err = capsys.readouterr().err
    assert rc == 0
    assert "WARNING" in err and "1 missing tick of" in err and "1 missing tick bridged" in err
    summary = json.loads((tmp_path / "b" / "summary.json").read_text())
    assert summary["samples"] == 3000       # the clock kept: 2999 read + 1 bridged
    # the bridge is the firmware's rule: linear between the neighbours, so a
    # parked IMU's constant increments come back to within rounding
    bridged, added = logs.bridge_gaps(logs.read_log(path, time_col="first", axes="frd",
                                                    strict=False))
    assert added == 1
    np.testing.assert_array_equal(bridged.tick, data.tick)
    # 1e-18 rad, 1e-16 m/s: a few ulp of increments of 7e-7 rad and 0.098 m/s
    assert np.max(np.abs(bridged.dtheta_p - data.dtheta_p)) < 1e-18
    assert np.max(np.abs(bridged.dv_p - data.dv_p)) < 1e-16


def test_npz_with_other_array_names(tmp_path, capsys):
    """Before: an npz without the project's six arrays was refused."""
    data = parked(3000)
    path = tmp_path / "peer.npz"
    np.savez(path, time=data.tick * 0.01, gyro=data.dtheta_p, acc=data.dv_p)
    got = logs.read_log(path)
    assert got.dt == 0.01
    np.testing.assert_array_equal(got.dtheta_p, data.dtheta_p)
    np.testing.assert_array_equal(got.dv_p, data.dv_p)
    # three arrays a triad, other names, rates in deg/h and g, forward-right-down
    frd = data.dtheta_p[:, [1, 0, 2]] * [1, 1, -1] / 0.01 / (DEG_TO_RAD / 3600)
    np.savez(path, stamp=data.tick * 0.01, wx=frd[:, 0], wy=frd[:, 1], wz=frd[:, 2],
             f=data.dv_p[:, [1, 0, 2]] * [1, 1, -1] / 0.01 / 9.80665)
    got = logs.read_log(path, columns={"t": "stamp"}, kind="rates", gyro_unit="deg/h",
                        accel_unit="g", axes="frd")
    # the rectangular rule multiplies each rate by the step of the stamps
    # tick * 0.01, which round to 1 ulp of 30 s (3.6e-15 s, 3.6e-13 of a tick):
    # 1e-18 rad is that share of an increment of 6e-7 rad, with room
    assert np.max(np.abs(got.dtheta_p - data.dtheta_p)) < 1e-18
    out = tmp_path / "cli"
    rc = cli.main(["replay", str(path), "--columns", "t=stamp", "--kind", "rates", "--gyro-unit",
                   "deg/h", "--accel-unit", "g", "--axes", "frd", *SITE, "--coarse", "20",
                   "--out", str(out), "--quiet"])
    assert rc == 0, capsys.readouterr().err
    np.savez(path, stamp=data.tick * 0.01, gyro=data.dtheta_p)
    expect_error(path, "no accel array", "the file has stamp, gyro")
    np.savez(path, t=data.tick[:10] * 0.01, gyro=data.dtheta_p, accel=data.dv_p)
    expect_error(path, "the time array has 10 samples, the gyro 3000")
    rc = cli.main(["replay", str(path), "--columns", "t", *SITE, "--coarse", "20", "--quiet"])
    assert rc == cli.EXIT_INPUT and "--columns 't': expected ROLE=NAME" in capsys.readouterr().err


def test_the_project_files_take_no_unit_options(tmp_path):
    data = parked(100)
    for name in ("p.npz", "p.csv"):
        logs.write_log(tmp_path / name, data)
        with pytest.raises(ValueError, match="unit, axis, scale and column options do not apply"):
            logs.read_log(tmp_path / name, axes="frd", dt=0.01)


@pytest.mark.parametrize("name", ["log.txt.gz", "log.csv.xz", "log.bin.bz2", "log.npz.gz"])
def test_written_compressed_reads_back_bit_for_bit(tmp_path, name):
    data = parked(500)
    path = tmp_path / name
    logs.write_log(path, data)
    assert logs.compression_of(path) == {"gz": "gzip", "xz": "xz", "bz2": "bzip2"}[name.rsplit(".", 1)[1]]
    got = logs.read_log(path, dt=0.01 if ".csv" in name else None)
    assert np.array_equal(got.dtheta_p.view(np.int64), data.dtheta_p.view(np.int64))
    assert np.array_equal(got.dv_p.view(np.int64), data.dv_p.view(np.int64))
    assert sorted(p.name for p in tmp_path.iterdir()) == [name]      # no temporary left
    with pytest.raises(ValueError, match="writing PSINS .imu is not supported"):
        logs.write_log(tmp_path / "x.imu", data)


def test_simulate_writes_a_compressed_log_that_replay_reads(tmp_path):
    log = tmp_path / "imu.txt.gz"
    assert cli.main(["simulate", "demo", str(log), "--hours", "0.01", "--quiet"]) == 0
    assert logs.compression_of(log) == "gzip"
    assert cli.main(["replay", str(log), "--scenario", "demo", "--out", str(tmp_path / "r"),
                     "--quiet"]) == 0
