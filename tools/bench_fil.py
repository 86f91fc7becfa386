#!/usr/bin/env python3
"""Benchmark: firmware-in-the-loop speed.

    .venv/bin/python tools/bench_fil.py [--hours 72] [--json runs/bench/fil.json]
    .venv/bin/python tools/bench_fil.py --count [--hours 0.5] [--dump DIR]
    .venv/bin/python tools/bench_fil.py --dump DIR [--hours 0.5]
    .venv/bin/python tools/bench_fil.py --schemes [--hours 6] [--rounds 5]

1. A 10-minute closed-loop run (seed 002 experiment 1, flexible scheme,
   seed 002 sensor errors) three ways: compiled plant + C++ firmware
   (pyins_fil_run), the C++ firmware alone on samples of the same kind
   (batch call, a record every 100 ticks as the loop keeps them), and the
   NumPy plant + NumPy reference firmware; ticks per second and the ratios.
   The compiled plant's own cost is counted, not timed (3.).
2. The full --hours run (default 72 h = 25.9 M ticks) through run_fil:
   wall time and peak memory (the targets set for the closed loop: < 6 s on
   a quiet machine, < 500 MiB).
3. (``--count``, also at the end of the default run) the machine-independent
   cost: valgrind callgrind's instructions per tick inside pyins_fil_run
   (plant + firmware), of which inside pyins_run (the firmware; the plant is
   the difference), over --hours of the same closed loop (default 0.5 h =
   180,000 ticks; the default run counts 0.5 h), through the C driver
   build/host/fil_count on the inputs run_fil builds (dumped to DIR, default
   build/host/fil_dump). fil_count's last lat_rad must equal the Python
   run_fil's bit for bit. ``--count`` alone runs only this and adds its
   figures to the existing JSON. ``--dump DIR`` alone only writes the inputs.
4. (``--schemes``) where the closed loop's wall time goes: fil_count's own
   timing of its one pyins_fil_run call (no Python around it) on the same
   ship and sensors with the table at rest (scheme none), the traditional
   and the flexible two-position scheme, timed in alternation: ns per tick
   of each, the ratio to the table at rest and the share of ticks turning.
"""
import argparse
import inspect
import json
import os
import re
import resource
import shutil
import struct
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from pyins import fil, metrics, native, scenario, sim
from pyins.reference import firmware as ref_firmware
from pyins.sim import turntable
from pyins.units import DT, TICK_HZ

ROOT = Path(__file__).resolve().parent.parent
BUILD = ROOT / "build" / "host"
FIL_COUNT = BUILD / "fil_count"


def the_case(scheme=4):
    """The closed loop every part of this benchmark runs: (motion, errors, config, seed, every);
    ``scheme``: the indexing scheme (4, seed 002's flexible two-position; ``--schemes`` also
    runs 0, none, and 2, the traditional two-position)."""
    return sim.HeadingSwing.experiment(1), sim.preset("seed002"), dict(index_scheme=scheme), 1, 100


# ---------------------------------------------------------------------------
# 3. instruction counts: the inputs of one pyins_fil_run call, the C driver
#    on them under callgrind

def dump_inputs(out_dir, n, scheme=4):
    """Write the inputs of pyins_fil_run over the first ``n`` ticks of the
    case (indexing ``scheme``), built as run_fil builds them (one chunk of
    ``n`` ticks), to ``out_dir`` (the files tools/fil_count.c reads), plus
    ``fil_dump.json`` with the sizes, the Python run_fil's final lat_rad and
    the share of its kept records (every 100th tick) with the table turning.
    Returns that dict."""
    m, errors, config, seed, every = the_case(scheme)
    defaults = {k: v.default for k, v in inspect.signature(fil.run_fil).parameters.items()}
    dt, nodes = defaults["dt"], defaults["nodes"]
    # run_fil's step 1 (the loop's parts), as there
    table = turntable.TableConfig()
    cfg = fil.initial_config(m, None, **config)
    loop = fil._Loop(m, cfg, errors, seed, table, dt, nodes, "native")
    if not isinstance(loop.plant, native.Plant):
        raise RuntimeError(f"run_fil's native plant is a {type(loop.plant).__name__}, not native.Plant")
    # its step 3 for one chunk of n ticks: the ship's rates, then the noise
    omega, force, x, w, period, phase0 = loop.ship_rates(n)
    drawn = loop.noise(n)
    g_noise, a_noise = drawn[0], drawn[1]
    # the pyins_config the firmware was initialised from (native.Firmware: make_config(cfg))
    c_cfg = native.make_config(cfg)
    ffi = native.ffi
    os.makedirs(out_dir, exist_ok=True)
    for name in ("gyro_noise.bin", "accel_noise.bin"):      # a stale noise file would be read
        if os.path.exists(os.path.join(out_dir, name)):
            os.remove(os.path.join(out_dir, name))

    def put(name, data):
        with open(os.path.join(out_dir, name), "wb") as f:
            f.write(data)

    put("config.bin", bytes(ffi.buffer(c_cfg, ffi.sizeof("pyins_config"))))
    put("plant_state.bin", bytes(ffi.buffer(loop.plant._st, ffi.sizeof("pyins_plant_state"))))
    put("table_config.bin", bytes(ffi.buffer(loop.plant._tab, ffi.sizeof("pyins_table_config"))))
    put("imu_errors.bin", bytes(ffi.buffer(loop.plant._err, ffi.sizeof("pyins_imu_errors"))))
    put("params.bin", struct.pack("=5qd", int(period), len(x), int(every), int(n), int(phase0), float(dt)))
    arrays = {"omega.bin": omega, "force.bin": force, "x.bin": x, "w.bin": w}
    if g_noise is not None:
        arrays.update({"gyro_noise.bin": g_noise, "accel_noise.bin": a_noise})
    for name in ("sum_omega.bin", "sum_force.bin"):         # a stale sums file would be read
        if os.path.exists(os.path.join(out_dir, name)):
            os.remove(os.path.join(out_dir, name))
    if loop.sums is not None:                               # what run_fil hands the plant
        arrays.update({"sum_omega.bin": loop.sums[0], "sum_force.bin": loop.sums[1]})
    for name, arr in arrays.items():
        put(name, np.ascontiguousarray(arr, dtype=np.float64).tobytes())

    # the Python run of the same n in one chunk: what fil_count must reproduce
    res = fil.run_fil(m, n, config=config, errors=errors, seed=seed, every=every, chunk_ticks=max(n, 1))
    lat = float(res.outputs["lat_rad"][-1])
    info = {
        "ticks": int(n), "period": int(period), "nodes": len(x), "phase0": int(phase0), "dt": float(dt),
        "every": int(every), "noise": g_noise is not None,
        "sizeof": {t: ffi.sizeof(t) for t in ("pyins_config", "pyins_plant_state", "pyins_table_config",
                                                "pyins_imu_errors", "pyins_output")},
        "doubles": {k: int(np.asarray(v).size) for k, v in arrays.items()},
        "python_final_lat_rad": lat, "python_final_lat_rad_hex": lat.hex(),
        "python_final_tick": int(res.outputs["tick"][-1]),
        "turning_share_sampled": float(np.mean(res.plant["rate_rad_s"] != 0.0)),
    }
    with open(os.path.join(out_dir, "fil_dump.json"), "w") as f:
        json.dump(info, f, indent=2)
    return info


def _after(stdout, name):
    """The word after ``name`` in fil_count's line `ticks N lat X ... loop_s T`."""
    words = stdout.split()
    return words[words.index(name) + 1]


def _lat_of(stdout):
    """(ticks, lat_rad) from fil_count's line."""
    return int(_after(stdout, "ticks")), float(_after(stdout, "lat"))


def _check_lat(what, stdout, info):
    ticks, lat = _lat_of(stdout)
    want = info["python_final_lat_rad"]
    if ticks != info["ticks"] or struct.pack("=d", lat) != struct.pack("=d", want):
        raise SystemExit(
            f"FAIL: {what}: {ticks} ticks, final lat_rad {lat!r} ({lat.hex()}) but the Python run_fil "
            f"gives {info['ticks']} ticks, {want!r} ({want.hex()}): the same inputs must give the same "
            f"bits. Is the installed library built from the same sources as build/host? (cmake --build "
            f"build/host && .venv/bin/python -m pip install -q -e .)")


def _callgrind(dump_dir, toggle, out_file):
    """Instructions collected inside ``toggle`` and the run's stdout."""
    res = subprocess.run(["valgrind", "--tool=callgrind", f"--toggle-collect={toggle}",
                          f"--callgrind-out-file={out_file}", str(FIL_COUNT), str(dump_dir)],
                         capture_output=True, text=True)
    if res.returncode != 0:
        raise SystemExit(f"FAIL: valgrind fil_count (toggle {toggle}) exited {res.returncode}:\n"
                         f"{res.stderr[-2000:]}")
    for line in res.stderr.splitlines():
        if "Collected :" in line:
            return int(line.split(":")[-1].strip()), res.stdout
    raise SystemExit(f"FAIL: callgrind printed no total (toggle {toggle})")


def _inclusive(out_file, names):
    """Inclusive instructions of the functions ``names`` in a callgrind
    output, by callgrind_annotate --inclusive=yes (None where not listed)."""
    res = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--threshold=100", str(out_file)],
                         capture_output=True, text=True, check=True)
    found = {}
    for line in res.stdout.splitlines():     # "  221,383,443 (62.78%)  ???:pyins_run [/path/obj]"
        mt = re.match(r"\s*([\d,]+)\s+\([^)]*\)\s+(.*?)(?:\s+\[[^\]]*\])?\s*$", line)
        if mt is None or ":" not in mt.group(2):
            continue
        sym = mt.group(2).split(":", 1)[1]
        if sym in names and sym not in found:
            found[sym] = int(mt.group(1).replace(",", ""))
    return {k: found.get(k) for k in names}


#: --schemes: (indexing scheme, name), the table at rest first
SCHEMES = ((0, "none (table at rest)"), (2, "traditional two-position"), (4, "flexible two-position"))


def time_schemes(hours, rounds, dump_root):
    """Section 4 (``--schemes``): the wall time of the closed loop alone, in C
    (fil_count: one pyins_fil_run call, no Python around it), of the same
    ship and sensors under three indexing schemes, timed in alternation
    ``rounds`` times: what a tick costs with the table at rest and what its
    turning ticks add. Figures dict."""
    n = int(round(hours * 3600 * TICK_HZ))
    subprocess.run(["cmake", "--build", str(BUILD), "--target", "fil_count"], check=True,
                   capture_output=True, text=True)
    print(f"the closed loop alone in C (fil_count), {hours:g} h ({n:,} ticks) under three schemes, "
          f"{rounds} rounds; load {os.getloadavg()[0]:.2f}")
    infos = {}
    for scheme, _ in SCHEMES:
        d = os.path.join(dump_root, f"scheme{scheme}")
        infos[scheme] = dump_inputs(d, n, scheme)
    times = {scheme: [] for scheme, _ in SCHEMES}
    for r in range(rounds):
        order = SCHEMES if r % 2 == 0 else SCHEMES[::-1]
        for scheme, _ in order:
            res = subprocess.run([str(FIL_COUNT), os.path.join(dump_root, f"scheme{scheme}")],
                                 capture_output=True, text=True)
            if res.returncode != 0:
                raise SystemExit(f"FAIL: fil_count exited {res.returncode}: {res.stderr.strip()}")
            _check_lat(f"fil_count, scheme {scheme}", res.stdout, infos[scheme])
            times[scheme].append(float(_after(res.stdout, "loop_s")))
    rest = float(np.median(times[0])) / n
    fig = {"schemes_hours": hours, "schemes_rounds": rounds}
    print(f"  {'scheme':26s} {'ns/tick':>8s} {'range':>15s} {'/ none':>7s} {'turning':>8s}")
    for scheme, name in SCHEMES:
        med = float(np.median(times[scheme])) / n
        share = infos[scheme]["turning_share_sampled"]
        fig[f"schemes_ns_per_tick_{scheme}"] = med * 1e9
        fig[f"schemes_turning_share_{scheme}"] = share
        lo, hi = min(times[scheme]) / n * 1e9, max(times[scheme]) / n * 1e9
        print(f"  {name:26s} {med * 1e9:8.1f} {f'[{lo:.1f}, {hi:.1f}]':>15s} {med / rest:7.3f} "
              f"{100 * share:7.2f}%")
    print(f"  (median and range over the rounds; turning: the share of the kept records, every 100th "
          f"tick, with the table's rate not 0; fil_count reproduced run_fil's final lat_rad bit for bit "
          f"in every round; load {os.getloadavg()[0]:.2f} after)")
    return fig


def count_instructions(hours, dump_dir):
    """Section 3: figures dict, or None (the reason printed) if it cannot run."""
    n = int(round(hours * 3600 * TICK_HZ))
    print(f"instruction count of the closed loop over {hours:g} h ({n:,} ticks)")
    if shutil.which("valgrind") is None or shutil.which("callgrind_annotate") is None:
        print("  skipped: valgrind (with callgrind_annotate) is not installed")
        return None
    try:  # rebuild the driver if its sources changed (a no-op otherwise)
        subprocess.run(["cmake", "--build", str(BUILD), "--target", "fil_count"], check=True,
                       capture_output=True, text=True)
    except (subprocess.CalledProcessError, FileNotFoundError) as exc:
        print(f"  skipped: build/host/fil_count did not build: "
              f"{getattr(exc, 'stderr', '') or exc}".rstrip())
        return None
    t0 = time.perf_counter()
    info = dump_inputs(dump_dir, n)
    print(f"  inputs written to {dump_dir} ({time.perf_counter() - t0:.1f} s with the Python run); "
          f"Python run_fil final lat_rad {info['python_final_lat_rad']!r}")
    res = subprocess.run([str(FIL_COUNT), str(dump_dir)], capture_output=True, text=True)
    if res.returncode != 0:
        raise SystemExit(f"FAIL: fil_count exited {res.returncode}: {res.stderr.strip()}")
    _check_lat("fil_count", res.stdout, info)
    t0 = time.perf_counter()
    out_total = BUILD / "callgrind.fil_count.out"
    total, stdout = _callgrind(dump_dir, "pyins_fil_run", out_total)
    _check_lat("fil_count under callgrind", stdout, info)
    fw_alone, _ = _callgrind(dump_dir, "pyins_run", BUILD / "callgrind.fil_count.pyins_run.out")
    incl = _inclusive(out_total, ("pyins_fil_run", "pyins_run", "pyins_get_motor_command",
                                  "pyins_get_output"))
    wall = time.perf_counter() - t0
    if incl["pyins_run"] is not None and incl["pyins_run"] != fw_alone:
        print(f"  note: pyins_run inclusive {incl['pyins_run']:,} (callgrind_annotate) vs {fw_alone:,} "
              f"(--toggle-collect=pyins_run)")
    getters = sum(v or 0 for k, v in incl.items() if k.startswith("pyins_get_"))
    fig = {
        "count_ticks": n,
        "count_ir_per_tick_fil_run": total / n,
        "count_ir_per_tick_firmware": fw_alone / n,
        "count_ir_per_tick_plant": (total - fw_alone) / n,
        "count_ir_per_tick_plant_of_which_getters": getters / n,
        "count_firmware_share": fw_alone / total,
        "count_ir_total_fil_run": total,
        "count_ir_total_pyins_run": fw_alone,
        "count_pyins_run_inclusive_annotate": incl["pyins_run"],
        "count_final_lat_rad": info["python_final_lat_rad"],
        "count_valgrind_wall_s": wall,
    }
    print(f"  fil_count reproduces run_fil's final lat_rad bit for bit (native and under callgrind)")
    print(f"  {'instructions per tick':34s} {'Ir/tick':>10s}")
    print(f"  {'pyins_fil_run (plant + firmware)':34s} {fig['count_ir_per_tick_fil_run']:10,.0f}")
    print(f"  {'  firmware (pyins_run inclusive)':34s} {fig['count_ir_per_tick_firmware']:10,.0f}   "
          f"({100 * fig['count_firmware_share']:.1f} %)")
    print(f"  {'  plant (difference)':34s} {fig['count_ir_per_tick_plant']:10,.0f}   "
          f"(of which pyins_get_* calls {fig['count_ir_per_tick_plant_of_which_getters']:,.0f})")
    print(f"  (two callgrind runs: {wall:.0f} s)")
    return fig


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hours", type=float, default=None,
                    help="the long run's ship time (default 72 h); with --count or --dump: the counted "
                         "run's (default 0.5 h)")
    ap.add_argument("--json", default=os.path.join("runs", "bench", "fil.json"))
    ap.add_argument("--ref-seconds", type=float, default=60.0, help="ship time the NumPy loop is timed on")
    ap.add_argument("--count", action="store_true",
                    help="only the callgrind instruction count (figures added to the JSON)")
    ap.add_argument("--dump", metavar="DIR", default=None,
                    help="where the inputs of fil_count go (alone: only write them)")
    ap.add_argument("--schemes", action="store_true",
                    help="only section 4: the closed loop alone in C under three indexing schemes "
                         "(--hours default 6, --rounds; figures added to the JSON)")
    ap.add_argument("--rounds", type=int, default=5, help="--schemes: timed rounds (default 5)")
    args = ap.parse_args(argv)
    dump_dir = args.dump or str(BUILD / "fil_dump")
    if args.schemes:
        if args.rounds < 1:
            ap.error("--rounds must be at least 1")
        hours = args.hours if args.hours is not None else 6.0
        if not hours > 0:
            ap.error("--hours must be > 0")
        _add_to_json(args.json, time_schemes(hours, args.rounds, args.dump or str(BUILD / "fil_schemes")))
        return 0
    if args.count or args.dump:
        hours = args.hours if args.hours is not None else 0.5
        if not args.count:
            info = dump_inputs(dump_dir, int(round(hours * 3600 * TICK_HZ)))
            print(f"fil_count inputs of {info['ticks']:,} ticks written to {dump_dir}; "
                  f"Python run_fil final lat_rad {info['python_final_lat_rad']!r}")
            return 0
        counted = count_instructions(hours, dump_dir)
        if counted is not None:
            _add_to_json(args.json, counted)
        return 0
    args.hours = args.hours if args.hours is not None else 72.0
    m, errors, cfg, _, _ = the_case()
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
    fw.run(samples, every=100)          # records as the closed loop keeps them
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
        "fil_numpy_ticks_per_s": n / t_ref,
        "plant_numpy_ticks_per_s": n / t_plant_ref,
        "firmware_numpy_ticks_per_s": n / (t_ref - t_plant_ref),
        "ratio_cpp_vs_numpy_fil": t_ref / t_fil,
    }
    print("10-minute closed loop (seed 002 exp. 1, flexible scheme, seed 002 errors)")
    print(f"{'':34s} {'ticks/s':>12s}")
    print(f"{'C++ plant + C++ firmware':34s} {fig['fil_cpp_ticks_per_s']:12,.0f}")
    print(f"{'C++ firmware alone':34s} {fig['firmware_cpp_ticks_per_s']:12,.0f}")
    print(f"{'C++ plant alone':34s} {'see --count':>12s}   (a difference of two wall times is noise here)")
    print(f"{'NumPy plant + NumPy firmware':34s} {fig['fil_numpy_ticks_per_s']:12,.0f}   "
          f"(timed on {args.ref_seconds:g} s)")
    print(f"{'NumPy plant alone':34s} {fig['plant_numpy_ticks_per_s']:12,.0f}")
    print(f"{'NumPy firmware alone':34s} {fig['firmware_numpy_ticks_per_s']:12,.0f}")
    print(f"ratio C++ / NumPy closed loop: {fig['ratio_cpp_vs_numpy_fil']:,.0f}x")

    ticks = int(round(args.hours * 3600 * TICK_HZ))
    load_before = os.getloadavg()[0]
    t0 = time.perf_counter()
    res = fil.run_fil(m, ticks, config=cfg, errors=errors, seed=1, every=100)
    wall = time.perf_counter() - t0
    peak_mib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    e = metrics.nav_errors(res)
    fig.update({"long_run_hours": args.hours, "long_run_ticks": ticks, "long_run_wall_s": wall,
                "long_run_load_1min_before": load_before,
                "long_run_ticks_per_s": ticks / wall, "peak_memory_mib": peak_mib,
                "long_run_max_horizontal_error_m": float(e.horizontal_m.max())})
    print(f"{args.hours:g} h FIL run ({ticks:,} ticks): {wall:.1f} s wall "
          f"({ticks / wall:,.0f} ticks/s), peak memory {peak_mib:.0f} MiB "
          f"at a load of {load_before:.2f}; targets (72 h, quiet machine) < 6 s and < 500 MiB: "
          f"wall {'met' if wall < 6.0 * args.hours / 72.0 else 'NOT met'}, "
          f"memory {'met' if peak_mib < 500 else 'NOT met'}")
    counted = count_instructions(0.5, dump_dir)
    if counted is not None:
        fig.update(counted)
    _write_json(args.json, fig)
    return 0


def _add_to_json(path, fig):
    """The figures ``fig`` added to those already in the JSON at ``path``."""
    old = {}
    if os.path.exists(path):
        with open(path) as f:
            old = json.load(f)
    _write_json(path, {**old, **fig})


def _write_json(path, fig):
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w") as f:
        json.dump(fig, f, indent=2)
    print(f"figures written to {path}")


if __name__ == "__main__":
    sys.exit(main())
