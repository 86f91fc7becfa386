"""pyins.sim.exact_time: the error-free products and sums, exact tick times,
phases; and the two table-angle wraps (plant mirror vs vectorised truth)."""
from fractions import Fraction

import numpy as np
import pytest

from pyins.sim import exact_time as X
from pyins.sim import imu, turntable
from pyins.units import DT, TWO_PI


def test_two_prod_and_two_sum_are_exact():
    rng = np.random.default_rng(0)
    a = rng.uniform(-1e6, 1e6, 200)
    b = rng.uniform(-1e3, 1e3, 200)
    p, e = X.two_prod(a, b)
    s, f = X.two_sum(a, b)
    for i in range(len(a)):
        assert Fraction(p[i]) + Fraction(e[i]) == Fraction(a[i]) * Fraction(b[i])
        assert Fraction(s[i]) + Fraction(f[i]) == Fraction(a[i]) + Fraction(b[i])


def test_split_times_is_the_exact_time():
    ticks = np.array([0, 1, 8_640_000, 25_920_000, 2**40])
    t_hi, t_lo = X.split_times(ticks, DT, t0=0.5, frac=0.25)
    for k, hi, lo in zip(ticks, t_hi, t_lo):
        exact = Fraction(0.5) + (Fraction(int(k)) + Fraction(0.25)) * Fraction(DT)
        assert abs(Fraction(hi) + Fraction(lo) - exact) < Fraction(1, 10**25)


def test_frac_cycles_keeps_the_phase_72_hours_in():
    t_hi, t_lo = X.split_times(np.array([25_920_000]), DT, frac=0.5)
    f = 0.3
    c = X.frac_cycles(f, t_hi, t_lo)[0]
    exact = Fraction(f) * (Fraction(t_hi[0]) + Fraction(t_lo[0]))
    exact -= round(exact)
    assert abs(c - float(exact)) < 1e-15
    assert -0.5 - 1e-12 <= c <= 0.5 + 1e-12


def test_as_times():
    t, lo = X.as_times(1.0, None)
    assert t.shape == (1,) and lo is None
    t, lo = X.as_times([1.0, 2.0], 0.0)
    assert lo.shape == (2,)
    with pytest.raises(ValueError, match="1-D"):
        X.as_times(np.zeros((2, 2)), None)


def test_the_two_wraps_agree_within_a_turn_and_part_beyond():
    # Within a turn either side of [0, 2 pi) the plant's a - 2 pi floor(a / 2 pi)
    # and np.mod give the same bits; many turns out they need not (why the
    # truth and the plant keep two functions).
    a = np.random.default_rng(1).uniform(-np.pi, 3 * np.pi, 5000)
    plant = np.array([turntable.wrap_two_pi(x) for x in a])
    np.testing.assert_array_equal(plant, imu.wrap_two_pi_mod(a))
    far = np.random.default_rng(2).uniform(-1e4, 1e4, 2000)
    plant = np.array([turntable.wrap_two_pi(x) for x in far])
    mod = imu.wrap_two_pi_mod(far)
    assert np.all((plant >= 0.0) & (plant < TWO_PI)) and np.all((mod >= 0.0) & (mod < TWO_PI))
    assert np.max(np.abs(plant - mod)) < 1e-11
