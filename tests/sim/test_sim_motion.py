"""Motion profiles: derivatives, sea-state mapping, heading swing, manoeuvre."""
from fractions import Fraction

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from pyins.reference import earth
from pyins.sim import motion as M
from pyins.sim import turntable as T
from pyins import units

D = units.DEG_TO_RAD
LAT, LON, HEIGHT = 30.0 * D, 120.0 * D, 100.0


@pytest.fixture(scope="module")
def manoeuvre():
    return M.Manoeuvre.default(LAT, LON, HEIGHT, 10.0 * D)


def central_diff(fun, t, h):
    """Fourth-order central difference of fun (returning (N, ...)) at times t."""
    return (fun(t - 2 * h) - 8 * fun(t - h) + 8 * fun(t + h) - fun(t + 2 * h)) / (12 * h)


PROFILES = {
    "static": lambda: M.Static(LAT, LON, HEIGHT, 1 * D, -2 * D, 200 * D),
    "bad_sea": lambda: M.sea_state("bad", LAT, LON, HEIGHT, 40 * D, phase=(0.3, 1.1, -0.7)),
    "heading_swing": lambda: M.HeadingSwing.experiment(2),
}


@pytest.mark.parametrize("name", sorted(PROFILES))
def test_euler_rate_is_derivative_of_euler(name):
    # 4th-order difference with h = 1 ms: truncation ~h^4 * 7 rad/s^5 / 30 ~ 2e-13
    # rad/s, rounding ~1e-16 / 1e-3 = 1e-13 rad/s; a wrong amplitude factor
    # 2 pi f would be off by ~0.1 rad/s, so 1e-10 rad/s is a safe bound.
    mo = PROFILES[name]()
    t = np.linspace(1.0, 200.0, 3001)
    fd = central_diff(lambda s: mo.state(s).euler, t, 1e-3)
    assert np.max(np.abs(fd - mo.state(t).euler_rate)) < 1e-10


def test_manoeuvre_derivatives(manoeuvre):
    # Same difference; speeds ~10 m/s, so velocity rounding ~1e-15 / 1e-3 and
    # jerk-derived truncation are < 1e-11; a missing centripetal term
    # (speed * yaw rate ~ 0.5 m/s^2) or a wrong pulse normalisation is >1e-3.
    t = np.linspace(0.01, manoeuvre.duration - 0.01, 40001)
    st = manoeuvre.state(t)
    acc_fd = central_diff(lambda s: manoeuvre.state(s).vel_n, t, 1e-3)
    assert np.max(np.abs(acc_fd - st.acc_n)) < 1e-9
    rate_fd = central_diff(lambda s: manoeuvre.state(s).euler, t, 1e-3)
    assert np.max(np.abs(rate_fd - st.euler_rate)) < 1e-10
    # velocity is along the bow: vel_n = speed [-sin yaw, cos yaw, 0]
    yaw = st.euler[:, 2]
    speed = np.hypot(st.vel_n[:, 0], st.vel_n[:, 1])
    np.testing.assert_allclose(st.vel_n[:, 0], -speed * np.sin(yaw), atol=1e-13)
    np.testing.assert_allclose(st.vel_n[:, 1], speed * np.cos(yaw), atol=1e-13)
    assert np.all(st.vel_n[:, 2] == 0.0)


def test_sea_state_mapping():
    # Seed 000 Table 2 'bad': inner 16 deg 0.2 Hz, middle 10/0.3, outer 10/0.3;
    # outer -> yaw, middle -> pitch, inner -> roll.
    sw = M.sea_state("bad", LAT, LON, HEIGHT, 0.5)
    np.testing.assert_array_equal(sw.amplitude, np.array([10.0, 16.0, 10.0]) * D)
    np.testing.assert_array_equal(sw.frequency_hz, [0.3, 0.2, 0.3])
    gen = M.Swing.sea_state("general", LAT, LON, HEIGHT, 0.0)
    np.testing.assert_array_equal(gen.amplitude, np.array([4.0, 10.0, 4.0]) * D)
    np.testing.assert_array_equal(gen.frequency_hz, [0.2, 0.125, 0.2])
    ideal = M.sea_state("ideal", LAT, LON, HEIGHT, 0.0)
    np.testing.assert_array_equal(ideal.amplitude, np.array([2.5, 3.0, 2.0]) * D)
    np.testing.assert_array_equal(ideal.frequency_hz, [0.08, 0.06, 0.08])
    # quarter period of the roll swing: roll at its peak, mean yaw 0.5
    st = sw.state(np.array([1.25]))
    assert abs(st.euler[0, 1] - 16.0 * D) < 1e-15
    assert np.all(st.vel_n == 0.0) and np.all(st.lat == LAT)
    with pytest.raises(ValueError, match="unknown sea state"):
        M.sea_state("stormy", LAT, LON, HEIGHT, 0.0)


def test_heading_swing_profile():
    # seed 002: omega(t) = A cos(2 pi t / T), yaw = yaw0 + A T / (2 pi) sin(2 pi t / T)
    for number, period in ((1, 120.0), (2, 60.0)):
        hs = M.HeadingSwing.experiment(number)
        a = 6.0 * D
        t = np.linspace(0.0, 3 * period, 1001)
        st = hs.state(t)
        # 1e-15 rad/s: rounding of the reference's own phase 2 pi t / T
        # (~1e-16 * 2 pi * 3) times A; a wrong period or sign is off by ~0.1 rad/s.
        np.testing.assert_allclose(st.euler_rate[:, 2], a * np.cos(2 * np.pi * t / period),
                                   rtol=0, atol=1e-15)
        np.testing.assert_allclose(st.euler[:, 2],
                                   -15 * D + a * period / (2 * np.pi) * np.sin(2 * np.pi * t / period),
                                   rtol=0, atol=1e-14)
        assert np.all(st.euler[:, 0] == 1.0 * D) and np.all(st.euler[:, 1] == -2.0 * D)
        assert np.all(st.euler_rate[:, :2] == 0.0)
        assert st.lat[0] == 34.246 * D and st.lon[0] == 108.910 * D and st.height[0] == 380.0
    # experiment 1 swings the heading by A T / (2 pi) = 114.6 deg
    hs = M.HeadingSwing.experiment(1)
    assert abs(hs.amplitude[2] - 360.0 / np.pi * D) < 1e-15


def test_long_run_phase_is_exact():
    # Times given as (t, t_lo) pairs keep the phase exact: the state at
    # t = 86400 s + x passed as (86400, x) equals the state at the same time
    # computed from a profile whose phase is advanced by f * 86400 cycles.
    sw = M.sea_state("bad", LAT, LON, HEIGHT, 0.0)
    x = np.linspace(0.0, 0.01, 7)
    late = sw.state(np.full(7, 86400.0), x)
    # exact fractional cycles f * 86400 mod 1 of the float64 frequencies
    shift = [float((Fraction(f) * 86400) % 1) for f in sw.frequency_hz]
    ref = M.Swing(LAT, LON, HEIGHT, 0, 0, 0, sw.amplitude, sw.frequency_hz,
                  2 * np.pi * np.array(shift))
    # Both sides are exact to a few ulp of the phase (~1e-15 rad); rounding
    # the time 86400 + x to one float64 instead would be off by ~1e-12 rad.
    np.testing.assert_allclose(late.euler, ref.state(x).euler, rtol=0, atol=1e-15)


def test_manoeuvre_segments_speed_and_yaw(manoeuvre):
    dt = manoeuvre.dt
    assert manoeuvre.n_ticks == 180000 and manoeuvre.duration == 1800.0
    ends = np.cumsum([s.ticks for s in manoeuvre.segments])
    # speed and yaw at the end of each segment, as designed
    speed, accel, yaw, rate = manoeuvre.kinematics(ends * dt)
    np.testing.assert_allclose(speed, [10, 10, 10, 10, 10, 10, 0, 0], rtol=0, atol=1e-14)
    yaw_expected = 10 * D + np.array([0, 0, 90, 90, -45, -45, -45, -45]) * D
    np.testing.assert_allclose(yaw, yaw_expected, rtol=0, atol=1e-14)
    # accelerations and turn rates vanish at every segment boundary (smooth joins)
    _, accel0, _, rate0 = manoeuvre.kinematics(np.concatenate(([0.0], ends * dt)))
    assert np.max(np.abs(accel0)) < 1e-15 and np.max(np.abs(rate0)) < 1e-15
    # peak of the raised-cosine pulses: 2 * change / duration, at mid-segment
    _, a_mid, _, _ = manoeuvre.kinematics(np.array([60.0]))
    assert abs(a_mid[0] - 2 * 10.0 / 120.0) < 1e-15
    _, _, _, r_mid = manoeuvre.kinematics(np.array([420.0 + 30.0]))
    assert abs(r_mid[0] - 2 * 90 * D / 60.0) < 1e-15
    # speed non-decreasing while accelerating, constant while cruising
    t = np.arange(0, 12001) * dt
    assert np.all(np.diff(manoeuvre.kinematics(t)[0]) >= 0)
    t = np.linspace(120.0, 420.0, 1001)
    sp, ac, yw, rt = manoeuvre.kinematics(t)
    assert np.all(sp == 10.0) and np.all(ac == 0.0) and np.all(rt == 0.0)


def test_manoeuvre_positions_against_ode_solver(manoeuvre):
    # Independent integration of lat_dot = vN/(R_M+h), lon_dot = vE/((R_N+h) cos lat)
    # with DOP853 (rtol 1e-13) on the offsets from the start, segment by
    # segment, at tick boundaries and inside ticks. DOP853 reaches ~2e-16 rad
    # here; 1e-14 rad is 0.06 mm. Using R_N for R_M would be off by ~1e-6 rad,
    # a one-tick time shift by ~1.6e-8 rad.
    lat0, lon0, h = manoeuvre.lat0, manoeuvre.lon0, manoeuvre.height

    def rhs(t, y):
        speed, _, yaw, _ = manoeuvre.kinematics(np.asarray(t))
        lat = lat0 + y[0]
        rm, rn = earth.principal_radii(np.sin(lat))
        return [speed * np.cos(yaw) / (rm + h), -speed * np.sin(yaw) / ((rn + h) * np.cos(lat))]

    y = [0.0, 0.0]
    worst = 0.0
    for start, seg in zip(manoeuvre._seg_t0, manoeuvre.segments):
        end = start + seg.ticks * manoeuvre.dt
        t_eval = np.concatenate((np.linspace(start, end, 7)[1:-1] + 0.0043, [end]))
        sol = solve_ivp(rhs, (start, end), y, method="DOP853", rtol=1e-13, atol=1e-22,
                        t_eval=t_eval)
        st = manoeuvre.state(t_eval)
        worst = max(worst, np.max(np.abs(st.lat - lat0 - sol.y[0])),
                    np.max(np.abs(st.lon - lon0 - sol.y[1])))
        y = sol.y[:, -1]
    assert worst < 1e-14
    lat, lon = manoeuvre.boundary_positions()
    # sanity: the ship really moved (some kilometres)
    assert abs(lat[-1] - lat0) * earth.A > 1000.0


def test_manoeuvre_positions_finite_differences(manoeuvre):
    # Central differences of the tick-boundary positions against the velocity:
    # position rounding 1.1e-16 rad / (2 dt) ~ 3.5e-8 m/s and truncation
    # dt^2/6 * jerk ~ 1e-7 m/s, so 1e-6 m/s; a wrong radius gives ~0.03 m/s.
    lat, lon = manoeuvre.boundary_positions()
    dt = manoeuvre.dt
    k = np.arange(1, manoeuvre.n_ticks)
    st = manoeuvre.state(k * dt)
    rm, rn = earth.principal_radii(np.sin(st.lat))
    vn_fd = (lat[k + 1] - lat[k - 1]) / (2 * dt) * (rm + st.height)
    ve_fd = (lon[k + 1] - lon[k - 1]) / (2 * dt) * (rn + st.height) * np.cos(st.lat)
    assert np.max(np.abs(vn_fd - st.vel_n[:, 1])) < 1e-6
    assert np.max(np.abs(ve_fd - st.vel_n[:, 0])) < 1e-6
    # the fixed point converged in a few iterations per block
    assert max(manoeuvre.iterations) < 10
    # state() on the boundaries returns the stored boundary positions
    st = manoeuvre.state(np.arange(0, manoeuvre.n_ticks + 1, 997) * dt)
    np.testing.assert_array_equal(st.lat, lat[::997])


def test_manoeuvre_rejects_bad_input():
    with pytest.raises(ValueError, match="positive integer"):
        M.Manoeuvre(LAT, LON, 0, 0, [("cruise", 10.5)])
    with pytest.raises(ValueError, match="accelerate"):
        M.Manoeuvre(LAT, LON, 0, 0, [("accelerate", 100, 5.0), ("accelerate", 100, 3.0)])
    with pytest.raises(ValueError, match="unknown kind"):
        M.Manoeuvre(LAT, LON, 0, 0, [("drift", 100)])
    mo = M.Manoeuvre(LAT, LON, 0, 0, [("accelerate", 100, 5.0)])
    with pytest.raises(ValueError, match="defined on"):
        mo.state(np.array([1.5]))


def test_table_profiles():
    t = np.array([0.0, 1.0, 100.0])
    alpha, rate = T.Fixed(0.3).state(t)
    assert np.all(alpha == 0.3) and np.all(rate == 0.0)
    tab = T.ConstantRate(6 * D, 0.1)
    alpha, rate = tab.state(t)
    assert np.all(rate == 6 * D)
    # angles equal alpha0 + rate t modulo whole turns
    d = np.mod(alpha - (0.1 + 6 * D * t) + np.pi, 2 * np.pi) - np.pi
    assert np.max(np.abs(d)) < 1e-13
