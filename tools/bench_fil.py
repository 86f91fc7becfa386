#!/usr/bin/env python3
"""Benchmark: firmware-in-the-loop speed.

    .venv/bin/python tools/bench_fil.py [--hours 72] [--json runs/bench/fil.json]

1. A 10-minute closed-loop run (seed 002 experiment 1, flexible scheme,
   seed 002 sensor errors) three ways: compiled plant + C++ firmware
   (pyins_fil_run), the C++ firmware alone on the same samples (batch call),
   and the NumPy plant + NumPy reference firmware; ticks per second and the
   ratios. The compiled plant's own cost is the difference of the first two.
2. The full --hours run (default 72 h = 25.9 M ticks) through run_fil:
   wall time and peak memory (target < 60 s and < 1 GiB).
"""
import argparse
import json
import os
import resource
import sys
import time

import numpy as np

from pyins import fil, metrics, native, scenario, sim
from pyins.reference import firmware as ref_firmware
from pyins.sim import turntable
from pyins.units import DT, TICK_HZ


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hours", type=float, default=72.0)
    ap.add_argument("--json", default=os.path.join("runs", "bench", "fil.json"))
    ap.add_argument("--ref-seconds", type=float, default=60.0, help="ship time the NumPy loop is timed on")
    args = ap.parse_args(argv)
    m = sim.HeadingSwing.experiment(1)
    errors = sim.preset("seed002")
    cfg = dict(index_scheme=4)
    n = 60_000

    fil.run_fil(m, 1000, config=cfg, errors=errors, seed=1, every=100)   # warm-up
    t0 = time.perf_counter()
    fil.run_fil(m, n, config=cfg, errors=errors, seed=1, every=100)
    t_fil = time.perf_counter() - t0      # includes the one-off node rates of one period
    # the C++ firmware alone on samples of the same kind (open loop, table fixed)
    dth, dv, al = sim.exact_increments(m, n)
    dth, dv = sim.SensorModel(errors, seed=1).apply(dth, dv)
    samples = native.make_samples(dth, dv, al)
    fw = native.Firmware(scenario.initial_config(m, None, **cfg))
    t0 = time.perf_counter()
    fw.run(samples)
    t_fw = time.perf_counter() - t0
    # the NumPy loop
    k = int(args.ref_seconds * TICK_HZ)
    ref = ref_firmware.Firmware(scenario.initial_config(m, None, **cfg))
    st, tab, mats = turntable.PlantState(), turntable.TableConfig(), turntable.error_matrices(errors)
    omega, force, x, w = sim.node_rates(m, np.arange(k))
    z = np.random.default_rng(1).standard_normal((k, 6)) * np.sqrt(DT)
    t0 = time.perf_counter()
    t_plant_ref = 0.0
    for i in range(k):
        tp = time.perf_counter()
        g, a, enc, seq = turntable.plant_tick(tab, st, mats, omega[i], force[i], x, w,
                                              errors.gyro_arw * z[i, :3], errors.accel_vrw * z[i, 3:], DT)
        t_plant_ref += time.perf_counter() - tp
        _, r = ref.step(g, a, enc, seq)
        st.rate_cmd_rad_s = r["motor_rate_cmd_rad_s"]
    t_ref = (time.perf_counter() - t0) * n / k
    t_plant_ref *= n / k

    fig = {
        "fil_cpp_ticks_per_s": n / t_fil,
        "firmware_cpp_ticks_per_s": n / t_fw,
        "plant_cpp_ticks_per_s_derived": n / max(t_fil - t_fw, 1e-9),
        "fil_numpy_ticks_per_s": n / t_ref,
        "plant_numpy_ticks_per_s": n / t_plant_ref,
        "firmware_numpy_ticks_per_s": n / (t_ref - t_plant_ref),
        "ratio_cpp_vs_numpy_fil": t_ref / t_fil,
    }
    print("10-minute closed loop (seed 002 exp. 1, flexible scheme, seed 002 errors)")
    print(f"{'':34s} {'ticks/s':>12s}")
    print(f"{'C++ plant + C++ firmware':34s} {fig['fil_cpp_ticks_per_s']:12,.0f}")
    print(f"{'C++ firmware alone':34s} {fig['firmware_cpp_ticks_per_s']:12,.0f}")
    print(f"{'C++ plant alone (difference)':34s} {fig['plant_cpp_ticks_per_s_derived']:12,.0f}")
    print(f"{'NumPy plant + NumPy firmware':34s} {fig['fil_numpy_ticks_per_s']:12,.0f}   "
          f"(timed on {args.ref_seconds:g} s)")
    print(f"{'NumPy plant alone':34s} {fig['plant_numpy_ticks_per_s']:12,.0f}")
    print(f"{'NumPy firmware alone':34s} {fig['firmware_numpy_ticks_per_s']:12,.0f}")
    print(f"ratio C++ / NumPy closed loop: {fig['ratio_cpp_vs_numpy_fil']:,.0f}x")

    ticks = int(round(args.hours * 3600 * TICK_HZ))
    t0 = time.perf_counter()
    res = fil.run_fil(m, ticks, config=cfg, errors=errors, seed=1, every=100)
    wall = time.perf_counter() - t0
    peak_mib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    e = metrics.nav_errors(res)
    fig.update({"long_run_hours": args.hours, "long_run_ticks": ticks, "long_run_wall_s": wall,
                "long_run_ticks_per_s": ticks / wall, "peak_memory_mib": peak_mib,
                "long_run_max_horizontal_error_m": float(e.horizontal_m.max())})
    print(f"{args.hours:g} h FIL run ({ticks:,} ticks): {wall:.1f} s wall "
          f"({ticks / wall:,.0f} ticks/s), peak memory {peak_mib:.0f} MiB "
          f"(targets < 60 s, < 1024 MiB: {'met' if wall < 60 and peak_mib < 1024 else 'NOT met'})")
    os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
    with open(args.json, "w") as f:
        json.dump(fig, f, indent=2)
    print(f"figures written to {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
