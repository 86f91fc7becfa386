"""`pyins.sim.NarrowbandYaw`, the random narrowband ship yaw that stands
beside seed 002's sinusoidal heading swing (tools/papers/seed002_random_yaw.py):
the RMS rate it is given, its rate and acceleration the derivatives of its
yaw, its spectrum peaked where it is told, its period, its draw, and exact
increments through the closed loop."""
import numpy as np
import pytest

from pyins import fil, metrics, scenario, sim
from pyins.sim.motion import periodic_ticks

DEG = np.pi / 180.0
#: seed 002 experiment 1's sinusoid: A = 6 deg/s at T = 120 s, its RMS rate A / sqrt 2
RMS, PERIOD = 6.0 * DEG / np.sqrt(2.0), 120.0


def _yaw(seed=3, **kw):
    return sim.NarrowbandYaw(0.6, 1.9, 380.0, 1.0 * DEG, -2.0 * DEG, -15.0 * DEG, RMS, PERIOD, seed=seed, **kw)


def test_rms_rate_period_and_draw():
    m = _yaw()
    # one repeat sampled at 0.25 s: the RMS of the rate is the one given (the components
    # lie on the repeat's harmonics, so the mean over a repeat is exact to rounding)
    t = np.arange(0.0, 2 * m.repeat_s, 0.25)
    st = m.state(t)
    assert np.sqrt(np.mean(st.euler_rate[:, 2] ** 2)) == pytest.approx(RMS, rel=1e-9)
    half = len(t) // 2
    np.testing.assert_allclose(st.euler[half:], st.euler[:half], atol=1e-9)   # it repeats
    assert periodic_ticks(m, 0.01) == m.repeat_s * 100
    # pitch and roll held, the mean yaw the one given
    assert np.all(st.euler[:, 0] == 1.0 * DEG) and np.all(st.euler[:, 1] == -2.0 * DEG)
    assert np.mean(st.euler[:half, 2]) == pytest.approx(-15.0 * DEG, abs=1e-9)
    # the same seed, the same yaw; another seed another
    np.testing.assert_array_equal(_yaw().state(t[:100]).euler, st.euler[:100])
    assert not np.allclose(_yaw(seed=4).state(t[:100]).euler, st.euler[:100])


def test_rate_and_acceleration_are_the_yaws_derivatives():
    m = _yaw()
    t = np.array([0.0, 100.0, 777.7, 1800.0])
    h = 1e-3
    up, down = m.state(t + h), m.state(t - h)
    # central differences: error ~ h^2 yaw''' / 6, ~1e-8 rad/s here
    np.testing.assert_allclose((up.euler[:, 2] - down.euler[:, 2]) / (2 * h), m.state(t).euler_rate[:, 2], atol=1e-7)
    np.testing.assert_allclose((up.euler_rate[:, 2] - down.euler_rate[:, 2]) / (2 * h), m.euler_accel(t)[:, 2],
                               atol=1e-7)


def test_the_spectrum_peaks_at_the_period_given():
    m = _yaw()
    # Fossen's wave-response model: the yaw rate's largest components at w0 (within the
    # grid's 1 / repeat_s), the band [f0 / 3, 3 f0]
    f_peak = m.freq[np.argmax(m.amp * m.freq)]
    assert abs(f_peak - 1.0 / PERIOD) <= 1.0 / m.repeat_s
    assert m.freq.min() >= 1.0 / (3.0 * PERIOD) and m.freq.max() <= 3.0 / PERIOD


@pytest.mark.parametrize("kw", [dict(damping=0.0), dict(damping=1.0), dict(repeat_s=0)])
def test_bad_parameters_are_refused(kw):
    with pytest.raises(ValueError, match="NarrowbandYaw"):
        _yaw(**kw)


def test_an_error_free_closed_loop_under_random_yaw_navigates_exactly():
    # exact increments (the plant's quadrature of the analytic yaw), no sensor error, the
    # table indexed: after an hour the position within a millimetre and the heading
    # within a milli-arc-second (measured 0 m and 1e-7 arcsec)
    m = _yaw()
    res = fil.run_fil(m, 360_000, config=dict(scenario.initial_config(m), index_scheme=2))
    e = metrics.nav_errors(res)
    assert e.horizontal_m.max() < 1e-3
    assert np.abs(e.att_n_rad[:, 2]).max() < 1e-3 / 3600.0 * DEG
