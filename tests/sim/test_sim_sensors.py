"""Sensor error model: bias, scale/misalignment, noise, quantisation, chunking, presets."""
import math

import numpy as np
import pytest

from pyins.sim import sensors as S
from pyins.units import DT
from pyins import units



def test_bias_only_mean_is_bias_dt():
    bias_g = np.array([1e-7, -2e-7, 3e-7])
    bias_a = np.array([1e-3, 2e-3, -5e-4])
    model = S.SensorModel(S.SensorErrors(gyro_bias=bias_g, accel_bias=bias_a), seed=1)
    zeros = np.zeros((1000, 3))
    th, dv = model.apply(zeros, zeros)
    # exactly bias * dt on every tick (0 + 0 + bias dt has no rounding)
    assert np.all(th == bias_g * DT) and np.all(dv == bias_a * DT)
    # on a moving input the error is bias * dt to the rounding of x + bias dt,
    # at most half an ulp of |x| < 4e-3 rad, i.e. 2e-19 rad (bias dt is 1e-9)
    rng = np.random.default_rng(0)
    x = rng.normal(0, 1e-3, (1000, 3))
    th, _ = model.apply(x, x)
    assert np.max(np.abs((th - x).mean(axis=0) - bias_g * DT)) < 2.5e-19


def test_scale_and_misalignment():
    scale = np.array([1e-4, -2e-4, 3e-4])
    mis = np.array([[0, 1e-4, -2e-4], [3e-4, 0, 4e-4], [-5e-4, 6e-4, 0]])
    model = S.SensorModel(S.SensorErrors(gyro_scale=scale, gyro_misalignment=mis,
                                         accel_scale=-scale, accel_misalignment=mis.T), seed=0)
    x = np.array([[1e-3, -2e-3, 5e-3], [0.1, 0.2, 0.3]])
    th, dv = model.apply(x, x)
    k_g = np.eye(3) + np.diag(scale) + mis
    k_a = np.eye(3) - np.diag(scale) + mis.T
    # relative 1e-15: rounding of the matrix product
    np.testing.assert_allclose(th, x @ k_g.T, rtol=1e-15, atol=0)
    np.testing.assert_allclose(dv, x @ k_a.T, rtol=1e-15, atol=0)
    with pytest.raises(ValueError, match="zero diagonal"):
        S.SensorErrors(gyro_misalignment=np.eye(3) * 1e-5)


def test_random_walk_std():
    # N = 200000 samples: the sample std of a Gaussian has relative standard
    # error 1/sqrt(2N) = 0.16 %; 5 sigma = 0.8 % (a sqrt(dt) vs dt mix-up is 10x).
    arw, vrw = 1e-5, 2e-4
    model = S.SensorModel(S.SensorErrors(gyro_arw=arw, accel_vrw=vrw), seed=42)
    n = 200000
    th, dv = model.apply(np.zeros((n, 3)), np.zeros((n, 3)))
    tol = 5.0 / math.sqrt(2 * n)
    np.testing.assert_allclose(th.std(axis=0) / (arw * math.sqrt(DT)), 1.0, atol=tol)
    np.testing.assert_allclose(dv.std(axis=0) / (vrw * math.sqrt(DT)), 1.0, atol=tol)
    # zero mean within 5 standard errors; gyro and accelerometer noise uncorrelated
    assert np.all(np.abs(th.mean(axis=0)) < 5 * arw * math.sqrt(DT) / math.sqrt(n))
    corr = np.corrcoef(th[:, 0], dv[:, 0])[0, 1]
    assert abs(corr) < 5 / math.sqrt(n)


@pytest.mark.parametrize("n", [1000, 70000])   # 70000 crosses the 2**16 reset
def test_quantisation_carries_residual(n):
    q = 1e-6
    rng = np.random.default_rng(5)
    x = rng.uniform(-3.3e-6, 7.7e-6, (n, 3))
    model = S.SensorModel(S.SensorErrors(gyro_quantum=q, accel_quantum=2 * q), seed=0)
    th, dv = model.apply(x, x)
    counts = th / q
    # every output is a whole number of pulses
    assert np.all(np.abs(counts - np.rint(counts)) < 1e-6)
    # the total count is the rounded exact sum of the inputs (no pulse lost)
    for axis in range(3):
        exact = math.fsum(x[:, axis])
        assert int(np.rint(counts[:, axis]).sum()) == math.floor(exact / q + 0.5)
    # the carried residual is what has not been output, at most half a pulse
    res_g, res_a = model.residuals
    assert np.all(np.abs(res_g) <= 0.5 * q * (1 + 1e-9))
    assert np.all(np.abs(res_a) <= q * (1 + 1e-9))
    # each output is within one pulse of its input (no pulses pile up)
    assert np.max(np.abs(th - x)) < 1.5 * q


def test_chunked_equals_one_shot_and_seeds():
    errors = S.preset("seed002")
    errors.gyro_quantum = 2.4e-6        # ~0.5 arcsec
    errors.accel_quantum = 1e-5
    rng = np.random.default_rng(9)
    n = 140000                           # crosses two quantiser resets
    th = rng.normal(0, 1e-3, (n, 3))
    dv = rng.normal(0, 1e-2, (n, 3)) + [0, 0, 0.098]
    one = S.SensorModel(errors, seed=123).apply(th, dv)
    model = S.SensorModel(errors, seed=123)
    cuts = [0, 1, 65535, 65537, 100000, n]
    parts = [model.apply(th[a:b], dv[a:b]) for a, b in zip(cuts[:-1], cuts[1:])]
    np.testing.assert_array_equal(one[0], np.concatenate([p[0] for p in parts]))
    np.testing.assert_array_equal(one[1], np.concatenate([p[1] for p in parts]))
    again = S.SensorModel(errors, seed=123).apply(th, dv)
    np.testing.assert_array_equal(one[0], again[0])
    other = S.SensorModel(errors, seed=124).apply(th, dv)
    assert not np.array_equal(one[0], other[0])


def test_presets_values():
    # Unit conversions against independently written literals (rtol 1e-15:
    # a couple of roundings); a deg/h vs deg/sqrt(h) mix-up is off by 60x.
    dph, ug, asec = units.DPH_TO_RPS, units.UG_TO_MPS2, units.ARCSEC_TO_RAD
    e0 = S.preset("error_free")
    assert np.all(e0.gyro_bias == 0) and e0.gyro_arw == 0 and e0.accel_vrw == 0
    e = S.preset("seed000")
    np.testing.assert_array_equal(e.gyro_bias, np.full(3, 0.01 * dph))
    np.testing.assert_array_equal(e.accel_bias, np.full(3, 100 * ug))
    assert e.gyro_arw == 0.0 and e.accel_vrw == 0.0
    e = S.preset("seed001")
    np.testing.assert_allclose(e.gyro_arw, 0.001 * np.pi / 180 / 60, rtol=1e-15)
    np.testing.assert_allclose(e.accel_vrw, 10e-6 * 9.80665, rtol=1e-15)
    e = S.preset("seed002")
    np.testing.assert_allclose(e.gyro_bias, 0.003 * np.pi / 180 / 3600, rtol=1e-15)
    np.testing.assert_allclose(e.accel_bias, 30e-6 * 9.80665, rtol=1e-15)
    np.testing.assert_allclose(e.gyro_arw, 0.0005 * np.pi / 180 / 60, rtol=1e-15)
    np.testing.assert_allclose(e.accel_vrw, 5e-6 * 9.80665, rtol=1e-15)
    np.testing.assert_allclose(e.gyro_scale, 10e-6, rtol=1e-15)
    assert np.count_nonzero(e.gyro_misalignment) == 6
    assert np.all(e.gyro_misalignment[~np.eye(3, dtype=bool)] == 10 * asec)
    assert np.count_nonzero(e.accel_misalignment) == 3
    assert np.all(np.tril(e.accel_misalignment, -1)[np.tril_indices(3, -1)] == 10 * asec)
    e = S.preset("seed003")
    m = np.array([[0, -2, 2], [2, 0, -2], [-2, 2, 0]]) * asec
    np.testing.assert_array_equal(e.gyro_misalignment, m)
    np.testing.assert_array_equal(e.accel_misalignment, m)
    np.testing.assert_allclose(e.gyro_scale, 0.466e-6, rtol=1e-15)
    np.testing.assert_allclose(e.accel_scale, 20e-6, rtol=1e-15)
    np.testing.assert_array_equal(e.accel_bias, np.full(3, 20 * ug))
    # sign patterns, and presets are copies (editing one leaves PRESETS alone)
    e = S.preset("seed002", gyro_bias_signs=(1, -1, 1), accel_bias_signs=(-1, -1, 1))
    np.testing.assert_array_equal(np.sign(e.gyro_bias), [1, -1, 1])
    np.testing.assert_array_equal(np.sign(e.accel_bias), [-1, -1, 1])
    e.gyro_misalignment[0, 1] = 1.0
    assert S.PRESETS["seed002"].gyro_misalignment[0, 1] == 10 * asec
    with pytest.raises(ValueError, match="unknown sensor preset"):
        S.preset("seed999")
