#!/usr/bin/env python3
"""Benchmark: the per-tick cost of the alignment modes.

    .venv/bin/python tools/bench_alignment.py [--json runs/bench/alignment.json]

For COARSE_ALIGN, FINE_ALIGN with the 5-state and with the 8-state filter,
and NAVIGATE: ns per tick through the C++ batch call, callgrind instructions
per pyins_step (repeatable), and the NumPy reference's us per tick, side by
side with the ratio; then the wall time of a full 10-minute alignment
(coarse 150 s + fine 450 s) through the batch call (target < 0.1 s).
"""
import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from pyins import native, sim
from pyins.reference import firmware as ref_firmware
from pyins.units import DEG_TO_RAD

ROOT = Path(__file__).resolve().parent.parent
LAT = 34.246 * DEG_TO_RAD
MODES = {
    "coarse": dict(coarse_ticks=25500),
    "fine5": dict(fine_ticks=10**6, fine_states=5),
    "fine8": dict(fine_ticks=10**6, fine_states=8),
    "nav": dict(),
}


def callgrind(mode, n=5000):
    exe = ROOT / "build" / "host" / "bench_step"
    subprocess.run(["cmake", "-S", str(ROOT), "-B", str(ROOT / "build" / "host"), "-G", "Ninja",
                    "-DCMAKE_BUILD_TYPE=Release", "-DPYINS_BUILD_TESTS=ON"], check=True, capture_output=True)
    subprocess.run(["cmake", "--build", str(ROOT / "build" / "host"), "--target", "bench_step"],
                   check=True, capture_output=True)
    out = ROOT / "build" / "host" / f"callgrind.{mode}.out"
    res = subprocess.run(["valgrind", "--tool=callgrind", "--toggle-collect=pyins_step",
                          f"--callgrind-out-file={out}", str(exe), str(n), mode],
                         capture_output=True, text=True)
    for line in res.stderr.splitlines():
        if "Collected :" in line:
            return int(line.split(":")[-1].strip()) / n
    return None


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", default=str(ROOT / "runs" / "bench" / "alignment.json"))
    args = ap.parse_args(argv)

    m = sim.sea_state("general", LAT, 0.0, 0.0, yaw0=0.4)
    n = 25_000
    dtheta, dv, alpha = sim.exact_increments(m, n)
    dtheta, dv = sim.SensorModel(sim.preset("seed001"), seed=1).apply(dtheta, dv)
    samples = native.make_samples(dtheta, dv, alpha)
    base = dict(lat_rad=LAT, euler_b_rad=m.state(np.array([0.0])).euler[0])
    fig = {}
    print(f"{'mode':8s} {'C++ ns/tick':>12s} {'Ir/tick':>9s} {'NumPy us/tick':>14s} {'NumPy / C++':>12s}")
    for mode, extra in MODES.items():
        cfg = dict(base, **extra)
        best = min(_timed(lambda: native.Firmware(cfg).run(samples, every=100)) for _ in range(3))
        ns = 1e9 * best / n
        ir = callgrind(mode)
        ref = ref_firmware.Firmware(cfg)
        k = 2000
        t0 = time.perf_counter()
        ref.run(dtheta[:k], dv[:k], alpha[:k])
        us_ref = 1e6 * (time.perf_counter() - t0) / k
        print(f"{mode:8s} {ns:12.1f} {ir:9.0f} {us_ref:14.1f} {1e3 * us_ref / ns:12.0f}")
        fig[f"{mode}_cpp_ns_per_tick"] = ns
        fig[f"{mode}_callgrind_ir_per_tick"] = ir
        fig[f"{mode}_reference_us_per_tick"] = us_ref
    # a full 10-minute alignment: coarse 150 s + fine 450 s
    n10 = 60_000
    d2, v2, a2 = sim.exact_increments(m, n10)
    d2, v2 = sim.SensorModel(sim.preset("seed001"), seed=2).apply(d2, v2)
    s10 = native.make_samples(d2, v2, a2)
    cfg = dict(base, coarse_ticks=15_000, fine_ticks=45_000)
    wall = min(_timed(lambda: native.Firmware(cfg).run(s10, every=100)) for _ in range(3))
    print(f"full 10-minute alignment (coarse 150 s + fine 450 s, 5-state) through the batch call: "
          f"{1e3 * wall:.1f} ms wall (target < 100 ms: {'met' if wall < 0.1 else 'NOT met'})")
    fig["ten_minute_alignment_wall_ms"] = 1e3 * wall
    os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
    with open(args.json, "w") as f:
        json.dump(fig, f, indent=2)
    print(f"figures written to {args.json}")
    return 0


def _timed(fn):
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


if __name__ == "__main__":
    sys.exit(main())
