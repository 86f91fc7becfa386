#!/usr/bin/env python3
"""Compare the indexing schemes on the horizontal gyro drifts alone.

    .venv/bin/python tools/papers/compare_schemes.py [--hours 72] [--out runs/compare_schemes]

Firmware in the loop, 0.003 deg/h on the IMU's x and y gyros as the only
error (the error the schemes are designed against), on seed 002's two
heading swings and a static ship (heading 15 deg, seed 002's site and
attitude), with the firmware's 30 deg/s^2 turns and with the paper's
constant-rate turns (600 deg/s^2, on the swings). For each ship and scheme:
maximum and final horizontal error, the fraction of a constant x/y drift
that survives (the proxy of docs/papers.md, seed 002 §10) and the flexible
fallbacks. The schemes: none, traditional two-position, seed 002's flexible
scheme (literal), its derivation form, and both with index_sums = all (the
turns summed too; our extension, docs/indexing.md "What the turns leave").

Writes table.md and compare_schemes.json (figure names with units) in --out.
"""
import argparse
import json
import os
import sys

import numpy as np

from pyins import analysis, fil, metrics, progress, sim
from pyins.sim import motion
from pyins.sim.turntable import TableConfig
from pyins.units import DEG_TO_RAD as DEG
from pyins.units import DPH_TO_RPS, NMI_TO_M, TICK_HZ

#: (id, scheme, index_sums, label)
VARIANTS = (("none", 0, 0, "no rotation"), ("two", 2, 0, "traditional"),
            ("flex", 4, 0, "flexible, literal"), ("derived", 6, 0, "derivation form"),
            ("derived_all", 6, 1, "derivation form, turns summed"),
            ("flex_all", 4, 1, "literal, turns summed"))
#: (id, label, accel [deg/s^2])
SHIPS = (("exp1", "seed 002 exp. 1 (T = 120 s)", 30.0), ("exp1", "exp. 1, 600 deg/s^2", 600.0),
         ("exp2", "seed 002 exp. 2 (T = 60 s)", 30.0), ("exp2", "exp. 2, 600 deg/s^2", 600.0),
         ("static", "static ship, heading 15 deg", 30.0))
PLANT_ACCEL = 1000.0 * DEG        # a motor that can follow 600 deg/s^2


def ship(name):
    if name == "static":
        return sim.Static(motion.SEED002_LAT, motion.SEED002_LON, motion.SEED002_HEIGHT,
                          motion.SEED002_PITCH, motion.SEED002_ROLL, -15.0 * DEG)
    return sim.HeadingSwing.experiment(int(name[-1]))


def run_one(m, scheme, sums, accel_deg, hours, progress):
    drift = 0.003 * DPH_TO_RPS
    errors = sim.SensorErrors(gyro_bias=np.array([drift, drift, 0.0]))
    res = fil.run_fil(m, int(hours * (3600 * TICK_HZ)), errors=errors, every=TICK_HZ,
                      config=dict(index_scheme=scheme, index_sums=sums, index_accel_rad_s2=accel_deg * DEG),
                      table=TableConfig(accel_max_rad_s2=PLANT_ACCEL), progress=progress)
    e = metrics.nav_errors(res)
    return {"max_nmi": float(e.horizontal_m.max() / NMI_TO_M),
            "final_nmi": float(e.horizontal_m[-1] / NMI_TO_M),
            "survives": analysis.drift_surviving(res.outputs["yaw_p_rad"]),
            "fallbacks": int(res.outputs["index_fallbacks"][-1])}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hours", type=float, default=72.0)
    ap.add_argument("--out", default=os.path.join("runs", "compare_schemes"))
    ap.add_argument("--quiet", action="store_true", help="no progress bar")
    args = ap.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    progress = None if args.quiet else progress.TextProgress()
    out = {"hours": args.hours, "gyro_drift_deg_h": 0.003}
    head = "| ship | " + " | ".join(v[3] for v in VARIANTS) + " |"
    rows = [f"Max horizontal error [nmi] over {args.hours:g} h, horizontal gyro drifts only "
            "(surviving fraction; flexible fallbacks if any)", "", head,
            "|" + "---|" * (len(VARIANTS) + 1)]
    for name, label, accel in SHIPS:
        m = ship(name)
        cells = []
        for vid, scheme, sums, _ in VARIANTS:
            if scheme == 0 and accel != 30.0:
                cells.append("")       # no turns: the acceleration does not matter
                continue
            f = run_one(m, scheme, sums, accel, args.hours, progress)
            key = f"{name}_accel{accel:g}_{vid}"
            out[f"{key}_max_horizontal_nmi"] = f["max_nmi"]
            out[f"{key}_final_horizontal_nmi"] = f["final_nmi"]
            out[f"{key}_drift_surviving_fraction"] = f["survives"]
            out[f"{key}_fallbacks"] = f["fallbacks"]
            fb = f"; {f['fallbacks']} fb" if f["fallbacks"] else ""
            cells.append(f"{f['max_nmi']:.3f} ({f['survives']:.4f}{fb})")
        rows.append(f"| {label} | " + " | ".join(cells) + " |")
        print(rows[-1], flush=True)
    table = "\n".join(rows) + "\n"
    with open(os.path.join(args.out, "table.md"), "w") as fh:
        fh.write(table)
    with open(os.path.join(args.out, "compare_schemes.json"), "w") as fh:
        json.dump(out, fh, indent=2)
    print(table)
    print(f"written to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
