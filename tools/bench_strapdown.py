#!/usr/bin/env python3
"""Benchmark: strapdown navigation over 1 h of 100 Hz data, three ways.

    .venv/bin/python tools/bench_strapdown.py [--json runs/bench/strapdown.json]

Prints, side by side in one run: the C++ core through the batch call, the
C++ core with one cffi call per step, and the NumPy reference (timed on its
first minute and quoted per step); steps per second and the ratios; the
fixed cost of one batch call; and the instructions per step counted by
valgrind's callgrind inside pyins_step (repeatable, unlike wall time). The
figures are also written as one JSON object (units in the keys).
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from pyins import native, sim
from pyins.reference import firmware as ref_firmware
from pyins.units import DEG_TO_RAD, TICK_HZ

ROOT = Path(__file__).resolve().parent.parent
LAT = 34.246 * DEG_TO_RAD


def best_of(fn, repeat):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def callgrind_ir_per_step(n_steps=20000):
    """Instructions per pyins_step from callgrind, or None if unavailable."""
    exe = ROOT / "build" / "host" / "bench_step"
    if shutil.which("valgrind") is None:
        return None, "valgrind not installed"
    if True:  # configure once, rebuild if the sources changed (a no-op otherwise)
        subprocess.run(["cmake", "-S", str(ROOT), "-B", str(ROOT / "build" / "host"), "-G", "Ninja",
                        "-DCMAKE_BUILD_TYPE=Release", "-DPYINS_BUILD_TESTS=ON"],
                       check=True, capture_output=True)
        subprocess.run(["cmake", "--build", str(ROOT / "build" / "host"), "--target", "bench_step"],
                       check=True, capture_output=True)
    out_file = ROOT / "build" / "host" / "callgrind.bench_step.out"
    res = subprocess.run(["valgrind", "--tool=callgrind", "--toggle-collect=pyins_step",
                          f"--callgrind-out-file={out_file}", str(exe), str(n_steps)],
                         capture_output=True, text=True)
    for line in res.stderr.splitlines():
        if "Collected :" in line:
            return int(line.split(":")[-1].strip()) / n_steps, None
    return None, "callgrind printed no total"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", default=str(ROOT / "runs" / "bench" / "strapdown.json"),
                    help="where to write the figures as JSON")
    ap.add_argument("--hours", type=float, default=1.0, help="ship time of the data set")
    ap.add_argument("--ref-seconds", type=float, default=60.0,
                    help="ship time the NumPy reference is timed on")
    args = ap.parse_args(argv)

    n = int(round(args.hours * 3600 * TICK_HZ))
    motion = sim.sea_state("bad", LAT, 0.0, 0.0, yaw0=0.3)
    dtheta, dv, table = sim.exact_increments(motion, n)
    samples = native.make_samples(dtheta, dv, table)
    st0 = motion.state(np.array([0.0]))
    cfg = dict(lat_rad=LAT, euler_b_rad=st0.euler[0])

    # 1. batch call through the Python wrapper
    outputs = np.empty(n, dtype=native.OUTPUT_DTYPE)
    t_batch = best_of(lambda: native.Firmware(cfg).run(samples, outputs), 3)

    # 1b. batch call keeping one record per second of ship time (every=100)
    t_batch_1hz = best_of(lambda: native.Firmware(cfg).run(samples, every=100), 3)

    # 2. one cffi call per step (pointers prepared in advance: the binding's floor)
    fw = native.Firmware(cfg)
    lib, ffi = native.lib, native.ffi
    n_step = min(n, 200_000)
    sample_ptr = ffi.cast("pyins_sample *", ffi.from_buffer(samples))
    out_ptr = ffi.cast("pyins_output *", ffi.from_buffer(outputs, require_writable=True))
    core = fw.core
    step = lib.pyins_step

    def per_step():
        for i in range(n_step):
            step(core, sample_ptr + i, out_ptr + i)
    t_step = best_of(per_step, 2) * n / n_step

    # 3. fixed cost of one batch call: raw lib call, and through Firmware.run
    one = samples[:1].copy()
    one_out = np.empty(1, dtype=native.OUTPUT_DTYPE)
    p1 = ffi.cast("pyins_sample *", ffi.from_buffer(one))
    po = ffi.cast("pyins_output *", ffi.from_buffer(one_out, require_writable=True))
    nd = ffi.new("size_t *")
    run = lib.pyins_run
    k = 100_000
    t_raw0 = best_of(lambda: [run(core, p1, 0, po, nd) for _ in range(k)], 3) / k
    t_raw1 = best_of(lambda: [run(core, p1, 1, po, nd) for _ in range(k)], 3) / k
    k2 = 20_000
    t_wrap1 = best_of(lambda: [fw.run(one, one_out) for _ in range(k2)], 3) / k2

    # 4. NumPy reference, per step
    n_ref = int(args.ref_seconds * TICK_HZ)
    ref = ref_firmware.Firmware(cfg)
    t_ref = best_of(lambda: ref.run(dtheta[:n_ref], dv[:n_ref], table[:n_ref]), 1) * n / n_ref

    # 5. instructions per step
    ir, why = callgrind_ir_per_step()

    fig = {
        "ticks": n,
        "ship_time_h": args.hours,
        "batch_steps_per_s": n / t_batch,
        "batch_ns_per_step": 1e9 * t_batch / n,
        "batch_1hz_records_steps_per_s": n / t_batch_1hz,
        "batch_1hz_records_ns_per_step": 1e9 * t_batch_1hz / n,
        "per_step_cffi_steps_per_s": n / t_step,
        "per_step_cffi_ns_per_step": 1e9 * t_step / n,
        "reference_steps_per_s": n / t_ref,
        "reference_us_per_step": 1e6 * t_ref / n,
        "ratio_batch_vs_per_step": t_step / t_batch,
        "ratio_batch_vs_reference": t_ref / t_batch,
        "ratio_per_step_vs_reference": t_ref / t_step,
        "fixed_cost_raw_call_n0_us": 1e6 * t_raw0,
        "fixed_cost_raw_call_n1_us": 1e6 * t_raw1,
        "fixed_cost_wrapper_run_n1_us": 1e6 * t_wrap1,
        "callgrind_ir_per_step": ir,
    }
    print(f"strapdown navigation, {args.hours:g} h of 100 Hz data ({n} ticks), bad sea state")
    print(f"{'engine':36s} {'steps/s':>14s} {'ns/step':>10s} {'x batch':>9s}")
    rows = [("C++ batch, a record every step", t_batch),
            ("C++ batch, a record every 100 steps", t_batch_1hz),
            ("C++ one cffi call per step", t_step),
            (f"NumPy reference (timed on {args.ref_seconds:g} s)", t_ref)]
    for name, t in rows:
        print(f"{name:36s} {n / t:14,.0f} {1e9 * t / n:10.1f} {t / t_batch:9.1f}")
    print(f"fixed cost per batch call: raw n=0 {1e6 * t_raw0:.2f} us, raw n=1 {1e6 * t_raw1:.2f} us, "
          f"Firmware.run n=1 {1e6 * t_wrap1:.2f} us")
    print(f"target: batch >= 5,000,000 steps/s -> every step {'met' if n / t_batch >= 5e6 else 'NOT met'}, "
          f"1 Hz records {'met' if n / t_batch_1hz >= 5e6 else 'NOT met'}; "
          f"fixed cost < 2 us -> {'met' if t_raw1 < 2e-6 else 'NOT met'} (raw call)")
    print(f"callgrind: {ir:,.0f} instructions per pyins_step" if ir else f"callgrind: n/a ({why})")
    os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
    with open(args.json, "w") as f:
        json.dump(fig, f, indent=2)
    print(f"figures written to {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
