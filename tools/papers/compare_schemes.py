#!/usr/bin/env python3
"""Compare the indexing schemes on the horizontal gyro drifts alone.
The ships, the turntable and the error set are the built-in scenarios
seed002_exp1/seed002_exp2 with overrides (and reproduce_seed002's
"horizontal gyro drifts only"); this driver adds the table.

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

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reproduce_seed002 import ERROR_SETS, SCENARIOS  # noqa: E402

from pyins import analysis, metrics, run_scenario, scenario  # noqa: E402
from pyins import progress as progress_bars  # noqa: E402
from pyins.units import NMI_TO_M, TICK_HZ  # noqa: E402

#: (id, scheme, index_sums, label)
VARIANTS = (("none", "none", "stops", "no rotation"), ("two", "two_position", "stops", "traditional"),
            ("flex", "flexible", "stops", "flexible, literal"),
            ("derived", "flexible_derived", "stops", "derivation form"),
            ("derived_all", "flexible_derived", "all", "derivation form, turns summed"),
            ("flex_all", "flexible", "all", "literal, turns summed"))
#: (id, label, accel [deg/s^2])
SHIPS = (("exp1", "seed 002 exp. 1 (T = 120 s)", 30.0), ("exp1", "exp. 1, 600 deg/s^2", 600.0),
         ("exp2", "seed 002 exp. 2 (T = 60 s)", 30.0), ("exp2", "exp. 2, 600 deg/s^2", 600.0),
         ("static", "static ship, heading 15 deg", 30.0))
#: ship id -> (built-in scenario, overrides): seed 002's heading swings; its site, attitude and
#: heading without the swing
SHIP_SCENARIOS = {"exp1": (SCENARIOS[1], {}), "exp2": (SCENARIOS[2], {}),
                  "static": (SCENARIOS[1], {"motion.kind": "static", "motion.rate_amplitude": None,
                                            "motion.period": None})}
#: every run: one scheme, no [paper], the horizontal gyro drifts as the only error, noise seed 0
COMMON = {"compare": None, "paper": None, "seed": 0, **ERROR_SETS["hdrift"]}


def spec_of(name, scheme, sums, accel_deg, hours):
    """The RunSpec of ship ``name`` with one scheme, its sums and turn acceleration [deg/s^2]."""
    ticks = int(hours * (3600 * TICK_HZ))
    base, overrides = SHIP_SCENARIOS[name]
    (spec,) = scenario.load(base).with_overrides({
        **COMMON, **overrides, "duration": f"{ticks / TICK_HZ!r} s", "indexing.scheme": scheme,
        "indexing.sums": sums, "indexing.acceleration": f"{accel_deg:g} deg/s^2"}).runs()
    return spec


def run_one(spec, progress):
    res = run_scenario.run(spec, progress=progress)
    e = metrics.nav_errors(res)
    return {"max_nmi": float(e.horizontal_m.max() / NMI_TO_M),
            "final_nmi": float(e.horizontal_m[-1] / NMI_TO_M),
            "survives": analysis.drift_surviving_of_run(spec.motion, res, spec.config)[0],
            "fallbacks": int(res.outputs["index_fallbacks"][-1])}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hours", type=float, default=72.0)
    ap.add_argument("--out", default=os.path.join("runs", "compare_schemes"))
    ap.add_argument("--quiet", action="store_true", help="no progress bar")
    args = ap.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    progress = None if args.quiet else progress_bars.TextProgress()
    out = {"hours": args.hours, "gyro_drift_deg_h": 0.003}
    head = "| ship | " + " | ".join(v[3] for v in VARIANTS) + " |"
    rows = [f"Max horizontal error [nmi] over {args.hours:g} h, horizontal gyro drifts only "
            "(surviving fraction; flexible fallbacks if any)", "", head,
            "|" + "---|" * (len(VARIANTS) + 1)]
    for name, label, accel in SHIPS:
        cells = []
        for vid, scheme, sums, _ in VARIANTS:
            if scheme == "none" and accel != 30.0:
                cells.append("")       # no turns: the acceleration does not matter
                continue
            f = run_one(spec_of(name, scheme, sums, accel, args.hours), progress)
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
