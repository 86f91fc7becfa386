#!/usr/bin/env python3
"""The navigation filter's own heading variance split by source: how much
of its sigma it owes to its noise (gyro ARW, accelerometer VRW, GNSS) and
to the priors of the level gyros' misalignments, on the acceptance voyage
of the at-sea issue (`tools/nav_error_budget.py`'s settings).

    .venv/bin/python tools/nav_covariance_split.py [--hours 72] [--eps 0.01] [--workers 2]

At the optimal gain the Kalman filter's covariance does not change with
the gain to first order (the Joseph form's derivative in K vanishes at
K = P H^T S^-1), so scaling one source's variance by (1 + eps) changes
P(t) by eps times that source's part of P(t). Four runs: the filter as
configured, then with nav_level_mis_sigma^2, with the ARW^2, VRW^2 and
the fixes' variances together, and with the ARW^2 alone scaled by
(1 + eps). The unit is error-free and the fixes exact (P does not depend
on the measured values). Printed: each part as a share of the heading
variance, time average after 10 min and at a few times; its complement
is every other prior's part. Set beside `tools/nav_error_budget.py`'s
shares of the expected NEES (each source's error squared over the same
variance), a source whose share there is larger than its part here is
one the filter counts short.
"""
import argparse
import concurrent.futures
import time

import numpy as np

import nav_error_budget as nb
import nees_gnss
from pyins import sim
from pyins.units import DT

PARTS = ("base", "level_mis", "noise", "arw")


def _run(job):
    hours, eps, part = job
    motion = sim.default_voyage(hours, seed=1)
    n = int(round(hours * 3600.0 / DT))
    cfg = nees_gnss.filter_config(motion, "seed002", nb.TABLE, 0.0, nb.LEVEL)
    refs, avail = nb._gnss(motion, n, False)
    s = np.sqrt(1.0 + eps)
    if part == "level_mis":
        cfg["nav_level_mis_sigma"] *= s
    elif part == "noise":
        cfg["fine_gyro_arw"] *= s
        cfg["fine_accel_vrw"] *= s
        refs["sigma"] *= s
    elif part == "arw":
        cfg["fine_gyro_arw"] *= s
    t, _, sig, _, _ = nees_gnss.fly(motion, n, sim.SensorErrors(), 0, cfg, refs, avail, True)
    return t, sig


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hours", type=float, default=72.0)
    ap.add_argument("--eps", type=float, default=0.01, help="relative change of each source's variance")
    ap.add_argument("--workers", type=int, default=2)
    args = ap.parse_args()
    if not args.hours * 3600.0 > 600.0:
        ap.error(f"--hours {args.hours:g}: more than 10 min")
    if not 1e-4 <= args.eps <= 0.1:
        ap.error(f"--eps {args.eps:g}: 1e-4 .. 0.1 (small for the first order, large against rounding)")
    if args.workers < 1:
        ap.error("--workers: at least 1")
    t0 = time.perf_counter()
    with concurrent.futures.ProcessPoolExecutor(args.workers) as pool:
        out = dict(zip(PARTS, pool.map(_run, [(args.hours, args.eps, p) for p in PARTS])))
    t = out["base"][0]
    p0 = out["base"][1] ** 2
    late = t > 600.0
    times = [ts for ts in (3600, 6 * 3600, 24 * 3600, 48 * 3600, 72 * 3600) if ts <= t[-1] + 1.0]
    print(f"the filter's heading variance, voyage {args.hours:g} h, seed 002's grade, two-position indexing "
          f"({time.perf_counter() - t0:.0f} s): part from")
    for part, label in (("noise", "the noise (ARW, VRW, GNSS)"), ("arw", "  of it the gyros' ARW"),
                        ("level_mis", "the priors of m_xy, m_yx")):
        share = (out[part][1] ** 2 - p0) / args.eps / p0
        at = ", ".join(f"{ts / 3600:g} h {share[min(int(np.searchsorted(t, ts)), len(t) - 1)]:.3f}"
                       for ts in times)
        print(f"  {label:28s} time average {share[late].mean():.3f}" + (f"; {at}" if at else ""))


if __name__ == "__main__":
    main()
