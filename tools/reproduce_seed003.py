#!/usr/bin/env python3
"""Reproduce seed 003 (single-position forward/reverse rotate-stop, 24 h).

    .venv/bin/python tools/reproduce_seed003.py [--out runs/seed003]

Static ship, 24 h, seed 003's sensor errors (SPEC 4.3: drift 0.003 deg/h,
ARW 0.0005 deg/sqrt(h), gyro SF 0.466 ppm, accelerometer bias 20 ug and
SF 20 ppm, the +-2" installation matrix on both triads), the firmware
started from the true state, the IMU either fixed (no rotation) or indexed
by the single-position scheme (stop 60 s at zero, +360 deg at 6 deg/s, stop,
-360 deg). The paper's drifts are random constants (one draw each); ours are
+0.003 deg/h on every axis. Its latitude is not given: 34.246 N is used.

Writes errors.png (position, level, heading, velocity errors over 24 h,
like its Figs. 4-9), table.md (maxima beside the paper's bounds) and
seed003.json.
"""
import argparse
import json
import os
import sys

import numpy as np

from pyins import fil, runner, sim
from pyins.reference import earth

DEG = earth.DEG_TO_RAD
ARCMIN = earth.ARCMIN_TO_RAD
PAPER = {"position_nmi": 1.1, "level_arcmin": 0.01, "heading_arcmin": 0.3, "velocity_mps": 0.06}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join("runs", "seed003"))
    ap.add_argument("--hours", type=float, default=24.0)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    m = sim.Static(34.246 * DEG, 108.91 * DEG, 0.0)
    errors = sim.preset("seed003")
    ticks = int(args.hours * 360_000)
    fig_json = {"hours": args.hours, "latitude_deg": 34.246}
    rows = []
    fg, ax = plt.subplots(4, 1, figsize=(9, 11), sharex=True)
    for scheme, label in ((0, "no rotation"), (1, "single-position fwd/rev (seed 003)")):
        res = fil.run_fil(m, ticks, config=dict(index_scheme=scheme), errors=errors, seed=args.seed,
                          every=100, progress=fil.TextProgress())
        e = runner.nav_errors(res)
        th = e.time_s / 3600
        figs = {
            "position_nmi": e.horizontal_m.max() / earth.NMI_TO_M,
            "level_arcmin": np.abs(e.att_n_rad[:, :2]).max() / ARCMIN,
            "heading_arcmin": np.abs(e.att_n_rad[:, 2]).max() / ARCMIN,
            "velocity_mps": np.abs(e.vel_n_mps[:, :2]).max(),
        }
        rows.append((label, figs))
        for k, v in figs.items():
            fig_json[f"{'rot' if scheme else 'norot'}_max_{k}"] = float(v)
        ax[0].plot(th, e.horizontal_m / earth.NMI_TO_M, label=label)
        ax[1].plot(th, np.abs(e.att_n_rad[:, :2]).max(axis=1) / ARCMIN, label=label)
        ax[2].plot(th, e.att_n_rad[:, 2] / ARCMIN, label=label)
        ax[3].plot(th, np.hypot(e.vel_n_mps[:, 0], e.vel_n_mps[:, 1]), label=label)
    for a, yl in zip(ax, ["horizontal position error [nmi]", "max |level error| [arcmin]",
                          "heading error [arcmin]", "horizontal velocity error [m/s]"]):
        a.set_ylabel(yl)
        a.legend(fontsize=8)
    ax[3].set_xlabel("time [h]")
    fg.suptitle("seed 003: static ship, 24 h, its sensor errors")
    fg.tight_layout()
    fg.savefig(os.path.join(args.out, "errors.png"), dpi=100)
    md = ["| | max position (nmi) | max level (') | max heading (') | max velocity (m/s) |",
          "|---|---|---|---|---|",
          f"| paper, rotating (bounds) | < {PAPER['position_nmi']} | < {PAPER['level_arcmin']} | "
          f"< {PAPER['heading_arcmin']} | < {PAPER['velocity_mps']} |"]
    for label, f in rows:
        md.append(f"| ours, {label} | {f['position_nmi']:.3f} | {f['level_arcmin']:.4f} | "
                  f"{f['heading_arcmin']:.3f} | {f['velocity_mps']:.4f} |")
    text = "\n".join(md)
    print(text)
    with open(os.path.join(args.out, "table.md"), "w") as fh:
        fh.write(text + "\n")
    with open(os.path.join(args.out, "seed003.json"), "w") as fh:
        json.dump(fig_json, fh, indent=2)
    print(f"written to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
