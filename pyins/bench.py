"""Quick benchmark figures for ``pyins bench`` (the full benchmarks, with JSON
files to compare across commits, are tools/bench_*.py).

Three figures on this machine, each timed for about ``seconds``:
- the C++ firmware in one batch call (navigation, IMU fixed, records every
  100 ticks) vs the NumPy reference engine (`pyins.engine`) stepping the
  same samples: ticks per second and the ratio;
- the closed loop (compiled plant + C++ firmware, flexible scheme, seed 002
  errors): ticks per second and the ship time one wall second buys.
"""
import time

from pyins import contract, engine, fil, scenario, sim
from pyins.units import DT


def _timed(fn, seconds):
    """Calls fn() until ``seconds`` passed (at least once); returns (calls, wall)."""
    n, t0 = 0, time.perf_counter()
    while True:
        fn()
        n += 1
        el = time.perf_counter() - t0
        if el >= seconds:
            return n, el


def run(seconds=3.0):
    """The figures as a dict (units in the keys)."""
    m = sim.HeadingSwing.experiment(1)
    errors = sim.preset("seed002")
    n = 100_000
    dth, dv, al = sim.exact_increments(m, n)
    dth, dv = sim.SensorModel(errors, seed=1).apply(dth, dv)
    samples = contract.make_samples(dth, dv, al)
    cfg = scenario.initial_config(m, None)

    def cpp():
        engine.firmware("native", cfg).run(samples, every=100)
    calls, wall = _timed(cpp, seconds)
    cpp_rate = calls * n / wall

    k = 300
    ref = engine.firmware("reference", cfg)

    def numpy_ref():
        for i in range(k):
            ref.step(dth[i], dv[i], al[i])
    calls, wall = _timed(numpy_ref, seconds)
    ref_rate = calls * k / wall

    f_ticks = 200_000

    def closed_loop():
        fil.run_fil(m, f_ticks, config=dict(index_scheme=4), errors=errors, seed=1, every=100)
    calls, wall = _timed(closed_loop, seconds)
    fil_rate = calls * f_ticks / wall
    return {"cpp_firmware_ticks_per_s": cpp_rate, "numpy_reference_ticks_per_s": ref_rate,
            "ratio_cpp_over_numpy": cpp_rate / ref_rate, "fil_closed_loop_ticks_per_s": fil_rate,
            "fil_ship_hours_per_wall_s": fil_rate * DT / 3600.0, "core_version": engine.core_version()}


def lines(fig):
    return [f"C++ firmware (batch):        {fig['cpp_firmware_ticks_per_s'] / 1e6:8.2f} M ticks/s",
            f"NumPy reference firmware:    {fig['numpy_reference_ticks_per_s'] / 1e3:8.2f} k ticks/s",
            f"ratio C++ / NumPy:           {fig['ratio_cpp_over_numpy']:8.0f}",
            f"closed loop (plant + C++):   {fig['fil_closed_loop_ticks_per_s'] / 1e6:8.2f} M ticks/s "
            f"= {fig['fil_ship_hours_per_wall_s']:.2f} h of ship time per wall second"]
