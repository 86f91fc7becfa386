"""Exact increments and truth: static values, convergence, chunking, independent checks."""
import numpy as np
import pytest

from pyins.reference import attitude, earth
from pyins.sim import imu
from pyins.sim import motion as M
from pyins.sim import turntable as T
from pyins.sim.sensors import SensorModel, preset
from pyins.units import DT
from pyins import units

D = units.DEG_TO_RAD
LAT, LON, HEIGHT = 30.0 * D, 120.0 * D, 100.0


@pytest.fixture(scope="module")
def bad_sea():
    return M.sea_state("bad", LAT, LON, HEIGHT, 40.0 * D, phase=(0.3, 1.1, -0.7))


@pytest.fixture(scope="module")
def manoeuvre():
    return M.Manoeuvre.default(LAT, LON, HEIGHT, 10.0 * D)


class NotStatic(M.Motion):
    """Delegates to a Static profile without being one: forces the generic path."""

    def __init__(self, inner):
        self.inner = inner

    def state(self, t, t_lo=None):
        return self.inner.state(t, t_lo)


# --- small quaternion helpers for the independent checks (N, 4) -------------
def qmul(p, q):
    pw, px, py, pz = p.T
    qw, qx, qy, qz = q.T
    return np.stack([pw * qw - px * qx - py * qy - pz * qz,
                     pw * qx + px * qw + py * qz - pz * qy,
                     pw * qy - px * qz + py * qw + pz * qx,
                     pw * qz + px * qy - py * qx + pz * qw], axis=-1)


def rotvec_to_quat(v):
    theta = np.linalg.norm(v, axis=-1, keepdims=True)
    s = np.where(theta > 0, np.sin(0.5 * theta) / np.where(theta > 0, theta, 1.0), 0.5)
    return np.concatenate([np.cos(0.5 * theta), s * v], axis=-1)


def quat_to_rotvec(q):
    q = q * np.where(q[:, :1] < 0, -1.0, 1.0)
    r = np.linalg.norm(q[:, 1:], axis=1)
    k = np.where(r > 0, 2.0 * np.arctan2(r, q[:, 0]) / np.where(r > 0, r, 1.0), 2.0)
    return k[:, None] * q[:, 1:]


def conj(q):
    return q * np.array([1.0, -1.0, -1.0, -1.0])


# --- tests ---------------------------------------------------------------------
def test_static_increments_equal_earth_rate_and_gravity():
    # Static, with a tilted attitude: dtheta = C_n^b omega_ie^n dt and
    # dv = C_n^b [0, 0, g] dt. 1e-18 rad is ~1e-12 of the 7e-7 rad per tick.
    euler = np.array([1.0, -2.0, 200.0]) * D
    st = M.Static(LAT, LON, HEIGHT, *euler)
    dtheta, dv, angle = imu.exact_increments(st, 50)
    c_nb = attitude.euler_to_mat(euler)        # C_b^n
    w_ie = np.array([0.0, earth.OMEGA_IE * np.cos(LAT), earth.OMEGA_IE * np.sin(LAT)])
    g = earth.normal_gravity(np.sin(LAT), HEIGHT)
    assert np.max(np.abs(dtheta - c_nb.T @ w_ie * DT)) < 1e-18
    # dv: 1e-16 m/s is one ulp of 0.098 m/s
    assert np.max(np.abs(dv - c_nb.T @ np.array([0.0, 0.0, g]) * DT)) < 1e-16
    assert np.all(angle == 0.0)


def test_static_fast_path_equals_generic_path():
    st = M.Static(LAT, LON, HEIGHT, 0.01, 0.02, 1.0)
    for table in (None, T.Fixed(1.2)):
        fast = imu.exact_increments(st, 1000, table=table, start_tick=123)
        slow = imu.exact_increments(NotStatic(st), 1000, table=table, start_tick=123)
        assert np.max(np.abs(fast[0] - slow[0])) < 1e-18
        assert np.max(np.abs(fast[1] - slow[1])) < 1e-18
        np.testing.assert_array_equal(fast[2], slow[2])


@pytest.mark.parametrize("profile", ["bad_sea", "manoeuvre"])
def test_quadrature_converged(profile, request):
    # nodes=5 against nodes=8 per tick: < 1e-15 rad and < 1e-14 m/s (1e-10 rad
    # per tick would already look like a 0.002 deg/h gyro). Checked at the
    # start and, for the sea state, 24 h into a run (phase kept exact).
    mo = request.getfixturevalue(profile)
    # manoeuvre: acceleration, first turn, second turn
    starts = [0, 40000, 77000] if profile == "manoeuvre" else [0, 8_640_000 - 20000]
    for start in starts:
        a = imu.exact_increments(mo, 20000, start_tick=start)
        b = imu.exact_increments(mo, 20000, start_tick=start, nodes=8)
        assert np.max(np.abs(a[0] - b[0])) < 1e-15
        assert np.max(np.abs(a[1] - b[1])) < 1e-14
    # ... and the midpoint rule (1 node) is visibly worse, so the comparison can fail
    a = imu.exact_increments(mo, 20000, start_tick=starts[-1])
    c = imu.exact_increments(mo, 20000, start_tick=starts[-1], nodes=1)
    assert np.max(np.abs(a[0] - c[0])) > 1e-15 and np.max(np.abs(a[1] - c[1])) > 1e-14


@pytest.mark.parametrize("profile", ["bad_sea", "manoeuvre"])
def test_chunks_are_bit_identical(profile, request):
    mo = request.getfixturevalue(profile)
    table = T.ConstantRate(6.0 * D, 0.2)
    n = 70000
    one = imu.exact_increments(mo, n, table=table)
    parts = [imu.exact_increments(mo, k, table=table, start_tick=s)
             for s, k in ((0, 50000), (50000, 13), (50013, n - 50013))]
    for i in range(3):
        np.testing.assert_array_equal(one[i], np.concatenate([p[i] for p in parts]))
    tr_one = imu.truth(mo, n, table=table)
    tr_part = imu.truth(mo, n - 50013, table=table, start_tick=50013)
    np.testing.assert_array_equal(tr_one.quat_nb[50013:], tr_part.quat_nb)
    np.testing.assert_array_equal(tr_one.lat[50013:], tr_part.lat)


def test_generate_matches_one_shot(bad_sea):
    table = T.ConstantRate(-6.0 * D)
    n = 23456
    th, dv, angle = imu.exact_increments(bad_sea, n, table=table)
    model = SensorModel(preset("seed002"), seed=7)
    mth, mdv = model.apply(th, dv)
    chunks = list(imu.generate(bad_sea, n, chunk_ticks=5000, table=table,
                               sensors=SensorModel(preset("seed002"), seed=7)))
    assert [c.first_tick for c in chunks] == [1, 5001, 10001, 15001, 20001]
    np.testing.assert_array_equal(np.concatenate([c.tick for c in chunks]), np.arange(1, n + 1))
    np.testing.assert_array_equal(np.concatenate([c.exact_dtheta_p for c in chunks]), th)
    np.testing.assert_array_equal(np.concatenate([c.exact_dv_p for c in chunks]), dv)
    np.testing.assert_array_equal(np.concatenate([c.dtheta_p for c in chunks]), mth)
    np.testing.assert_array_equal(np.concatenate([c.dv_p for c in chunks]), mdv)
    np.testing.assert_array_equal(np.concatenate([c.table_angle for c in chunks]), angle)
    tr = imu.truth(bad_sea, n, table=table)
    np.testing.assert_array_equal(np.concatenate([c.truth.euler for c in chunks]), tr.euler)


def test_euler_to_quat_matches_reference():
    rng = np.random.default_rng(3)
    euler = np.column_stack([rng.uniform(-1.5, 1.5, 500), rng.uniform(-3.1, 3.1, 500),
                             rng.uniform(-3.1, 3.1, 500)])
    euler[:5] = [[0, 0, 0], [0, 0, np.pi], [0.3, 0, -np.pi / 2], [0, 2.5, 3.0], [-1.2, -3, 0.1]]
    q = imu.euler_to_quat(euler)
    ref = np.array([attitude.euler_to_quat(e) for e in euler])
    # both are unit quaternions built from the same angles; 1e-15 ~ a few ulp
    assert np.max(np.abs(q - ref)) < 1e-15
    assert np.all(q[:, 0] >= 0.0)
    assert np.max(np.abs(np.sum(q * q, axis=1) - 1.0)) < 1e-15
    m = imu.euler_to_mat(euler)
    ref_m = np.array([attitude.euler_to_mat(e) for e in euler])
    assert np.max(np.abs(m - ref_m)) < 1e-15


def test_truth_is_state_at_end_of_tick(manoeuvre):
    table = T.ConstantRate(6.0 * D, 6.2)
    tr = imu.truth(manoeuvre, 300, table=table, t0=100.0, start_tick=10)
    np.testing.assert_array_equal(tr.tick, np.arange(11, 311))
    st = manoeuvre.state(100.0 + np.arange(11, 311) * DT)
    # positions agree to rounding of the time (1e-16 rad ~ 1 nm)
    assert np.max(np.abs(tr.lat - st.lat)) < 1e-15
    assert np.max(np.abs(tr.vel_n - st.vel_n)) < 1e-12
    # table angle at the end of the tick, wrapped to [0, 2 pi)
    expected = np.mod(6.2 + 6.0 * D * (100.0 + tr.tick * DT), 2 * np.pi)
    d = np.mod(tr.table_angle - expected + np.pi, 2 * np.pi) - np.pi
    assert np.max(np.abs(d)) < 1e-12
    assert np.all((tr.table_angle >= 0) & (tr.table_angle < 2 * np.pi))


def _attitude_residual(motion, n, t0=0.0, table=None, coning=True):
    """Truth attitude change over each tick against the composed increments.

        q(k+1) = rv(-omega_in^n dt) (x) q(k) (x) rv(dtheta_k + dtheta_{k-1} x dtheta_k / 12)

    a two-sample (previous + current) coning correction (Qin 2014 sec. 9.3),
    omega_in^n = omega_ie^n + omega_en^n from the mid-tick average of the
    truth. With a table the attitude is that of p: quat_np = quat_nb (x) q_z(alpha).
    Returns the rotation vector of the residual per tick [rad].
    """
    dtheta, _, _ = imu.exact_increments(motion, n + 1, t0=t0, table=table)
    tr = imu.truth(motion, n + 1, t0=t0, table=table)
    q = tr.quat_nb
    if table is not None:
        a = tr.table_angle
        q = qmul(q, np.column_stack([np.cos(a / 2), 0 * a, 0 * a, np.sin(a / 2)]))
    lat = 0.5 * (tr.lat[:-1] + tr.lat[1:])
    h = 0.5 * (tr.height[:-1] + tr.height[1:])
    v = 0.5 * (tr.vel_n[:-1] + tr.vel_n[1:])
    rm, rn = earth.principal_radii(np.sin(lat))
    w_in = np.column_stack([-v[:, 1] / (rm + h),
                            earth.OMEGA_IE * np.cos(lat) + v[:, 0] / (rn + h),
                            earth.OMEGA_IE * np.sin(lat) + v[:, 0] / (rn + h) * np.tan(lat)])
    phi = dtheta[1:] + (np.cross(dtheta[:-1], dtheta[1:]) / 12.0 if coning else 0.0)
    pred = qmul(qmul(rotvec_to_quat(-w_in * DT), q[:-1]), rotvec_to_quat(phi))
    return quat_to_rotvec(qmul(conj(q[1:]), pred))


@pytest.mark.parametrize("with_table", [False, True])
def test_attitude_from_increments_matches_truth(bad_sea, with_table):
    # Bad sea state: the coning algorithm's own truncation error is ~1.6e-10
    # rad per tick; bound 1e-9 rad. A sign error gives ~1e-2 rad, a wrong
    # Earth-rate sign ~1e-6 rad, increments rotated into the tick-start frame
    # (i.e. already coning-corrected) ~2e-8 rad.
    table = T.ConstantRate(6.0 * D, 0.4) if with_table else None
    assert np.max(np.abs(_attitude_residual(bad_sea, 3000, table=table))) < 1e-9
    # the check has teeth: without the coning term it fails
    assert np.max(np.abs(_attitude_residual(bad_sea, 3000, table=table, coning=False))) > 1e-9


def test_attitude_from_increments_manoeuvre(manoeuvre):
    # The ship turns slowly, so the residual is rounding (~5e-16 rad); bound
    # 1e-12 rad. The transport rate left out or with a wrong sign gives
    # 1.5e-8 / 3e-8 rad per tick while under way, so this checks omega_en.
    for t0 in (0.0, 400.0, 700.0, 1100.0):
        assert np.max(np.abs(_attitude_residual(manoeuvre, 3000, t0=t0))) < 1e-12


def _velocity_residual(motion, n, t0):
    """Truth velocity change minus a second-order velocity update from the increments.

    dv^n = [I - (dt/2) omega_in^n x] C_b^n(k) (dv + dtheta x dv / 2 + dtheta x (dtheta x dv) / 6
           + (dtheta_{k-1} x dv_k + dv_{k-1} x dtheta_k) / 12) + (g^n - (2 omega_ie + omega_en) x v) dt
    (Qin 2014 sec. 7.2 with the rotation term to second order), Earth
    quantities at the mid-tick average of the truth.
    """
    dtheta, dv, _ = imu.exact_increments(motion, n + 1, t0=t0)
    tr = imu.truth(motion, n + 1, t0=t0)
    c = imu.euler_to_mat(tr.euler)[:-1]
    lat = 0.5 * (tr.lat[:-1] + tr.lat[1:])
    h = 0.5 * (tr.height[:-1] + tr.height[1:])
    v = 0.5 * (tr.vel_n[:-1] + tr.vel_n[1:])
    sl = np.sin(lat)
    rm, rn = earth.principal_radii(sl)
    zero = np.zeros_like(lat)
    w_ie = np.column_stack([zero, earth.OMEGA_IE * np.cos(lat), earth.OMEGA_IE * sl])
    w_en = np.column_stack([-v[:, 1] / (rm + h), v[:, 0] / (rn + h), v[:, 0] / (rn + h) * np.tan(lat)])
    g = np.column_stack([zero, zero, -earth.normal_gravity(sl, h)])
    a, b = dtheta[1:], dv[1:]
    sf = (b + 0.5 * np.cross(a, b) + np.cross(a, np.cross(a, b)) / 6.0
          + (np.cross(dtheta[:-1], b) + np.cross(dv[:-1], a)) / 12.0)
    sf_n = np.einsum("kij,kj->ki", c, sf)
    sf_n = sf_n - 0.5 * DT * np.cross(w_ie + w_en, sf_n)
    dv_n = sf_n + (g - np.cross(2.0 * w_ie + w_en, v)) * DT
    return tr.vel_n[1:] - tr.vel_n[:-1] - dv_n


def test_velocity_from_increments_matches_truth(manoeuvre, bad_sea):
    # Manoeuvre, through the acceleration, both turns and the deceleration:
    # residual ~2e-10 m/s per tick; bound 1e-9 m/s. Errors it catches: a
    # Coriolis sign (~1.5e-5 m/s per tick), the transport rate left out or
    # with a wrong sign (~2e-7), the centripetal term (~5e-3), gravity (0.2).
    for t0 in (0.0, 400.0, 700.0, 1100.0):
        assert np.max(np.abs(_velocity_residual(manoeuvre, 3000, t0))) < 1e-9
    # Bad sea state (velocity zero): the third-order terms left out of the
    # update leave ~5e-9 m/s per tick; bound 5e-8 m/s.
    assert np.max(np.abs(_velocity_residual(bad_sea, 3000, 0.0))) < 5e-8


def test_table_rate_enters_z_only():
    # With a static ship, the p-frame rate is Rz(alpha)^T omega_ib^b + [0, 0, rate]:
    # the z increment gains rate * dt, and the horizontal part, a constant
    # vector seen from a frame turning at `rate`, integrates to a chord:
    # |h_p| = |h_b| sin(rate dt / 2) / (rate dt / 2) (1 - 4.6e-8 here).
    # Bounds: a few ulp of 7e-7 rad (1e-21) and of 0.1 m/s (1e-17).
    st = M.Static(LAT, LON, HEIGHT, 0.02, -0.01, 0.7)
    rate = 6.0 * D
    b, dvb, _ = imu.exact_increments(st, 200)
    p, dvp, angle = imu.exact_increments(st, 200, table=T.ConstantRate(rate))
    shrink = np.sin(0.5 * rate * DT) / (0.5 * rate * DT)
    assert np.max(np.abs(p[:, 2] - (b[:, 2] + rate * DT))) < 1e-17
    assert np.max(np.abs(np.hypot(p[:, 0], p[:, 1]) - shrink * np.hypot(b[:, 0], b[:, 1]))) < 1e-21
    assert np.max(np.abs(np.hypot(dvp[:, 0], dvp[:, 1])
                         - shrink * np.hypot(dvb[:, 0], dvb[:, 1]))) < 1e-17
    np.testing.assert_allclose(angle, rate * DT * np.arange(1, 201), rtol=0, atol=1e-14)
    # rotating the table by +alpha turns the body x axis by -alpha in p
    alpha = 0.5
    q, _, _ = imu.exact_increments(st, 1, table=T.Fixed(alpha))
    ca, sa = np.cos(alpha), np.sin(alpha)
    expected = np.array([ca * b[0, 0] + sa * b[0, 1], -sa * b[0, 0] + ca * b[0, 1], b[0, 2]])
    assert np.max(np.abs(q[0] - expected)) < 1e-20
