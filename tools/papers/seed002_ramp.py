#!/usr/bin/env python3
"""Seed 002's traditional scheme against the turntable's ramp: how much of
the horizontal gyro drift survives, and the final error, as the turns'
acceleration lengthens each 180-deg turn (the claims issue, point 4).

    .venv/bin/python tools/papers/seed002_ramp.py [--hours 72] [--out docs/results]

The built-ins `seed002_exp1` and `seed002_exp2` (Table 1 and 2, the
sinusoidal heading swing, 72 h), the traditional two-position scheme only,
its turns at 6 deg/s reached with the acceleration a: each turn then takes
rate / a longer than a constant-rate turn (600 deg/s^2, the built-in's: the
rate within one 10 ms tick, 0.01 s; 30 deg/s^2, the firmware default:
0.2 s). Per acceleration: the surviving fraction of a constant drift
(`pyins.analysis.drift_surviving_of_run`: |mean of exp(j yaw_p)| over the
run, the table's history integrated between the records, split into the
stops and the turns) and the final horizontal error. Printed and written to
OUT/seed002_ramp.{md,json}.
"""
import argparse
import json
import sys
from pathlib import Path

from pyins import analysis, metrics, run_scenario, scenario
from pyins.units import NMI_TO_M

SCENARIOS = {1: "seed002_exp1", 2: "seed002_exp2"}
RATE_DEG_S = 6.0
#: deg/s^2: the extra time per turn rate / a = 0.01, 0.02, 0.05, 0.1, 0.2 s
ACCELS = (600.0, 300.0, 120.0, 60.0, 30.0)


def one(exp, accel, hours):
    over = {"compare": None, "paper": None, "indexing.scheme": "two_position",
            "indexing.acceleration": f"{accel:g} deg/s^2", "duration": f"{hours:g} h"}
    (spec,) = scenario.load(SCENARIOS[exp]).with_overrides(over).runs()
    res = run_scenario.run(spec)
    survives, stops, turns = analysis.drift_surviving_of_run(spec.motion, res, spec.config)
    e = metrics.nav_errors(res)
    return dict(exp=exp, accel_deg_s2=accel, extra_s=RATE_DEG_S / accel, survives=survives,
                survives_stops=stops, survives_turns=turns, final_nmi=float(e.horizontal_m[-1] / NMI_TO_M))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hours", type=float, default=72.0)
    ap.add_argument("--out", type=Path, default=None)
    args = ap.parse_args(argv)
    rows = []
    for exp in SCENARIOS:
        for a in ACCELS:
            r = one(exp, a, args.hours)
            rows.append(r)
            print(f"  exp {exp}, {a:g} deg/s^2 (+{r['extra_s']:g} s a turn): surviving {r['survives']:.5f} "
                  f"(stops {r['survives_stops']:.5f}, turns {r['survives_turns']:.5f}), final "
                  f"{r['final_nmi']:.2f} nmi", flush=True)
    lines = [f"The traditional two-position scheme, {args.hours:g} h, Table 2's errors as the built-ins build "
             "them; the surviving fraction of a constant drift (whole run, its stops, its turns) and the final "
             "horizontal error:", "",
             "| experiment | acceleration | extra time a turn | surviving | in the stops | in the turns | final |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['exp']} | {r['accel_deg_s2']:g} deg/s^2 | {r['extra_s']:g} s | {r['survives']:.5f} | "
                     f"{r['survives_stops']:.5f} | {r['survives_turns']:.5f} | {r['final_nmi']:.2f} nmi |")
    text = "\n".join(lines)
    print("\n" + text)
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
        (args.out / "seed002_ramp.json").write_text(json.dumps(rows, indent=1) + "\n")
        (args.out / "seed002_ramp.md").write_text(
            "# Seed 002's traditional scheme against the turntable's ramp\n\n"
            "Written by `.venv/bin/python tools/papers/seed002_ramp.py"
            + (f" --hours {args.hours:g}" if args.hours != 72.0 else "") + " --out docs/results` (its docstring "
            "says what runs).\n\n" + text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
