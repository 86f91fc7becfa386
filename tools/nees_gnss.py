#!/usr/bin/env python3
"""Is the integrated navigation filter consistent? Its normalised
estimation error squared (NEES) over many runs of a voyage with GNSS,
against the chi-square 95 % bounds (the at-sea issue's acceptance 2).

    .venv/bin/python tools/nees_gnss.py [--seeds 30] [--hours 2] [--errors model|seed002|seed002-draws[-modelled]]
                                        [--prior default|seed002] [--bias 0] [--indexing]
                                        [--table-scale 0] [--table-mis 0] [--level-scale 0]
                                        [--level-mis 0] [--bias-rw 0]
                                        [--workers 1]

Each run (seed s = 0 .. seeds - 1) navigates `pyins.sim.default_voyage`
(route seed 1; the general sea state; the IMU fixed unless --indexing, then
the firmware indexes it between two positions in the closed loop) from an
initial state whose errors are drawn from the filter's own prior: attitude
2', 2', 10' (E, N, U; the configured fine_sigma0_att), velocity 0.1 m/s and
position 10 m per horizontal axis (the filter's kNavSigma0Vel and Pos).
``--errors model`` (default): the sensor errors the filter models, drawn
from its prior: gyro biases 0.01 deg/h, accelerometer biases 100 ug, white
noise at the densities it assumes (0.001 deg/sqrt(h), 10 ug/sqrt(Hz)).
``--errors seed002``: seed 002's error set instead (scale factors and
installation errors the filter does not model), noise seeded per run:
every run has the same +1-sigma errors (the papers' set as PSINS's
imuerrset builds it), so the runs share one error and their mean NEES is
not chi-square(N) / N: a test of that one unit, not of consistency.
``--errors seed002-draws``: run s draws its random constants from seed
002's 1-sigma values (`pyins.sim.sensors.draw_random_constants("seed002", s)`: bias,
scale factor, installation terms, signs and sizes random), the test of
consistency over a production of units.
``--errors seed002-draws-modelled``: the same draws with the terms the
filter does not carry set to 0 (the accelerometers' scale factors and
misalignments, the z gyro's misalignments m_zx, m_zy): splits an
inconsistency into what the filter models wrongly and what it leaves out.
``--prior seed002``: the filter told seed 002's grade (fine_sigma0_gyro
0.003 deg/h, fine_sigma0_accel 30 ug: its bias magnitudes; fine_gyro_arw
0.0005 deg/sqrt(h), fine_accel_vrw 5 ug/sqrt(Hz): its noise) instead of
the defaults (0.01 deg/h, 100 ug, 0.001 deg/sqrt(h), 10 ug/sqrt(Hz)); with
``--errors model`` the biases and the noise are then drawn from that.
``--table-scale``, ``--table-mis``: the filter's nav_table_scale_sigma
[ppm] and nav_table_mis_sigma [arcsec] (the priors of its table-axis error
states: the heading and the tilt each table move exposes; seed 002's gyros:
10 ppm, 10 arcsec); ``--level-scale``, ``--level-mis``: its
nav_level_scale_sigma [ppm] and nav_level_mis_sigma [arcsec] (the level
gyros' scale factors and misalignments, through which the Earth's rate
gives a heading error indexing does not remove); ``--bias-rw`` its
nav_gyro_bias_rw [deg/h/sqrt(h)] (0: the biases random constants; the
acceptance run over 72 h tells it 0.0005, stabilising noise for the terms
the filter leaves out: docs/concepts.md, "The filter").
GNSS at 1 Hz: 3 m (5 m up) white, 0.05 m/s; ``--bias`` the receiver's
Gauss-Markov bias [m] (300 s), which the filter does not model (0: none).

NEES at each record (the record carries the filter's sigmas):
heading (phi_U / sigma_psi)^2, chi-square with 1 degree of freedom when
consistent; horizontal (dE^2 + dN^2) / (P_EE + P_NN), mean 1 when
consistent (chi-square 2 / 2 when P is isotropic). Their means over the
runs are tested against the two-sided 95 % bounds of chi-square(N) / N and
chi-square(2N) / (2N). Printed: the share of record times after the first
10 min inside the bounds (95 % expected), the time-averaged mean NEES and
its bounds, at a few times.
"""
import argparse
import concurrent.futures
import time
from dataclasses import replace

import numpy as np
from scipy.stats import chi2

from pyins import contract, fil, metrics, sim
from pyins.open_loop import navigate
from pyins.scenario.build import initial_errors
from pyins.sim import references
from pyins.sim.sensors import draw_random_constants
from pyins.units import ARCMIN_TO_RAD, DEG_TO_RAD, DT, G0

SIGMA0_ATT = np.array([2.0, 2.0, 10.0]) * ARCMIN_TO_RAD     # configured: the filter's prior
SIGMA0_VEL, SIGMA0_POS = 0.1, 10.0                            # the firmware's kNavSigma0Vel, kNavSigma0Pos
GYRO_BIAS, ACCEL_BIAS = 0.01 * DEG_TO_RAD / 3600.0, 100e-6 * G0       # fine_sigma0_gyro, fine_sigma0_accel
GYRO_ARW, ACCEL_VRW = 0.001 * DEG_TO_RAD / 60.0, 10e-6 * G0           # fine_gyro_arw, fine_accel_vrw


PRIORS = {"default": (GYRO_BIAS, ACCEL_BIAS, GYRO_ARW, ACCEL_VRW),
          "seed002": (0.003 * DEG_TO_RAD / 3600.0, 30e-6 * G0, 0.0005 * DEG_TO_RAD / 60.0, 5e-6 * G0)}


def modelled_only(sens):
    """``sens`` with the terms the filter's 19 states do not carry set to 0:
    the accelerometers' scale factors and misalignments, the z gyro's
    misalignments m_zx, m_zy (gyro_misalignment's last row)."""
    g_mis = sens.gyro_misalignment.copy()
    g_mis[2, :] = 0.0
    return replace(sens, gyro_misalignment=g_mis, accel_scale=np.zeros(3), accel_misalignment=np.zeros((3, 3)))


def filter_config(motion, prior="default", table=(0.0, 0.0), bias_rw=0.0, level=(0.0, 0.0), phi=None, dv=None,
                  dp=None):
    """The firmware's configuration of one run: the initial state with the
    errors ``phi`` [rad, E N U], ``dv`` [m/s, E N], ``dp`` [m, E N] (None:
    0), the filter told ``prior``'s grade and the error-state priors
    (``table``, ``level``: (scale [ppm], misalignment [arcsec]))."""
    gyro_prior, accel_prior, arw, vrw = PRIORS[prior]
    phi = np.zeros(3) if phi is None else phi
    dv = np.zeros(2) if dv is None else dv
    dp = np.zeros(2) if dp is None else dp
    cfg = dict(initial_errors(motion, phi=phi, velocity=[dv[0], dv[1], 0.0], north=dp[1], east=dp[0]),
               fine_sigma0_att_rad=SIGMA0_ATT)
    if prior != "default":
        cfg.update(fine_sigma0_gyro=gyro_prior, fine_sigma0_accel=accel_prior, fine_gyro_arw=arw,
                   fine_accel_vrw=vrw)
    cfg.update(nav_table_scale_sigma=table[0] * 1e-6, nav_table_mis_sigma=table[1] * ARCMIN_TO_RAD / 60.0,
               nav_level_scale_sigma=level[0] * 1e-6, nav_level_mis_sigma=level[1] * ARCMIN_TO_RAD / 60.0)
    cfg.update(nav_gyro_bias_rw=bias_rw * DEG_TO_RAD / 3600.0 / 60.0)
    return cfg


def fly(motion, n, sens, seed, cfg, refs, avail_tick, indexing):
    """Navigate ``n`` ticks of ``motion`` with the sensor errors ``sens``
    (noise from ``seed``) and the GNSS ``refs``: returns (time [s], heading
    error [rad], the filter's heading sigma [rad], horizontal error [m],
    the filter's horizontal sigma [m]) at every record (1 s)."""
    if indexing:
        res = fil.run_fil(motion, n, config=dict(cfg, index_scheme=2), errors=sens, seed=seed, every=100,
                          refs=refs, avail_tick=avail_tick)
    else:
        res = navigate(motion, n, every=100, sensors=sim.SensorModel(sens, seed=seed), config=cfg, refs=refs,
                       avail_tick=avail_tick)
    e = metrics.nav_errors(res)
    o = res.outputs
    return (e.time_s, e.att_n_rad[:, 2], o["nav_sigma_heading_rad"], np.hypot(e.east_m, e.north_m),
            o["nav_sigma_pos_m"])


def one_run(motion, n, seed, errors, bias, indexing, prior="default", table=(0.0, 0.0), bias_rw=0.0,
            level=(0.0, 0.0)):
    gyro_prior, accel_prior, arw, vrw = PRIORS[prior]
    rng = np.random.default_rng(1000 + seed)
    if errors == "model":
        z3 = np.zeros(3)
        sens = sim.SensorErrors(gyro_bias=rng.normal(0.0, gyro_prior, 3), gyro_scale=z3,
                                gyro_misalignment=np.zeros((3, 3)), gyro_arw=arw, gyro_quantum=0.0,
                                accel_bias=rng.normal(0.0, accel_prior, 3), accel_scale=z3,
                                accel_misalignment=np.zeros((3, 3)), accel_vrw=vrw, accel_quantum=0.0)
    elif errors == "seed002":
        sens = sim.preset("seed002")
    else:  # seed002-draws: run s's own production unit
        sens = draw_random_constants("seed002", seed)
        if errors == "seed002-draws-modelled":
            sens = modelled_only(sens)
    phi = rng.normal(0.0, 1.0, 3) * SIGMA0_ATT
    dv = rng.normal(0.0, SIGMA0_VEL, 2)
    dp = rng.normal(0.0, SIGMA0_POS, 2)
    cfg = filter_config(motion, prior, table, bias_rw, level, phi, dv, dp)
    g = references.gnss(motion, n * DT, seed=2000 + seed, bias_sigma_m=bias)
    t, head_err, head_sig, hor_err, hor_sig = fly(motion, n, sens, seed, cfg, g.refs.astype(contract.REF_DTYPE),
                                                  g.avail_tick, indexing)
    # the horizontal sigma's square is P_EE + P_NN (the record's nav_sigma_pos_m)
    return t, (head_err / head_sig) ** 2, hor_err ** 2 / hor_sig ** 2, head_err, hor_err


_MOTIONS = {}


def _run_seed(a):
    """One seed, in this process or a worker; the voyage built once per
    process (deterministic: route seed 1), not sent to the workers."""
    hours, n, s, (errors, bias, indexing, prior, table, bias_rw, level) = a
    if hours not in _MOTIONS:
        _MOTIONS[hours] = sim.default_voyage(hours, seed=1)
    return one_run(_MOTIONS[hours], n, s, errors, bias, indexing, prior, table, bias_rw, level)


class _Inline:
    """One process: map in order, as the pool does."""

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False

    @staticmethod
    def map(fn, items):
        return map(fn, items)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=30)
    ap.add_argument("--hours", type=float, default=2.0)
    ap.add_argument("--errors", choices=("model", "seed002", "seed002-draws", "seed002-draws-modelled"),
                    default="model")
    ap.add_argument("--prior", choices=tuple(PRIORS), default="default",
                    help="the bias sigmas the filter is told (seed002: its grade)")
    ap.add_argument("--bias", type=float, default=0.0, help="GNSS Gauss-Markov bias sigma [m]")
    ap.add_argument("--indexing", action="store_true", help="two-position indexing (closed loop)")
    ap.add_argument("--table-scale", type=float, default=0.0,
                    help="the filter's nav_table_scale_sigma [ppm] (seed 002's gyros: 10)")
    ap.add_argument("--table-mis", type=float, default=0.0,
                    help="the filter's nav_table_mis_sigma [arcsec] (seed 002's gyros: 10)")
    ap.add_argument("--level-scale", type=float, default=0.0,
                    help="the filter's nav_level_scale_sigma [ppm] (seed 002's gyros: 10)")
    ap.add_argument("--level-mis", type=float, default=0.0,
                    help="the filter's nav_level_mis_sigma [arcsec] (seed 002's gyros: 10)")
    ap.add_argument("--bias-rw", type=float, default=0.0,
                    help="the filter's gyro bias random walk, nav_gyro_bias_rw [deg/h/sqrt(h)]")
    ap.add_argument("--workers", type=int, default=1, help="runs at once (processes); the figures do not "
                                                           "depend on it")
    args = ap.parse_args()
    if args.workers < 1:
        ap.error("--workers: at least 1")
    if not args.hours * 3600.0 > 600.0:
        ap.error(f"--hours {args.hours:g}: more than 10 min (the NEES is averaged after the first 10 min)")
    n = int(round(args.hours * 3600.0 / DT))
    t0 = time.perf_counter()
    heads, hors, errs, herrs = [], [], [], []
    job = (args.errors, args.bias, args.indexing, args.prior, (args.table_scale, args.table_mis), args.bias_rw,
           (args.level_scale, args.level_mis))
    with concurrent.futures.ProcessPoolExecutor(args.workers) if args.workers > 1 else _Inline() as pool:
        runs = pool.map(_run_seed, [(args.hours, n, s, job) for s in range(args.seeds)])
        for s, (t, h, p, err, herr) in enumerate(runs):
            heads.append(h)
            hors.append(p)
            errs.append(err)
            herrs.append(herr)
            print(f"  run {s + 1}/{args.seeds}: mean NEES heading {h[t >= 600].mean():.2f}, horizontal "
                  f"{p[t >= 600].mean():.2f} ({time.perf_counter() - t0:.0f} s)", flush=True)
    head, hor = np.mean(heads, axis=0), np.mean(hors, axis=0)
    N = args.seeds
    b1 = (chi2.ppf(0.025, N) / N, chi2.ppf(0.975, N) / N)
    b2 = (chi2.ppf(0.025, 2 * N) / (2 * N), chi2.ppf(0.975, 2 * N) / (2 * N))
    late = t >= 600.0
    print(f"\nvoyage {args.hours:g} h, {N} runs, errors {args.errors}, prior {args.prior}, "
          f"GNSS bias {args.bias:g} m, "
          f"{'two-position indexing' if args.indexing else 'IMU fixed'}, nav_table_scale_sigma "
          f"{args.table_scale:g} ppm, nav_table_mis_sigma {args.table_mis:g} arcsec, nav_level_scale_sigma "
          f"{args.level_scale:g} ppm, nav_level_mis_sigma {args.level_mis:g} arcsec, bias random walk "
          f"{args.bias_rw:g} deg/h/sqrt(h)")
    after = t >= 3600.0
    if np.any(after):
        rms = np.sqrt(np.mean(np.square(np.array(errs)[:, after]))) / ARCMIN_TO_RAD
        print(f"heading error RMS over the runs after the first hour: {rms:.3f}'")
        hrms = np.sqrt(np.mean(np.square(np.array(herrs)[:, after])))
        print(f"horizontal position error RMS over the runs after the first hour: {hrms:.2f} m")
    for name, v, (lo, hi) in (("heading", head, b1), ("horizontal", hor, b2)):
        inside = np.mean((v[late] >= lo) & (v[late] <= hi))
        print(f"{name:10s} mean NEES over the runs: time average {v[late].mean():.3f} (bounds {lo:.3f} .. "
              f"{hi:.3f}); inside at {100 * inside:.1f} % of the record times after 10 min")
        for ts in sorted({600, 1800, 3600, *range(6 * 3600, int(args.hours * 3600), 6 * 3600),
                          int(args.hours * 3600) - 1}):
            k = int(np.searchsorted(t, ts))
            if k < len(t):
                print(f"           at {t[k]:6.0f} s: {v[k]:.3f}")


if __name__ == "__main__":
    main()
