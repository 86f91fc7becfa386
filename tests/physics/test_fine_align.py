"""Kalman fine alignment (seed 001) through the C++ firmware.

Seed 001's scenario: static, pitch -5 deg, roll 2 deg, yaw 235 deg (the
paper's psi, counter-clockwise from North as in its authors' texts), initial
attitude error [10', 10', 60'], drifts 0.01 deg/h, biases 100 ug, gyro noise
0.001 deg/sqrt(h), accelerometer noise 10 ug/sqrt(Hz), 1200 s. The paper
gives no latitude: we use 34.246 N (Xi'an, where its authors work; also seed
002's site).
"""
import numpy as np
import pytest

from pyins import analysis, metrics, open_loop, sim
from pyins.reference import attitude, earth
from pyins import units

DEG = units.DEG_TO_RAD
ARCMIN = units.ARCMIN_TO_RAD
DPH = units.DPH_TO_RPS
LAT = 34.246 * DEG
EULER = np.array([-5.0, 2.0, 235.0]) * DEG
N = 120_000                                  # 1200 s at 100 Hz


def run_seed001(states, seed, errors=None, phi0=np.array([10.0, 10.0, 60.0]) * ARCMIN, **cfg):
    m = sim.Static(LAT, 108.91 * DEG, 0.0, *EULER)
    guess = attitude.mat_to_euler(attitude.rotvec_to_mat(-phi0) @ attitude.euler_to_mat(EULER))
    errors = errors if errors is not None else sim.preset("seed001")
    res = open_loop.navigate(m, N, every=1000, sensors=sim.SensorModel(errors, seed=seed),
                          config=dict(euler_b_rad=guess, fine_ticks=N, fine_states=states, **cfg))
    return res, metrics.nav_errors(res), analysis.alignment_limits(LAT, EULER, errors.gyro_bias,
                                                                  errors.accel_bias)


def eps_n_estimate(out, states):
    return out["kf_x"][[3, 4]] if states == 5 else out["kf_x"][[4, 5]]


def test_reduced_filter_gap_to_limit_within_paper():
    """Median over 10 noise seeds at 1200 s of |estimate error - limit|, with
    feedback (the firmware default): no larger than seed 001's Fig. 2 (phi_E
    0.07', phi_U 2', eps_N 0.002 deg/h). The paper's figure is an open-loop
    run, whose second-order terms feedback removes, so it is an upper bound
    here, not a reproduction: the open loop as the paper ran it is held to
    its own figures in tests/papers/test_seed001_open_loop.py."""
    gaps = []
    for seed in range(10):
        res, e, lim = run_seed001(5, seed)
        out = res.outputs[-1]
        eps_err = lim.eps_n[1] - eps_n_estimate(out, 5)[0]
        gaps.append([abs(e.att_n_rad[-1, 0] - lim.phi_n[0]) / ARCMIN,
                     abs(e.att_n_rad[-1, 2] - lim.phi_n[2]) / ARCMIN,
                     abs(eps_err - lim.eps_n_limit[1]) / DPH])
        assert out["fault_flags"] == 0 and out["mode"] == 3
    med = np.median(gaps, axis=0)
    print(f"\nreduced filter, median gaps: phi_E {med[0]:.4f}', phi_U {med[1]:.3f}', "
          f"eps_N {med[2]:.5f} deg/h")
    assert med[0] <= 0.07 and med[1] <= 2.0 and med[2] <= 0.002


def test_full_filter_behaves_as_the_paper_says():
    """The 8-state filter: eps_E and the accelerometer biases are not
    estimated (their sigmas stay > 90 % of the initial ones), nothing
    diverges, and its attitude is no better than the limit allows."""
    res, e, lim = run_seed001(8, 3)
    out = res.outputs[-1]
    sig0 = np.array([0.01 * DPH, 100e-6 * 9.80665, 100e-6 * 9.80665])
    assert np.all(out["kf_sigma"][[3, 6, 7]] > 0.9 * sig0)
    assert out["kf_sigma"][4] < 0.3 * 0.01 * DPH          # eps_N is estimated
    assert out["fault_flags"] == 0
    assert np.all(np.isfinite(res.outputs["kf_x"])) and np.all(np.isfinite(res.outputs["kf_sigma"]))
    gap = np.abs(e.att_n_rad[-1] - lim.phi_n) / ARCMIN
    print(f"\nfull filter gaps: phi {gap} arcmin")
    assert gap[0] < 0.1 and gap[1] < 0.1 and gap[2] < 2.0


@pytest.mark.parametrize("states", [5, 8])
def test_reported_sigma_is_consistent(states):
    """Over 30 seeds with truths drawn from the filter's own prior, each
    state's normalised squared error (e_i / sigma_i)^2 averages inside the
    95 % bounds of chi2(30)/30, [0.56, 1.57]: the reported sigmas can be
    trusted. (For the 5-state filter the errors are taken against the
    transformed truth of eq. 21.)"""
    rng = np.random.default_rng(2026)
    sig_att = np.array([10.0, 10.0, 60.0]) * ARCMIN
    sig_eps, sig_nab = 0.01 * DPH, 100e-6 * 9.80665
    g = earth.normal_gravity(np.sin(LAT), 0.0)
    w_n = earth.OMEGA_IE * np.cos(LAT)
    if states == 5:
        # prior of the transformed states, diagonal (eq. 21)
        s_att = np.sqrt(sig_att**2 + np.array([sig_nab / g, sig_nab / g,
                                               np.hypot(sig_eps / w_n, np.tan(LAT) * sig_nab / g)])**2)
        cfg = dict(fine_sigma0_att_rad=s_att, fine_sigma0_gyro=sig_eps)
    else:
        cfg = dict(fine_sigma0_att_rad=sig_att, fine_sigma0_gyro=sig_eps, fine_sigma0_accel=sig_nab)
    z2 = []
    for seed in range(30):
        phi0 = rng.normal(0.0, sig_att)
        errors = sim.preset("seed001")
        errors.gyro_bias = rng.normal(0.0, sig_eps, 3)
        errors.accel_bias = rng.normal(0.0, sig_nab, 3)
        res, e, lim = run_seed001(states, 100 + seed, errors=errors, phi0=phi0, **cfg)
        out = res.outputs[-1]
        phi_res = e.att_n_rad[-1]             # residual attitude error after feedback
        if states == 5:
            truth = analysis.reduced_truth(lim, phi_res)
            est = np.concatenate([np.zeros(3), out["kf_x"][3:5]])
            err = (truth - est)
            # the fed-back attitude: its error is phi_res itself, the estimate 0
            sig = out["kf_sigma"][:5]
        else:
            mat_nb = attitude.euler_to_mat(EULER)
            eps_n = mat_nb @ errors.gyro_bias
            nab_n = (mat_nb @ errors.accel_bias)[:2]
            truth = np.concatenate([phi_res, eps_n, nab_n])
            est = np.concatenate([np.zeros(3), out["kf_x"][3:8]])
            err = truth - est
            sig = out["kf_sigma"][:8]
        z2.append((err / sig) ** 2)
    mean = np.mean(z2, axis=0)
    print(f"\n{states}-state mean normalised squared errors: {np.round(mean, 2)}")
    assert np.all(mean > 0.56) and np.all(mean < 1.57)
