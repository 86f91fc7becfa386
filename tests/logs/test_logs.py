"""IMU logs from the field (pyins.logs): round trips through every reader and
writer, one test per kind of malformed file, and the unit-mix-up hints."""
import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from pyins import logs
from pyins.logs import ImuData
from pyins.units import DEG_TO_RAD
from pyins.sim import imu, motion, sensors, turntable
from strategies import finite

LAT = 34.246 * DEG_TO_RAD
EXT = {"text": "txt", "binary": "bin", "npz": "npz", "csv": "csv"}


def same_bits(a, b):
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    return a.shape == b.shape and np.array_equal(a.view(np.int64), b.view(np.int64))


def assert_same_data(got, want, ticks=True):
    assert same_bits(got.dtheta_p, want.dtheta_p)
    assert same_bits(got.dv_p, want.dv_p)
    assert same_bits(got.table_angle_rad, want.table_angle_rad)
    if ticks:
        np.testing.assert_array_equal(got.tick, want.tick)
        assert got.tick.dtype == np.int64


def assert_within_ulps(got, want, ulps):
    """|got - want| <= ulps * spacing(want), elementwise (a bound in rad or m/s
    that scales with the value)."""
    got, want = np.asarray(got), np.asarray(want)
    assert np.all(np.abs(got - want) <= ulps * np.spacing(np.abs(want))), np.max(
        np.abs(got - want) / np.spacing(np.abs(want)))


def static_log(n=2000, seed=5, table=False):
    """A static IMU at 34 deg latitude with the seed 002 sensor errors and noise."""
    mo = motion.Static(LAT, 108.9 * DEG_TO_RAD, 380.0, pitch=0.01, roll=-0.02, yaw=0.7)
    th, dv, angle = imu.exact_increments(
        mo, n, table=turntable.ConstantRate(0.05) if table else None)
    th, dv = sensors.SensorModel(sensors.preset("seed002"), seed=seed).apply(th, dv)
    return ImuData(np.arange(1, n + 1, dtype=np.int64), th, dv, angle, 0.01, {"seed": seed})


def ship_log(n=1000):
    """A ship in the 'bad' sea state of seed 000 (roll rate up to 0.35 rad/s)."""
    mo = motion.sea_state("bad", LAT, 108.9 * DEG_TO_RAD, 0.0, 0.3)
    th, dv, angle = imu.exact_increments(mo, n)
    return ImuData(np.arange(1, n + 1, dtype=np.int64), th, dv, angle, 0.01, {})


def awkward_log():
    """Signed zero, subnormal, huge, 1/3, pi and ulp neighbours, ticks with a gap."""
    d = static_log(n=300, table=True)
    d.dtheta_p[0] = [-0.0, 5e-324, 1e-300]
    d.dtheta_p[1] = [1.0 / 3.0, 0.01 * np.pi, np.nextafter(0.01, 1.0)]
    d.dv_p[0] = [1e-300, -2.2250738585072014e-308, np.nextafter(0.1, 0.0)]
    d.table_angle_rad[0] = np.nextafter(2 * np.pi, 0.0)
    d.tick = d.tick + 345600
    return d


# ---------------------------------------------------------------------------
# Round trips, bit for bit
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("fmt, options", [
    ("text", {}),                                           # PSINS [wm vm t alpha]
    ("text", {"time_col": "first"}),
    ("text", {"time_col": "first", "axes": "frd"}),         # KF-GINS layout
    ("text", {"axes": "flu->rfu"}),
    ("text", {"axes": [[0, 0, 1], [-1, 0, 0], [0, -1, 0]]}),
    ("binary", {"table": True}),
    ("binary", {"table": True, "axes": "ned"}),
    ("npz", {}),
    ("csv", {"dt": 0.01}),
])
def test_round_trip_bit_exact(tmp_path, fmt, options):
    data = awkward_log()
    path = tmp_path / f"log.{EXT[fmt]}"
    logs.write_log(path, data, **options)
    back = logs.read_log(path, plausibility=False, **options)
    assert_same_data(back, data)
    assert back.dt == 0.01                      # inferred: the median step, to 1 ns
    assert logs.check_log(path, plausibility=False, **options) == []


def test_round_trip_without_time_or_table(tmp_path):
    data = static_log(n=200)                    # table angle 0: no column written
    path = tmp_path / "wm_vm.txt"
    logs.write_log(path, data, time_col="none", header=False)
    assert len(path.read_text().splitlines()[0].split()) == 6
    back = logs.read_log(path, time_col="none", dt=0.01)
    assert_same_data(back, data)
    back = logs.read_log(path, time_col="none", dt=0.01, table_angle=0.25)
    assert np.all(back.table_angle_rad == 0.25)
    path = tmp_path / "plain.bin"
    logs.write_log(path, data)
    assert path.stat().st_size == 56 * 200
    assert_same_data(logs.read_log(path), data)


def test_text_layouts_are_what_the_docs_say(tmp_path):
    data = ImuData(np.array([100, 101]), np.array([[1e-3, 2e-3, 3e-3], [4e-3, 5e-3, 6e-3]]),
                   np.array([[0.1, 0.2, 9.8e-2], [0.3, 0.4, 0.5]]), np.array([0.5, 0.75]),
                   0.01, {})
    path = tmp_path / "a.txt"
    logs.write_log(path, data)
    lines = path.read_text().splitlines()
    assert lines[0] == ("% columns: gyro_x[rad] gyro_y[rad] gyro_z[rad] accel_x[m/s] "
                        "accel_y[m/s] accel_z[m/s] t[s] table[rad]; kind=increments; axes=rfu")
    assert lines[1] == "0.001 0.002 0.0030000000000000001 0.10000000000000001 " \
                       "0.20000000000000001 0.098000000000000004 1 0.5"
    logs.write_log(path, data, time_col="first", axes="frd", header=False)
    first = [float(x) for x in path.read_text().splitlines()[0].split()]
    # t, then forward, right, down: p's y, x and -z
    assert first == [1.0, 2e-3, 1e-3, -3e-3, 0.2, 0.1, -9.8e-2, 0.5]
    logs.write_log(path, data, fmt="binary", table=True)
    rec = np.fromfile(path, dtype="<f8").reshape(2, 8)
    assert rec[1].tolist() == [1.01, 4e-3, 5e-3, 6e-3, 0.3, 0.4, 0.5, 0.75]


def test_axes_matrices():
    np.testing.assert_array_equal(logs.axes_matrix("rfu"), np.eye(3))
    frd = np.array([[0, 1, 0], [1, 0, 0], [0, 0, -1]])
    for spec in ("frd", "ned", "FRD->rfu", "ned -> p"):
        np.testing.assert_array_equal(logs.axes_matrix(spec), frd)
    np.testing.assert_array_equal(logs.axes_matrix("flu"), [[0, -1, 0], [1, 0, 0], [0, 0, 1]])
    for m in logs.AXES.values():
        assert round(np.linalg.det(m)) == 1
    # Physics: a level IMU heading North. An frd triad reads gravity's
    # reaction on -z and the Earth rate's North part on x; in p they must
    # come out on +z and +y.
    omega, g = 7.292e-5 * np.cos(LAT), 9.79
    v_frd = np.array([omega, 0.0, -g])
    np.testing.assert_array_equal(logs.axes_matrix("frd") @ v_frd, [0.0, omega, g])


def test_static_log_in_frd_reads_as_p(tmp_path):
    # The same static log written as an frd text file by hand reads back as p.
    data = static_log(n=100)
    m = logs.AXES["frd"]
    rows = np.column_stack([data.tick * 0.01, data.dtheta_p @ m, data.dv_p @ m])   # M.T v_p
    path = tmp_path / "kfgins.txt"
    np.savetxt(path, rows, fmt="%.17g")
    back = logs.read_log(path, time_col="first", axes="frd")
    assert_same_data(back, data)


# ---------------------------------------------------------------------------
# Unit and rate conversions: close, not bit-exact
# ---------------------------------------------------------------------------
# Each conversion rounds once on writing (divide by the factor or the
# interval) and once on reading (multiply back), each within half an ulp:
# one unit conversion stays within 2 ulp of the value, a unit conversion
# plus a rate conversion within 4 ulp. For increments below 0.1 rad, 4 ulp
# is under 5.6e-17 rad (1e-11 arc-second), nine orders below the RLG quantum.
@pytest.mark.parametrize("options, ulps", [
    ({"gyro_unit": "deg", "table_unit": "deg"}, 2),
    ({"kind": "rates"}, 2),
    ({"kind": "rates", "gyro_unit": "deg/s", "accel_unit": "g"}, 4),
    ({"kind": "rates", "gyro_unit": "deg/h", "accel_unit": "g", "time_col": "first",
      "axes": "frd"}, 4),
    ({"kind": "rates", "time_col": "none", "dt": 0.01}, 2),
    ({"fmt": "binary", "kind": "rates", "gyro_unit": "deg/s", "table": True,
      "table_unit": "deg"}, 4),
])
def test_round_trip_with_conversions(tmp_path, options, ulps):
    data = static_log(n=500, table=True)
    if options.get("time_col") == "none":
        data.table_angle_rad[:] = 0.0
    path = tmp_path / "conv.txt"
    logs.write_log(path, data, **options)
    back = logs.read_log(path, **options)
    np.testing.assert_array_equal(back.tick, data.tick)
    assert_within_ulps(back.dtheta_p, data.dtheta_p, ulps)
    assert_within_ulps(back.dv_p, data.dv_p, ulps)
    assert_within_ulps(back.table_angle_rad, data.table_angle_rad, 2)
    assert back.metadata["kind"] == options.get("kind", "increments")


def test_rates_are_integrated_over_each_interval(tmp_path):
    # rectangular rule: increment_k = rate_k * (t_k - t_{k-1}); the first
    # sample uses the nominal dt. The 0.02-s step is a gap (one missing tick):
    # the sample after it is one tick's increment, rate x (0.02 s / 2 ticks),
    # and the missing tick is the bridge's (rate x 0.02 s made it two ticks'
    # worth, which the bridge then ramped towards)
    path = tmp_path / "rates.txt"
    path.write_text("% t wx wy wz fx fy fz\n"
                    "0.00 1 0 0 0 0 9.8\n"
                    "0.01 1 0 0 0 0 9.8\n"
                    "0.03 2 0 0 0 0 9.8\n"
                    "0.04 1 0 0 0 0 9.8\n")
    data = logs.read_log(path, kind="rates", time_col="first", strict=False)
    np.testing.assert_allclose(data.dtheta_p[:, 0], [0.01, 0.01, 0.02, 0.01], rtol=1e-14)
    np.testing.assert_allclose(data.dv_p[:, 2], [0.098, 0.098, 0.098, 0.098], rtol=1e-14)
    np.testing.assert_array_equal(data.tick, [0, 1, 3, 4])
    assert len(data.metadata["warnings"]) == 1 and "1 missing tick" in data.metadata["warnings"][0]


# ---------------------------------------------------------------------------
# Hypothesis: random data, small examples
# ---------------------------------------------------------------------------
ANY_FLOAT = st.floats(allow_nan=False, allow_infinity=False, width=64)
AXES_CHOICES = st.sampled_from(["rfu", "frd", "flu", "ned", "enu->rfu",
                                [[0, 0, 1], [1, 0, 0], [0, 1, 0]],
                                [[-1, 0, 0], [0, -1, 0], [0, 0, 1]]])


@st.composite
def imu_data(draw, elements=ANY_FLOAT, max_n=8, gaps=True):
    """Random samples; ticks mostly one apart, gaps in fewer than half the
    steps (so the median step is the tick)."""
    n = draw(st.integers(1, max_n))
    dtheta = draw(arrays(np.float64, (n, 3), elements=elements))
    dv = draw(arrays(np.float64, (n, 3), elements=elements))
    angle = draw(arrays(np.float64, (n,), elements=elements))
    steps = np.ones(n - 1, dtype=np.int64)
    if gaps and n > 2:
        where = draw(st.lists(st.integers(0, n - 2), max_size=(n - 2) // 2, unique=True))
        for k in where:
            steps[k] = draw(st.integers(2, 50))
    start = draw(st.sampled_from([0, 1, 345600]) | st.integers(-10**6, 10**7))
    tick = start + np.concatenate(([0], np.cumsum(steps)))
    return ImuData(tick.astype(np.int64), dtheta, dv, angle, 0.01, {})


@given(data=imu_data(), fmt=st.sampled_from(["text", "binary"]),
       time_col=st.sampled_from(["last", "first"]), axes=AXES_CHOICES,
       infer_dt=st.booleans())
def test_hypothesis_round_trip_bit_exact(tmp_path_factory, data, fmt, time_col, axes, infer_dt):
    path = tmp_path_factory.mktemp("h") / f"h.{EXT[fmt]}"
    options = {"axes": axes}
    if fmt == "text":
        options["time_col"] = time_col
    else:
        options["table"] = True
    logs.write_log(path, data, **options)
    dt = None if infer_dt and len(data.tick) > 1 else 0.01
    back = logs.read_log(path, dt=dt, strict=False, plausibility=False, **options)
    assert_same_data(back, data)
    assert back.dt == 0.01


@given(data=imu_data(gaps=False))
@example(data=ImuData(np.array([0]), np.zeros((1, 3)), np.zeros((1, 3)), np.array([-0.0]), 0.01,
                      {}))      # a -0.0 table angle once made the text writer drop the column
def test_hypothesis_round_trip_npz_csv_no_time(tmp_path_factory, data):
    folder = tmp_path_factory.mktemp("h")
    for fmt in ("npz", "csv"):
        logs.write_log(folder / f"h.{fmt}", data)
        assert_same_data(logs.read_log(folder / f"h.{fmt}", plausibility=False), data)
    data.tick = np.arange(1, len(data.tick) + 1, dtype=np.int64)
    logs.write_log(folder / "h.dat", data, time_col="none")
    assert_same_data(logs.read_log(folder / "h.dat", time_col="none", dt=0.01,
                                   plausibility=False), data)


NORMAL_SMALL = finite(-0.1, 0.1).filter(lambda v: v == 0.0 or abs(v) > 1e-200)


@given(data=imu_data(elements=NORMAL_SMALL),
       units=st.sampled_from([("increments", "deg", "m/s"), ("rates", "rad/s", "m/s^2"),
                              ("rates", "deg/s", "g"), ("rates", "deg/h", "g")]),
       table_unit=st.sampled_from(["rad", "deg"]), axes=AXES_CHOICES,
       time_col=st.sampled_from(["last", "first"]))
def test_hypothesis_round_trip_conversions(tmp_path_factory, data, units, table_unit, axes,
                                           time_col):
    kind, gyro_unit, accel_unit = units
    options = dict(kind=kind, gyro_unit=gyro_unit, accel_unit=accel_unit, axes=axes,
                   table_unit=table_unit, time_col=time_col, table=True)
    path = tmp_path_factory.mktemp("h") / "h.txt"
    logs.write_log(path, data, **options)
    back = logs.read_log(path, dt=0.01, strict=False, plausibility=False, **options)
    np.testing.assert_array_equal(back.tick, data.tick)
    assert_within_ulps(back.dtheta_p, data.dtheta_p, 4)      # see the comment above
    assert_within_ulps(back.dv_p, data.dv_p, 4)
    assert_within_ulps(back.table_angle_rad, data.table_angle_rad, 2)


# ---------------------------------------------------------------------------
# Malformed files: one line naming the file, the place and the reason
# ---------------------------------------------------------------------------
ROW = "1e-6 2e-6 3e-6 1e-4 2e-4 0.098"       # gyro [rad], accel [m/s], per 10 ms


def rows(times, row=ROW):
    return "".join(f"{row} {t}\n" for t in times)


def expect_error(path, *parts, **options):
    with pytest.raises(logs.LogError) as info:
        logs.read_log(path, **options)
    msg = str(info.value)
    assert "\n" not in msg, msg
    assert msg.startswith(str(path) + ": "), msg
    for part in parts:
        assert part in msg, msg
    issues = logs.check_log(path, **{k: v for k, v in options.items() if k != "strict"})
    assert issues and any(part in i.message for i in issues for part in parts[:1]), issues
    return msg


@pytest.mark.parametrize("text, parts", [
    ("1 2 3 4 5\n", ["line 1", "expected 7 or 8 columns", "got 5"]),
    ("% header\n" + rows([0.01]) + "1 2 3 4 5 6 0.02 0.5\n",
     ["line 3", "expected 7 columns", "like line 2", "got 8"]),
    ("# a\n\n" + rows([0.01]) + "1e-6 2e-6 abc 1e-4 2e-4 0.098 0.02\n",
     ["line 4, column 3 (gyro_z)", "'abc' is not a number"]),
    ("1e-6,2e-6,3e-6,1e-4,2e-4,0.098,0.01\n", ["line 1", "got 1", "fmt='csv'"]),
    ("1e-6 2e-6 3e-6 1e-4 2e-4 0.098;0.01 0.5\n",
     ["line 1, column 6 (accel_z)", "'0.098;0.01' is not a number", "fmt='csv'"]),
    (rows([0.01, 0.02]) + "1e-6 2e-6 3e-6 1e-4 NaN 0.098 0.03\n",
     ["line 3, column 5 (accel_y)", "nan is not finite"]),
    (rows([0.01, 0.02, 0.03]) + "1e-6 2e-6 3e-6 1e-4 2e-4 -inf 0.04\n",
     ["line 4, column 6 (accel_z)", "-inf is not finite"]),
    (rows([0.01, 0.02, 0.03, 0.025]), ["line 4", "goes back from 0.03 at line 3"]),
    (rows([0.01, 0.02, 0.02, 0.03]), ["line 3", "time 0.02 repeats 0.02 at line 2"]),
    (rows([0.01, 0.02, 0.03, 0.034, 0.04, 0.05]),
     ["line 4", "less than half the tick dt=0.01 s"]),
    ("% only a comment\n\n", ["no data lines"]),
])
def test_text_malformed(tmp_path, text, parts):
    path = tmp_path / "field_log.txt"
    path.write_text(text)
    expect_error(path, *parts)


def test_text_gap_is_a_warning_with_missing_ticks(tmp_path):
    path = tmp_path / "gappy.txt"
    path.write_text("% PSINS-style\n" + rows([0.01, 0.02, 0.03, 0.07, 0.08, 0.09, 0.10]))
    expect_error(path, "line 5", "gap of 0.04 s after line 4 (t=0.03)", "3 missing ticks",
                 "strict=False")
    issues = logs.check_log(path)
    assert [i.level for i in issues] == ["warning"]
    data = logs.read_log(path, strict=False)
    np.testing.assert_array_equal(data.tick, [1, 2, 3, 7, 8, 9, 10])
    assert data.metadata["warnings"] == [issues[0].message]


def test_many_gaps_are_summarised(tmp_path):
    times = np.concatenate([np.arange(0, 30) * 0.03, [0.9 + 0.01 * k for k in range(1, 60)]])
    path = tmp_path / "holes.txt"
    path.write_text(rows([f"{t:.2f}" for t in times]))
    issues = logs.check_log(path)
    assert len(issues) == logs.MAX_LISTED + 1
    # 29 gaps of 2 ticks, then 0.87 -> 0.91 s: 3 ticks
    assert "and 20 more gaps; 30 gaps, 61 missing ticks in all" in issues[-1].message


def test_text_irregular_step(tmp_path):
    path = tmp_path / "jitter.txt"
    path.write_text(rows([0.01, 0.02, 0.03, 0.0405, 0.05, 0.06]))
    msg = expect_error(path, "line 4", "irregular time step 0.0105 s", "more than 1%")
    assert "2 such steps" in msg            # 0.0105 then 0.0095
    # jitter within 1 % of the tick is fine
    path.write_text(rows([0.01, 0.02, 0.03, 0.04005, 0.05, 0.06]))
    assert logs.check_log(path) == []


def test_text_wrong_dt(tmp_path):
    path = tmp_path / "rate200.txt"
    path.write_text(rows([0.005 * k for k in range(1, 20)], row="1e-6 2e-6 3e-6 1e-4 2e-4 0.049"))
    expect_error(path, "lines 1-19", "median time step 0.005 s differs from dt=0.01 s", dt=0.01)
    data = logs.read_log(path)            # inferred: a 200 Hz log is fine as such
    assert data.dt == 0.005


def test_text_single_sample_needs_dt(tmp_path):
    path = tmp_path / "one.txt"
    path.write_text(rows([0.01]))
    expect_error(path, "line 1", "cannot be inferred; pass dt")
    assert logs.read_log(path, dt=0.01).tick.tolist() == [1]


def test_text_not_utf8(tmp_path):
    path = tmp_path / "really_binary.txt"
    logs.write_log(path, static_log(n=4), fmt="binary")
    expect_error(path, "not UTF-8 text", "fmt='binary'")


def test_binary_size(tmp_path):
    path = tmp_path / "cut.bin"
    path.write_bytes(b"\0" * (56 * 3 + 20))
    expect_error(path, "size 188 bytes", "56-byte records", "3 whole records and 20 bytes over")
    path.write_bytes(b"\0" * 100)
    expect_error(path, "size 100 bytes", "64-byte records", "1 whole record and 36 bytes over",
                 table=True)
    path.write_bytes(b"")
    expect_error(path, "no records")


def test_binary_nan_and_time(tmp_path):
    data = static_log(n=6)
    path = tmp_path / "rec.bin"
    logs.write_log(path, data)
    raw = np.fromfile(path, dtype="<f8").reshape(6, 7)
    raw[2, 2] = np.nan
    raw.tofile(path)
    expect_error(path, "record 2 (0-based, byte offset 112), field 3 (gyro_y)",
                 "nan is not finite")
    raw[2, 2] = 0.0
    raw[4, 0] = raw[3, 0] - 0.001
    raw.tofile(path)
    expect_error(path, "record 4 (0-based, byte offset 224)", "goes back from", "record 3")
    raw[4, 0] = raw[3, 0] + 0.05
    raw[5, 0] = raw[4, 0] + 0.01
    raw.tofile(path)
    expect_error(path, "record 4", "4 missing ticks")


def test_project_formats_errors_are_log_errors(tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text(logs.CSV_HEADER + "\n1,1,2,x3,4,5,6,7\n")
    expect_error(path, "line 2, column 4 (dtheta_z_rad)", "not a number")
    path = tmp_path / "bad.npz"
    np.savez(path, dtheta_p=np.zeros((3, 3)))
    expect_error(path, "no accel array", "the file has dtheta_p")


def test_project_formats_are_checked_too(tmp_path):
    data = static_log(n=50)
    data.tick[20:] += 3
    path = tmp_path / "gappy.npz"
    logs.write_log(path, data)
    expect_error(path, "sample 20 (0-based)", "3 missing ticks after tick 20")
    data.dv_p *= 100.0                      # m/s^2 stored as if they were increments
    logs.write_log(path, data)
    expect_error(path, "samples 0-49", "these look like m/s^2 rates, not m/s increments",
                 strict=False)


# ---------------------------------------------------------------------------
# Implausible magnitudes: the hints fire on unit mix-ups, not on real data
# ---------------------------------------------------------------------------
def test_plausible_logs_pass(tmp_path):
    # static IMU at 34 deg latitude with seed-002 noise, and a ship in a bad
    # sea, each written and declared in every unit: no finding at all
    for data in (static_log(), ship_log()):
        for options in ({}, {"gyro_unit": "deg"}, {"kind": "rates"},
                        {"kind": "rates", "gyro_unit": "deg/s", "accel_unit": "g"},
                        {"kind": "rates", "gyro_unit": "deg/h"}):
            path = tmp_path / "ok.txt"
            logs.write_log(path, data, **options)
            assert logs.check_log(path, **options) == [], options


@pytest.mark.parametrize("written, declared, parts", [
    # gyro: the ship's 0.35 rad/s roll rate is 20 deg/s
    ({"gyro_unit": "deg"}, {}, ["gyro rate", "rad/s (read as rad increments) exceeds 10 rad/s",
                                "these look like deg, not rad"]),
    ({"kind": "rates", "gyro_unit": "deg/s"}, {"kind": "rates"},
     ["these look like deg/s, not rad/s"]),
    # accelerometer: per-tick dv of ~9.8, ~1 where m/s^2 was declared, ...
    ({"kind": "rates"}, {}, ["median specific force", "(read as m/s increments)",
                             "these look like m/s^2 rates, not m/s increments"]),
    ({"kind": "rates", "accel_unit": "g"}, {"kind": "rates"},
     ["(read as m/s^2 rates)", "these look like g rates, not m/s^2 rates"]),
    ({}, {"kind": "rates"}, ["these look like m/s increments, not m/s^2 rates"]),
    ({"kind": "rates"}, {"kind": "rates", "accel_unit": "g"},
     ["these look like m/s^2 rates, not g rates"]),
    ({"kind": "rates", "accel_unit": "g"}, {}, ["these look like g rates, not m/s increments"]),
])
def test_unit_hints(tmp_path, written, declared, parts):
    path = tmp_path / "mixed_up.txt"
    logs.write_log(path, ship_log(), **written)
    msg = expect_error(path, *parts, **declared)
    assert "line" in msg


def test_gyro_hint_follows_the_accelerometer(tmp_path):
    # rates declared as increments: gravity tells, and the gyro agrees
    path = tmp_path / "rates.txt"
    logs.write_log(path, ship_log(), kind="rates", gyro_unit="deg/s")
    issues = logs.check_log(path, gyro_unit="deg")
    assert [i.level for i in issues] == ["error", "error"]
    assert "these look like m/s^2 rates, not m/s increments" in issues[0].message
    assert "line 2: gyro rate" in issues[1].message
    assert "the accelerometer says these are rates, not increments (kind='rates')" \
        in issues[1].message


def test_gyro_hint_names_the_first_bad_line(tmp_path):
    data = static_log(n=100)
    data.dtheta_p[41] = [0.0, 0.12, 0.0]        # 12 rad/s for one tick
    path = tmp_path / "spike.txt"
    logs.write_log(path, data)                   # header on line 1: sample 41 is line 43
    expect_error(path, "line 43", "gyro rate 12 rad/s", "these look like deg, not rad")
    assert logs.read_log(path, plausibility=False).dtheta_p[41, 1] == 0.12


def test_no_gravity_needs_plausibility_off(tmp_path):
    data = static_log(n=50)
    data.dv_p[:] = 0.0
    path = tmp_path / "gyro_bench.bin"
    logs.write_log(path, data)
    expect_error(path, "records 0-49 (0-based)", "check accel_unit and kind",
                 "plausibility=False")
    assert_same_data(logs.read_log(path, plausibility=False), data)


# ---------------------------------------------------------------------------
# Wrong options are ValueErrors (the caller's mistake, not the file's)
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("options, match", [
    ({"axes": [[1, 0, 0], [0, 1, 0], [0, 0, 2]]}, "not a signed permutation"),
    ({"axes": [[1, 0, 0], [1, 0, 0], [0, 0, 1]]}, "not a signed permutation"),
    ({"axes": [[0.6, 0.8, 0], [-0.8, 0.6, 0], [0, 0, 1]]}, "not a signed permutation"),
    ({"axes": [[0, 1, 0], [1, 0, 0], [0, 0, 1]]}, "determinant -1"),
    ({"axes": np.eye(2)}, "must be 3x3"),
    ({"axes": "xyz"}, "unknown frame 'xyz'"),
    ({"axes": "rfu->frd"}, "target must be the IMU frame p"),
    ({"gyro_unit": "deg/s"}, "does not go with kind='increments'"),
    ({"kind": "rates", "accel_unit": "m/s"}, "does not go with kind='rates'"),
    ({"kind": "rate"}, "kind 'rate'"),
    ({"time_col": "middle"}, "time_col 'middle'"),
    ({"table_unit": "grad"}, "table_unit"),
    ({"dt": -0.01}, "positive"),
    ({"time_col": "none"}, "pass dt"),
    ({"fmt": "binary", "time_col": "last"}, "always start with the time"),
    ({"columns": {"t": "time"}}, "does not apply to text"),
    ({"fmt": "csv", "columns": {"time": "t"}}, "must map roles"),
    ({"fmt": "psins", "gyro_unit": "deg"}, "states its units"),
    ({"gyro_scale": 0.0}, "gyro_scale must be a positive number"),
    ({"fmt": "xls"}, "fmt 'xls'"),
])
def test_bad_options(tmp_path, options, match):
    path = tmp_path / "opts.txt"
    path.write_text(rows([0.01, 0.02]))
    with pytest.raises(ValueError, match=match) as info:
        logs.read_log(path, **options)
    assert not isinstance(info.value, logs.LogError)


def test_bad_extension_and_writer_refusals(tmp_path):
    with pytest.raises(ValueError, match=r"log\.xyz: cannot tell the format"):
        logs.read_log(tmp_path / "log.xyz")
    data = static_log(n=10, table=True)
    with pytest.raises(ValueError, match="would drop non-zero table angles"):
        logs.write_log(tmp_path / "x.bin", data)
    data.tick[5:] += 1
    data.table_angle_rad[:] = 0.0
    with pytest.raises(ValueError, match="cannot show the gaps"):
        logs.write_log(tmp_path / "x.txt", data, time_col="none")
    data.dtheta_p[3, 0] = np.nan
    with pytest.raises(ValueError, match="dtheta_p has NaN"):
        logs.write_log(tmp_path / "x.txt", data)
    path = tmp_path / "with_table.txt"
    logs.write_log(path, static_log(n=10, table=True))
    with pytest.raises(ValueError, match="table_angle given"):
        logs.read_log(path, table_angle=0.1)
