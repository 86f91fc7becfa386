#!/usr/bin/env python3
"""Coarse alignment on a moored ship: heave, surge, sway and a lever arm.

    .venv/bin/python tools/moored_alignment.py [--out runs/moored] [--seeds 10]

For each of seed 000's sea states (ideal, general, bad) and each heading of
its static test (0..300 deg, step 60), with seed 000's sensor errors (gyro
drift 0.01 deg/h, accelerometer bias 100 ug on every axis; ARW 0.0005
deg/sqrt(h) and VRW 5 ug/sqrt(Hz) borrowed from seeds 002/003, the same
class of IMU) and N noise seeds, the coarse heading error against the truth
and against the theoretical limit at 200 s and 300 s, for:

- ``swing``: the pure swing of seed 000 (rotation about the IMU), as the
  paper simulates it;
- ``moored``: the same swing plus the moored-ship linear motion (heave
  0.5 m at 8 s, surge 0.3 m at 12 s, sway 0.3 m at 10 s) and a 2 m lever arm
  (0.5, 1.5, 1.2) m from the reference point to the IMU
  (`pyins.sim.moored`), the lever arm configured;
- ``moored_unknown_lever``: the same ship, the lever arm not configured;

each with the coarse methods TRIAD (seed 000) and FIT (moving base). The
alignment runs 300 s on a 2 s output grid (the fixed history holds 255
intervals). Median over the seeds of |error|, per case, and the maximum over
the headings of those medians, in arc-minutes. Writes moored.json and
moored.md into --out. Takes ~1-2 min on this machine.
"""
import argparse
import json
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reproduce_seed000 import LAT, LON, HEADINGS, limit_euler, sensors  # noqa: E402

from pyins import native, runner, sim  # noqa: E402
from pyins.reference import earth  # noqa: E402

DEG = earth.DEG_TO_RAD
ARCMIN = earth.ARCMIN_TO_RAD
ARCSEC = earth.ARCSEC_TO_RAD
SEA_STATES = ("ideal", "general", "bad")
METHODS = {"triad": 0, "fit": 1}
TIMES_S = (200, 300)
EVERY = 200          # coarse output grid [ticks]: 300 s in 150 intervals


def motions(state, heading):
    yaw = -heading * DEG
    swing = sim.sea_state(state, LAT, LON, 0.0, yaw0=yaw)
    return {"swing": sim.ShipAtSea(swing), "moored": sim.moored(state, LAT, LON, 0.0, yaw)}


def heading_error(yaw, yaw_true):
    """Marine heading error [rad] (heading = -yaw)."""
    return -(((yaw - yaw_true) + np.pi) % (2 * np.pi) - np.pi)


def run_case(m, exact, model, method, lever_known):
    dtheta, dv = model.apply(*exact)
    cfg = runner.initial_config(m, None, coarse_ticks=TIMES_S[-1] * 100, coarse_method=method,
                                coarse_output_every_ticks=EVERY, euler_b_rad=[0.0, 0.0, 0.0])
    if not lever_known:
        cfg["lever_b_m"] = np.zeros(3)
        cfg["lever_p_m"] = np.zeros(3)
    return native.Firmware(cfg).run(native.make_samples(dtheta, dv), every=1000)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="runs/moored")
    ap.add_argument("--seeds", type=int, default=10)
    args = ap.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    t0 = time.time()
    n = TIMES_S[-1] * 100
    rows = []   # (state, heading, variant, method, seed, err@200, err@300, lim@200, lim@300) [arcmin]
    for state in SEA_STATES:
        for h in HEADINGS:
            for name, m in motions(state, h).items():
                exact = sim.exact_increments(m, n)[:2]
                ticks = np.array([t * 100 for t in TIMES_S])
                truth = sim.truth_at(m, ticks)
                for s in range(args.seeds):
                    _, errs = sensors(seed=7 + 1000 * h + s)
                    lim = [limit_euler(m, errs, float(t))[2] * ARCSEC / ARCMIN for t in TIMES_S]
                    variants = [(name, True)] if name == "swing" else [(name, True), (name + "_unknown_lever", False)]
                    for variant, known in variants:
                        for mname, method in METHODS.items():
                            model, _ = sensors(seed=7 + 1000 * h + s)   # same noise draw per variant
                            rec = run_case(m, exact, model, method, known)
                            idx = [int(np.flatnonzero(rec["tick"] == t)[0]) for t in ticks]
                            err = [heading_error(rec["euler_b_rad"][i, 2], truth.euler[j, 2]) / ARCMIN
                                   for j, i in enumerate(idx)]
                            rows.append((state, h, variant, mname, s, *err, *lim))
        print(f"{state}: done ({time.time() - t0:.0f} s)", flush=True)
    summary = {}
    md = ["| sea state | case | method | median \\|heading err\\| 200 s (') | 300 s (') | "
          "vs limit 200 s (') | vs limit 300 s (') |", "|---|---|---|---|---|---|---|"]
    for state in SEA_STATES:
        for variant in ("swing", "moored", "moored_unknown_lever"):
            for mname in METHODS:
                sel = [r for r in rows if r[0] == state and r[2] == variant and r[3] == mname]
                a = np.array([r[5:] for r in sel], dtype=float)
                hs = np.array([r[1] for r in sel])
                med = {}
                for lab, col, lim_col in (("200", 0, 2), ("300", 1, 3)):
                    per_h = [np.median(np.abs(a[hs == h, col])) for h in HEADINGS]
                    per_h_lim = [np.median(np.abs(a[hs == h, col] - a[hs == h, lim_col])) for h in HEADINGS]
                    med[f"max_over_headings_median_abs_err_{lab}s_arcmin"] = float(np.max(per_h))
                    med[f"max_over_headings_median_abs_vs_limit_{lab}s_arcmin"] = float(np.max(per_h_lim))
                    med[f"per_heading_median_abs_err_{lab}s_arcmin"] = [float(v) for v in per_h]
                summary[f"{state}/{variant}/{mname}"] = med
                md.append(f"| {state} | {variant} | {mname} | "
                          f"{med['max_over_headings_median_abs_err_200s_arcmin']:.2f} | "
                          f"{med['max_over_headings_median_abs_err_300s_arcmin']:.2f} | "
                          f"{med['max_over_headings_median_abs_vs_limit_200s_arcmin']:.2f} | "
                          f"{med['max_over_headings_median_abs_vs_limit_300s_arcmin']:.2f} |")
    md.append("")
    md.append(f"Each figure: the largest, over the six headings, of the median over {args.seeds} "
              "noise seeds of |coarse heading error|, against the truth and against the "
              "theoretical limit (-eps_E / (W cos L) + tan L nabla_E / g).")
    out = {"seeds": args.seeds, "headings_deg": list(HEADINGS), "times_s": list(TIMES_S),
           "output_every_ticks": EVERY, "wall_s": time.time() - t0, "cases": summary}
    with open(os.path.join(args.out, "moored.json"), "w") as f:
        json.dump(out, f, indent=1)
    with open(os.path.join(args.out, "moored.md"), "w") as f:
        f.write("\n".join(md) + "\n")
    print("\n".join(md))
    print(f"wall {time.time() - t0:.0f} s; {args.out}/moored.json")
    return 0


if __name__ == "__main__":
    sys.exit(main())
