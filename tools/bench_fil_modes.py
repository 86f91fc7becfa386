#!/usr/bin/env python3
"""Benchmark: the closed loop's wall time in each navigation mode, side by
side in one run (the at-sea issue's benchmark).

    .venv/bin/python tools/bench_fil_modes.py [--hours 72] [--rounds 3]

The closed loop of tools/bench_fil.py (seed 002 experiment 1: the heading
swing, the flexible scheme, seed 002's sensor errors; `pyins.fil.run_fil`,
compiled plant and firmware, a record every 100 ticks) for --hours, three
ways, interleaved over --rounds rounds (the machine's load moves wall time
by up to 2x here; the median of each is printed and the ratios of the
medians):

- UNDAMPED: ``nav_mode`` UNDAMPED, the firmware of ABI 0.14 (no filter);
- AUTO, no references: the navigation filter at sea predicts its
  covariance once a second beside the strapdown;
- INTEGRATED: AUTO with a 1 Hz GNSS (3 m, 2 m Gauss-Markov bias, 0.05 m/s;
  `pyins.sim.references.gnss`), pushed between plant calls
  (`pyins.aiding.Aider`); its simulation is not timed.

The instruction counts per tick of each mode are tools/size_report.py's
(the embedded report); this prints wall time only. Not a timed test.
"""
import argparse
import statistics
import time

from pyins import fil, sim
from pyins.reference import abi
from pyins.sim import references
from pyins.units import DT


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hours", type=float, default=72.0)
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args()
    motion, errors = sim.HeadingSwing.experiment(1), sim.preset("seed002")
    n = int(round(args.hours * 3600.0 / DT))
    t0 = time.perf_counter()
    g = references.gnss(motion, n * DT, seed=1)
    print(f"{args.hours:g} h = {n:,} ticks; GNSS {len(g.refs):,} references simulated in "
          f"{time.perf_counter() - t0:.1f} s (not timed below)", flush=True)
    cases = {
        "UNDAMPED (no filter)": dict(config=dict(index_scheme=4, nav_mode=abi.PYINS_NAV_UNDAMPED)),
        "AUTO, no references": dict(config=dict(index_scheme=4)),
        "INTEGRATED (GNSS 1 Hz)": dict(config=dict(index_scheme=4), refs=g.refs, avail_tick=g.avail_tick),
    }
    walls = {name: [] for name in cases}
    for r in range(args.rounds):
        for name, kw in cases.items():
            t0 = time.perf_counter()
            res = fil.run_fil(motion, n, errors=errors, seed=1, every=100, **kw)
            walls[name].append(time.perf_counter() - t0)
            modes = set(res.outputs["nav_mode"].tolist())
            print(f"  round {r + 1}: {name}: {walls[name][-1]:.2f} s (modes {sorted(modes)})", flush=True)
    base = statistics.median(walls["UNDAMPED (no filter)"])
    print(f"\n{'mode':26s} {'median wall [s]':>16s} {'M ticks/s':>10s} {'vs UNDAMPED':>12s}")
    for name, w in walls.items():
        m = statistics.median(w)
        print(f"{name:26s} {m:16.2f} {n / m / 1e6:10.2f} {m / base:11.2f}x")


if __name__ == "__main__":
    main()
