"""External reference sensors of the simulator (pyins.sim.references):
truth, lever arms, error statistics, faults, the log, the DVL, files, seeds."""
import numpy as np
import pytest

from pyins import sim
from pyins.reference import earth
from pyins.sim import references as R
from pyins.units import DEG_TO_RAD, DT

D = DEG_TO_RAD
LAT, LON, HEIGHT = 30.0 * D, 120.0 * D, 10.0
NO_ERRORS = dict(pos_noise_m=0.0, vel_noise_mps=0.0, bias_sigma_m=0.0)


@pytest.fixture(scope="module")
def manoeuvre():
    return sim.Manoeuvre(LAT, LON, HEIGHT, 0.3, sim.default_segments(), pitch=0.02, roll=-0.03)


@pytest.fixture(scope="module")
def static():
    return sim.Static(LAT, LON, HEIGHT, yaw=0.5)


def metres(pos, ref):
    """ENU difference [m] of [lat, lon, h] rows pos - ref (radii at ref)."""
    rm, rn = earth.principal_radii(np.sin(ref[:, 0]))
    return np.column_stack([(pos[:, 1] - ref[:, 1]) * (rn + ref[:, 2]) * np.cos(ref[:, 0]),
                            (pos[:, 0] - ref[:, 0]) * (rm + ref[:, 2]), pos[:, 2] - ref[:, 2]])


def split(refs):
    return refs.select(R.KIND_GNSS_POS), refs.select(R.KIND_GNSS_VEL)


def test_record_layout():
    dt = R.REF_DTYPE
    assert dt.itemsize == 64
    assert [dt.fields[f][1] for f in dt.names] == [0, 4, 8, 16, 40]
    assert (R.KIND_GNSS_POS, R.KIND_GNSS_VEL, R.KIND_SPEED_LOG, R.KIND_DVL,
            R.KIND_ZERO_VEL) == (1, 2, 3, 4, 5)


def test_record_layout_is_the_headers():
    from pyins import contract        # the dtype read from csrc/include/pyins_core.h
    if not hasattr(contract, "REF_DTYPE"):
        pytest.skip("this pyins.contract has no REF_DTYPE")
    c = contract.REF_DTYPE
    assert c.names == R.REF_DTYPE.names and c.itemsize == R.REF_DTYPE.itemsize
    assert all(c.fields[f] == R.REF_DTYPE.fields[f] for f in c.names)


def test_schedule():
    assert R.schedule(5.0, 1.0).tolist() == [100, 200, 300, 400, 500]
    assert R.schedule(2.0, 2.0, t0_s=10.0).tolist() == [1050, 1100, 1150, 1200]
    with pytest.raises(ValueError, match="whole number"):
        R.schedule(10.0, 3.0)          # 33.3 ticks between fixes


# --- truth -------------------------------------------------------------------
def test_error_free_gnss_is_the_truth_of_a_manoeuvre(manoeuvre):
    pos, vel = split(R.gnss(manoeuvre, 1800.0, **NO_ERRORS))
    assert len(pos) == len(vel) == 1800 and np.all(pos.refs["tick"] == vel.refs["tick"])
    tr = sim.truth_at(manoeuvre, pos.refs["tick"])
    true_pos = np.column_stack([tr.lat, tr.lon, tr.height])
    # 1e-6 m: the brief's bound; both sides are the same closed-form state, so ~0.
    assert np.abs(metres(pos.refs["value"], true_pos)).max() < 1e-6
    assert np.abs(vel.refs["value"] - tr.vel_n).max() < 1e-9
    assert np.array_equal(pos.truth_value, pos.refs["value"])
    with pytest.raises(ValueError, match="motion lasts"):
        R.gnss(manoeuvre, 1801.0)


def test_error_free_gnss_of_a_moored_ship():
    ship = sim.moored("bad", LAT, LON, HEIGHT, 0.4)
    pos, vel = split(R.gnss(ship, 300.0, **NO_ERRORS))
    tr = sim.truth_at(ship, pos.refs["tick"])
    ref = np.column_stack([tr.lat, tr.lon, tr.height])      # the motion reference point
    assert np.abs(metres(pos.refs["value"], ref)).max() < 1e-6
    assert np.abs(vel.refs["value"] - tr.vel_n).max() < 1e-9
    # An antenna at the IMU's lever arm is the IMU point. ShipAtSea places it with
    # the radii fixed at the site and we with those at the current latitude and
    # height: a relative difference ~ heave / R ~ 2e-7, i.e. ~1e-7 m on the 2 m arm
    # and ~1e-7 m/s on ~0.5 m/s; 1e-6 bounds that with margin.
    pos, vel = split(R.gnss(ship, 300.0, lever_b=ship.lever_b, **NO_ERRORS))
    imu = np.column_stack([tr.imu_lat, tr.imu_lon, tr.imu_height])
    assert np.abs(metres(pos.refs["value"], imu)).max() < 1e-6
    assert np.abs(vel.refs["value"] - tr.imu_vel_n).max() < 1e-6


def test_lever_arm_of_a_pure_yaw_rotation():
    motion = sim.HeadingSwing(LAT, LON, HEIGHT, 0.0, 0.0, 0.2, 6.0 * D, 60.0)
    lever = np.array([1.0, 10.0, 2.0])
    ticks = np.arange(100, 6000, 37)
    pos, vel, c, _ = R.antenna(motion, ticks, lever)
    yaw_rate = motion.state(ticks * DT).euler_rate[:, 2]
    r_n = np.einsum("nij,j->ni", c, lever)
    expected = np.cross(np.column_stack([0 * yaw_rate, 0 * yaw_rate, yaw_rate]), r_n)
    assert np.abs(vel - expected).max() < 1e-12     # w x r, rounding only (|v| ~ 1 m/s)
    # Fourth-order central difference over +-2 ticks of the antenna position: the
    # truncation is ~h^4 r w^5 / 30 ~ 1e-15 m/s; the rounding of lat, lon (1e-16
    # rad ~ 7e-10 m) over 0.12 s gives ~1e-8 m/s. 1e-6 m/s leaves a wide margin.
    p = [metres(R.antenna(motion, ticks + k, lever)[0], pos) for k in (-2, -1, 1, 2)]
    fd = (p[0] - 8 * p[1] + 8 * p[2] - p[3]) / (12 * DT)
    assert np.abs(fd - vel).max() < 1e-6


# --- statistics and faults ------------------------------------------------------
def test_white_noise_std(static):
    pos, vel = split(R.gnss(static, 3600.0, pos_noise_m=(3.0, 3.0, 5.0), vel_noise_mps=0.05,
                            bias_sigma_m=0.0, seed=3))
    err = metres(pos.refs["value"], pos.truth_value)
    # N = 3600: a sample std has relative sd 1/sqrt(2N) = 1.2 %, so 10 % is ~8 sd.
    assert np.allclose(err.std(axis=0), [3.0, 3.0, 5.0], rtol=0.10)
    assert np.allclose((vel.refs["value"] - vel.truth_value).std(axis=0), 0.05, rtol=0.10)
    assert np.allclose(pos.refs["sigma"], [3.0, 3.0, 5.0])


def test_gauss_markov_bias(static):
    tau, sigma = 300.0, 2.0
    pos, _ = split(R.gnss(static, 86400.0, rate_hz=0.1, pos_noise_m=0.0, bias_sigma_m=sigma,
                          bias_tau_s=tau, velocity=False, seed=5))
    b = metres(pos.refs["value"], pos.truth_value)
    lag = int(tau * 0.1)
    rho = np.mean([np.corrcoef(b[:-lag, i], b[lag:, i])[0, 1] for i in range(3)])
    # 24 h / tau gives only ~144 independent stretches per axis: Bartlett's formula
    # puts the sd of a lag-tau autocorrelation at ~0.045 per axis, ~0.026 for the
    # mean of three, so +-0.12 (4.5 sd) about e^-1; the std (sd ~3.5 %) within 15 %.
    assert abs(rho - np.exp(-1.0)) < 0.12
    assert np.allclose(b.std(axis=0), sigma, rtol=0.15)
    assert np.allclose(pos.refs["sigma"], sigma)     # sqrt(0^2 + 2^2)


def test_outages_remove_exactly_the_fixes_inside(static):
    full = R.gnss(static, 600.0, seed=2)
    cut = R.gnss(static, 600.0, seed=2, outages=[(100.0, 200.0), (350.5, 351.0)])
    t = full.refs["tick"] * DT
    keep = ~(((t >= 100.0) & (t < 200.0)) | ((t >= 350.5) & (t < 351.0)))
    assert np.array_equal(cut.refs.tobytes(), full.refs[keep].tobytes())
    assert len(full) - len(cut) == 2 * 100


def test_outliers(static):
    n, rate = 3600, 0.05
    base, _ = split(R.gnss(static, float(n), seed=4))
    hit, _ = split(R.gnss(static, float(n), seed=4, outlier_rate=rate, outlier_m=(50.0, 500.0)))
    # errors in m with the radii at the true position, as the module converts them
    jump = metres(hit.refs["value"], hit.truth_value) - metres(base.refs["value"], base.truth_value)
    jumped = np.hypot(jump[:, 0], jump[:, 1]) > 1e-3
    # Binomial(3600, 0.05): mean 180, sd 13.1; +-5 sd.
    assert abs(jumped.sum() - rate * n) < 5 * np.sqrt(n * rate * (1 - rate))
    mag = np.hypot(jump[jumped, 0], jump[jumped, 1])
    assert mag.min() > 50.0 - 1e-6 and mag.max() < 500.0 + 1e-6     # 1e-6 m: rounding
    assert np.abs(jump[:, 2]).max() < 1e-9                           # horizontal only
    assert np.array_equal(hit.refs["sigma"], base.refs["sigma"])     # not informed


def test_frozen_receiver_repeats_the_last_fix(static):
    ref = R.gnss(static, 600.0, seed=6, frozen=[(300.0, 400.0), (0.0, 5.0)])
    for kind in (R.KIND_GNSS_POS, R.KIND_GNSS_VEL):
        r = ref.select(kind)
        t = r.refs["tick"] * DT
        inside = (t >= 300.0) & (t < 400.0)
        last = np.flatnonzero(t < 300.0)[-1]
        assert t[last] == 299.0 and inside.sum() == 100
        assert np.all(r.refs["value"][inside] == r.refs["value"][last])
        assert np.all(np.diff(r.refs["tick"][inside]) == 100)      # the tick advances
        assert t[0] == 5.0          # frozen with nothing to repeat: no fixes


def test_offsets_add_exactly(static):
    off = (10.0, -20.0, 5.0)
    base, _ = split(R.gnss(static, 900.0, seed=7))
    moved, _ = split(R.gnss(static, 900.0, seed=7, offsets=[(500.0, 600.0, off)]))
    d = (metres(moved.refs["value"], moved.truth_value)
         - metres(base.refs["value"], base.truth_value))
    t = base.refs["tick"] * DT
    inside = (t >= 500.0) & (t < 600.0)
    # 1e-6 m: the rad <-> m conversion rounds at ~1e-9 m.
    assert np.abs(d[inside] - off).max() < 1e-6
    assert np.all(d[~inside] == 0.0)


def test_latency_delays_availability(static):
    ref = R.gnss(static, 10.0, latency_s=0.25)
    assert np.all(ref.avail_tick == ref.refs["tick"] + 25)


# --- speed log, DVL, zero velocity --------------------------------------------------
def test_speed_log_through_the_current(manoeuvre):
    cur = R.Current((0.4, -0.3), amplitude_mps=0.2, period_s=3600.0, seed=1)
    clean = R.speed_log(manoeuvre, 1800.0, cur, scale_factor=0.0, noise_mps=0.0)
    tr = sim.truth_at(manoeuvre, clean.refs["tick"])
    yaw, pitch = tr.euler[:, 2], tr.euler[:, 0]
    bow = np.column_stack([-np.sin(yaw) * np.cos(pitch), np.cos(yaw) * np.cos(pitch),
                           np.sin(pitch)])
    v = np.sum((tr.vel_n - cur.velocity(tr.time)) * bow, axis=1)
    assert np.abs(clean.refs["value"][:, 0] - v).max() < 1e-9
    assert np.all(clean.refs["value"][:, 1:] == 0.0) and np.all(clean.refs["sigma"][:, 1:] == 0.0)
    biased = R.speed_log(manoeuvre, 1800.0, cur, scale_factor=0.01, bias_mps=0.1, noise_mps=0.0)
    assert np.abs(biased.refs["value"][:, 0] - (1.01 * v + 0.1)).max() < 1e-12
    noisy = R.speed_log(manoeuvre, 1800.0, cur, scale_factor=0.0, noise_mps=0.05, seed=2)
    # N = 1800: relative sd of a std 1.7 %; 10 % is ~6 sd.
    assert np.isclose(np.std(noisy.refs["value"][:, 0] - v), 0.05, rtol=0.10)
    assert np.all(noisy.refs["sigma"][:, 0] == 0.05)


def test_current_model():
    cur = R.Current((0.4, -0.3, 0.0), amplitude_mps=0.2, period_s=1000.0, seed=3)
    t = np.linspace(0.0, 5000.0, 501)
    v = cur.velocity(t)
    assert np.all(v[:, 2] == 0.0)
    assert np.abs(v[:, :2] - [0.4, -0.3]).max() <= 0.2 + 1e-15
    assert np.abs(cur.velocity(t + 1000.0) - v).max() < 1e-12   # one period; rounding
    assert not np.array_equal(R.Current((0.4, -0.3), 0.2, 1000.0, seed=4).velocity(t), v)
    assert np.all(R.Current((0.4, -0.3)).velocity(t) == [0.4, -0.3, 0.0])
    with pytest.raises(ValueError):
        R.Current((0.1, 0.2, 0.3))


def test_dvl(manoeuvre):
    bottom = R.dvl(manoeuvre, 1800.0, noise_mps=0.0)
    tr = sim.truth_at(manoeuvre, bottom.refs["tick"])
    c = sim.euler_to_mat(tr.euler)
    v_b = np.einsum("nji,nj->ni", c, tr.vel_n)          # C_n^b v
    assert np.abs(bottom.refs["value"] - v_b).max() < 1e-12    # rounding at 10 m/s
    a = 0.03                                                   # about z: d = Rz(a) b
    turned = R.dvl(manoeuvre, 1800.0, misalignment_rad=(0.0, 0.0, a), noise_mps=0.0)
    ca, sa = np.cos(a), np.sin(a)
    expected = np.column_stack([ca * v_b[:, 0] + sa * v_b[:, 1],
                                -sa * v_b[:, 0] + ca * v_b[:, 1], v_b[:, 2]])
    assert np.abs(turned.refs["value"] - expected).max() < 1e-12
    m = np.array([0.01, -0.02, 0.005])
    small = R.dvl(manoeuvre, 1800.0, misalignment_rad=m, noise_mps=0.0, scale_factor=0.002)
    first_order = 1.002 * (v_b - np.cross(m, v_b))          # (I - [m x]) v_b
    # second order in m: |m|^2 |v| / 2 ~ 3e-3 m/s at 10 m/s
    assert np.abs(small.refs["value"] - first_order).max() < np.dot(m, m) * 10.5
    cur = R.Current((0.5, 0.2))
    water = R.dvl(manoeuvre, 1800.0, current=cur, noise_mps=0.0)
    v_w = np.einsum("nji,nj->ni", c, tr.vel_n - [0.5, 0.2, 0.0])
    assert np.abs(water.refs["value"] - v_w).max() < 1e-12
    # water track is marked (the ABI's reserved = 1: the firmware refuses it), bottom track is not
    assert np.all(water.refs["reserved"] == 1) and np.all(bottom.refs["reserved"] == 0)


def test_zero_velocity():
    z = R.zero_velocity(60.0, rate_hz=2.0, sigma_mps=0.02, t0_s=100.0)
    assert len(z) == 120 and z.refs["tick"][0] == 10050 and z.refs["tick"][-1] == 16000
    assert np.all(z.refs["kind"] == R.KIND_ZERO_VEL) and np.all(z.refs["value"] == 0.0)
    assert np.all(z.refs["sigma"] == 0.02)


def test_merge_sorted_and_stable(static):
    g = R.gnss(static, 20.0, seed=1)
    z = R.zero_velocity(20.0, rate_hz=2.0)
    z2 = R.zero_velocity(20.0, sigma_mps=0.5)
    m = R.merge(z, g, z2)
    key = m.refs["tick"] * 10 + m.refs["kind"]
    assert np.all(np.diff(key) >= 0) and len(m) == len(g) + len(z) + len(z2)
    same = (m.refs["kind"] == R.KIND_ZERO_VEL) & (m.refs["tick"] == 1000)
    assert m.refs["sigma"][same, 0].tolist() == [0.01, 0.5]      # argument order kept


# --- files ------------------------------------------------------------------------
def all_kinds(seed=0):
    cur = R.Current((0.3, 0.1), 0.1, seed=seed)
    ship = sim.moored("general", -70.0 * D, 179.9 * D, 5.0, 1.0)
    return R.merge(R.gnss(ship, 60.0, seed=seed, lever_b=(1.0, 2.0, 20.0)),
                   R.speed_log(ship, 60.0, cur, seed=seed),
                   R.dvl(ship, 60.0, None, misalignment_rad=(0.01, 0.0, 0.02), seed=seed),
                   R.zero_velocity(60.0))


def test_csv_round_trip_is_bit_exact(tmp_path):
    refs = all_kinds().refs
    rng = np.random.default_rng(0)
    many = np.zeros(3000, R.REF_DTYPE)          # lat, lon all over the globe
    many["kind"], many["tick"] = R.KIND_GNSS_POS, np.arange(3000)
    many["value"] = np.column_stack([rng.uniform(-np.pi / 2, np.pi / 2, 3000),
                                     rng.uniform(-np.pi, np.pi, 3000), rng.normal(0, 100, 3000)])
    many["value"][:4, :2] = [[-0.0, -0.0], [np.pi / 2, np.pi], [1e-300, -5e-324], [0.0, 0.0]]
    many["sigma"] = 1.0
    for arr in (refs, many):
        path = tmp_path / "refs.csv"
        R.save_refs_csv(path, arr)
        back = R.load_refs_csv(path)
        assert back.dtype == R.REF_DTYPE and back.tobytes() == arr.tobytes()
    lines = (tmp_path / "refs.csv").read_text().splitlines()
    assert lines[0] == R.CSV_HEADER
    row = lines[1].split(",")                  # degrees in the file
    assert row[1] == "gnss_pos" and np.isclose(float(row[2]), many["value"][0, 0] / D, rtol=1e-15)


GOOD = ["tick,kind,v0,v1,v2,s0,s1,s2",
        "100,gnss_pos,30.5,120.25,10.0,3.0,3.0,5.0",
        "100,gnss_vel,0.1,0.2,0.0,0.05,0.05,0.05",
        "200,speed_log,5.0,0.0,0.0,0.05,0.0,0.0",
        "300,zero_velocity,0.0,0.0,0.0,0.01,0.01,0.01"]


@pytest.mark.parametrize("line, text, match", [
    (1, "tick,kind,v0,v1,v2,s0,s1", "header"),
    (3, "100,gnss_vel,0.1,0.2,0.05,0.05,0.05", "8 wanted"),
    (3, "100,gnss_vel,0.1,abc,0.0,0.05,0.05,0.05", "abc"),
    (3, "1.5,gnss_vel,0.1,0.2,0.0,0.05,0.05,0.05", "1.5"),
    (3, "100,lidar,0.1,0.2,0.0,0.05,0.05,0.05", "unknown kind"),
    (3, "100,gnss_vel,nan,0.2,0.0,0.05,0.05,0.05", "non-finite"),
    (2, "100,gnss_pos,inf,120.0,10.0,3.0,3.0,5.0", "non-finite"),
    (3, "100,gnss_vel,0.1,0.2,0.0,0.05,0.0,0.05", "must be > 0"),
    (4, "200,speed_log,5.0,0.0,0.0,-0.05,0.0,0.0", "must be > 0"),
    (4, "200,speed_log,5.0,0.0,0.0,0.05,0.05,0.0", "component 0 only"),
    (5, "150,zero_velocity,0.0,0.0,0.0,0.01,0.01,0.01", "must not decrease"),
])
def test_bad_files_name_the_line(tmp_path, line, text, match):
    path = tmp_path / "bad.csv"
    lines = list(GOOD)
    lines[line - 1] = text
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match=match) as e:
        R.load_refs_csv(path)
    assert f"{path}:{line}:" in str(e.value)


def test_good_file_and_refused_save(tmp_path):
    path = tmp_path / "good.csv"
    path.write_text("\n".join(GOOD) + "\n\n")
    refs = R.load_refs_csv(path)
    assert refs["kind"].tolist() == [1, 2, 3, 5]
    assert refs["value"][0, 0] == 30.5 * D and refs["value"][0, 1] == 120.25 * D
    refs["sigma"][1, 2] = 0.0
    with pytest.raises(ValueError, match="line 3"):
        R.save_refs_csv(tmp_path / "out.csv", refs)
    # a water-track DVL has no row: a dvl row is bottom track (the firmware's only track)
    water = R.dvl(sim.moored("general", 0.0, 0.0, 0.0, 0.0), 5.0, R.Current((0.3, 0.1)))
    with pytest.raises(ValueError, match="record 0 .*water-track dvl record"):
        R.save_refs_csv(tmp_path / "out.csv", water)


# --- seeds ------------------------------------------------------------------------
def test_seeds(static):
    def run(seed):
        return R.gnss(static, 300.0, seed=seed, outlier_rate=0.1).refs.tobytes()
    assert run(1) == run(1) and run(1) != run(2)
    assert all_kinds(3).refs.tobytes() == all_kinds(3).refs.tobytes()
    assert all_kinds(3).refs.tobytes() != all_kinds(4).refs.tobytes()
