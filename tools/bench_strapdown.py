#!/usr/bin/env python3
"""Benchmark: strapdown navigation over 100 Hz data, beside its peers, in one run.

    .venv/bin/python tools/bench_strapdown.py [--peer numba] [--psins DIR]
                     [--hours 0.5] [--rounds 7] [--json runs/bench/strapdown.json]

Prints, side by side in one run: the C++ core through the batch call, the
C++ core with one cffi call per step, and the NumPy reference (timed on its
first minute and quoted per step); steps per second and the ratios; the
fixed cost of one batch call; and the instructions per step counted by
valgrind's callgrind inside pyins_step, pyins_run with NULL outputs and
pyins_run_decimated every 100 (tools/bench_step.c, its nav scenario;
repeatable, unlike wall time).

Then interleaved rounds (--rounds): each round times, on the same increments
(bad sea state, --hours of 100 Hz data, 30 min = 180,000 ticks by default),
the raw ``lib.pyins_run(core, samples, n, NULL, &n_done)`` (no output
records), the raw ``pyins_run_decimated`` every 100 ticks, the raw
``pyins_run`` with a record every tick (each on a fresh core, buffers made
before the clock starts), and then each peer once; the order of the two sides
alternates from round to round; each engine runs --repeat times back to back
in its turn and the fastest counts for the round. Reported: per-round paired ratios
peer/core (median, min, max over the rounds), the minimum ns/step of each
engine, and os.getloadavg() before and after the rounds. With
--peer-callgrind the numba kernel's instructions per step are counted too
(callgrind of the whole peer process on the first 1,000 and the first
21,000 increments, differenced: imports and JIT cancel; a few minutes).

Peers (optional, never shipped):

--peer numba   nmayorov/pyins (PyPI ``python-ins``), whose numba-jitted
               strapdown kernel is timed in a long-lived subprocess
               (tools/peer_numba_kernel.py) inside its own virtual environment
               .venv-peer (both packages import as ``pyins``). The venv is
               made on demand (python3 -m venv; pip install python-ins==1.0.1
               numba) if it is missing; if that fails the table says
               "not measured: <why>". PYINS_PEER_VENV=PATH puts it elsewhere.
--psins DIR    a PSINS C++ build the user made. DIR must hold an executable
               ``psins_bench`` with this contract:
                   psins_bench FILE N DT_S LAT_RAD LON_RAD HEIGHT_M PITCH_RAD ROLL_RAD YAW_RAD
               FILE is raw little-endian float64, N rows of 6 values
               (dtheta_x, dtheta_y, dtheta_z [rad], dv_x, dv_y, dv_z [m/s]),
               body frame starboard-bow-up, navigation frame ENU, Euler angles
               in PSINS order [pitch, roll, yaw] (C_b^n = Rz(yaw) Rx(pitch)
               Ry(roll)), ship at rest at that position. It integrates all N
               increments once (vertical channel held, as the core does by
               default) and prints the elapsed seconds of that integration
               alone (file reading excluded) as the last line of stdout;
               exit status 0. It is run once per round.

The figures are also written as one JSON object (units in the keys). Exit
status 0 when the core's own figures were measured (a peer that could not be
measured does not change it).
"""
import argparse
import json
import os
import queue
import shutil
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

from pyins import native, sim
from pyins.reference import firmware as ref_firmware
from pyins.sim.imu import euler_to_mat
from pyins.units import DEG_TO_RAD, TICK_HZ

ROOT = Path(__file__).resolve().parent.parent
LAT = 34.246 * DEG_TO_RAD
PEER_VENV = Path(os.environ.get("PYINS_PEER_VENV", ROOT / ".venv-peer"))
PEER_SCRIPT = ROOT / "tools" / "peer_numba_kernel.py"
PEER_PACKAGE = "python-ins"
PEER_VERSION = "1.0.1"
TARGET_RATIO = 4.0


def best_of(fn, repeat):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def build_bench_step():
    """Configure once and rebuild bench_step if the sources changed; None or why not."""
    try:
        subprocess.run(["cmake", "-S", str(ROOT), "-B", str(ROOT / "build" / "host"), "-G", "Ninja",
                        "-DCMAKE_BUILD_TYPE=Release", "-DPYINS_BUILD_TESTS=ON"],
                       check=True, capture_output=True)
        subprocess.run(["cmake", "--build", str(ROOT / "build" / "host"), "--target", "bench_step"],
                       check=True, capture_output=True)
    except subprocess.CalledProcessError as exc:
        return f"bench_step did not build ({' '.join(map(str, exc.cmd[:2]))} failed)"
    return None


BENCH_STEP_API = {"step": "pyins_step", "null": "pyins_run", "every100": "pyins_run_decimated"}


def callgrind_ir_per_step(n_steps=20000, api="step"):
    """Instructions per step inside one API function (tools/bench_step.c), or None and why."""
    exe = ROOT / "build" / "host" / "bench_step"
    if shutil.which("valgrind") is None:
        return None, "valgrind not installed"
    out_file = ROOT / "build" / "host" / f"callgrind.bench_step.{api}.out"
    res = subprocess.run(["valgrind", "--tool=callgrind", f"--toggle-collect={BENCH_STEP_API[api]}",
                          f"--callgrind-out-file={out_file}", str(exe), str(n_steps), "nav", api],
                         capture_output=True, text=True)
    for line in res.stderr.splitlines():
        if "Collected :" in line:
            return int(line.split(":")[-1].strip()) / n_steps, None
    return None, "callgrind printed no total"


def callgrind_peer_ir_per_step(py, data_dir, n_small=1000, n_big=21000):
    """Instructions per step of the numba kernel: whole-process callgrind totals
    of two runs (first n_small and first n_big increments, JIT compile and
    imports in both) differenced; the two run side by side."""
    if shutil.which("valgrind") is None:
        return None, "valgrind not installed"
    env = {k: v for k, v in os.environ.items() if not k.startswith("PYTHON")}
    env.update(PYTHONHASHSEED="0", NUMBA_NUM_THREADS="1")
    procs = [subprocess.Popen(["valgrind", "--tool=callgrind",
                               f"--callgrind-out-file={data_dir}/callgrind.peer.{m}.out",
                               str(py), "-I", str(PEER_SCRIPT), "--count", str(data_dir), str(m)],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
                              cwd=str(data_dir)) for m in (n_small, n_big)]
    totals = []
    for p in procs:
        _, err = p.communicate()
        hits = [ln for ln in err.splitlines() if "Collected :" in ln]
        if p.returncode != 0 or not hits:
            return None, f"callgrind of the peer failed (exit {p.returncode})"
        totals.append(int(hits[-1].split(":")[-1].strip()))
    return (totals[1] - totals[0]) / (n_big - n_small), None


# ---------------------------------------------------------------------------
# peers
# ---------------------------------------------------------------------------
class NotMeasured(Exception):
    """A peer could not be timed; the message says why."""


def _peer_python():
    return PEER_VENV / "bin" / "python"


def ensure_peer_venv():
    """The peer venv's python, made on demand; NotMeasured if that fails."""
    py = _peer_python()
    probe = [str(py), "-I", "-c", "import pyins.strapdown, pyins._numba_integrate, numba"]
    if py.exists() and subprocess.run(probe, capture_output=True, cwd=tempfile.gettempdir()).returncode == 0:
        return py
    print(f"peer: {PEER_VENV} missing or incomplete; making it "
          f"(python3 -m venv, pip install {PEER_PACKAGE}=={PEER_VERSION} numba) ...", flush=True)
    if not py.exists():
        res = subprocess.run([sys.executable if shutil.which("python3") is None else "python3",
                              "-m", "venv", str(PEER_VENV)], capture_output=True, text=True)
        if res.returncode != 0:
            raise NotMeasured(f"python3 -m venv {PEER_VENV} failed: {res.stderr.strip()[-200:]}")
    pip = [str(py), "-m", "pip", "install", "-q", "--disable-pip-version-check"]
    res = subprocess.run(pip + [f"{PEER_PACKAGE}=={PEER_VERSION}", "numba"], capture_output=True, text=True)
    if res.returncode != 0:
        print(f"peer: {PEER_PACKAGE}=={PEER_VERSION} did not install; trying the newest that does",
              flush=True)
        res = subprocess.run(pip + [PEER_PACKAGE, "numba"], capture_output=True, text=True)
        if res.returncode != 0:
            raise NotMeasured(f"pip install {PEER_PACKAGE} numba failed: {res.stderr.strip()[-200:]}")
    if subprocess.run(probe, capture_output=True, cwd=tempfile.gettempdir()).returncode != 0:
        raise NotMeasured(f"{PEER_PACKAGE} installed but pyins.strapdown / numba do not import")
    print(f"peer: {PEER_VENV} ready", flush=True)
    return py


class NumbaPeer:
    """tools/peer_numba_kernel.py as a long-lived subprocess in .venv-peer."""

    def __init__(self, data_dir, timeout_s=600.0):
        py = ensure_peer_venv()
        env = {k: v for k, v in os.environ.items() if not k.startswith("PYTHON")}
        env["NUMBA_NUM_THREADS"] = "1"
        # -I: no PYTHONPATH, no user site, neither the script's directory nor
        # the cwd on sys.path, so `import pyins` is the peer's package
        self.proc = subprocess.Popen([str(py), "-I", str(PEER_SCRIPT), str(data_dir)],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.PIPE, text=True, env=env, cwd=str(data_dir))
        self.lines = queue.Queue()
        threading.Thread(target=self._pump, daemon=True).start()
        first = self._read(timeout_s)
        if not first.startswith("ready "):
            raise NotMeasured(f"peer did not start: {first}")
        self.info = json.loads(first[len("ready "):])

    def _pump(self):
        for line in self.proc.stdout:
            self.lines.put(line.strip())
        self.lines.put(None)

    def _read(self, timeout_s):
        try:
            line = self.lines.get(timeout=timeout_s)
        except queue.Empty:
            raise NotMeasured(f"peer gave no answer within {timeout_s:g} s")
        if line is None:
            err = self.proc.stderr.read().strip().splitlines()
            raise NotMeasured("peer exited" + (f": {err[-1]}" if err else ""))
        if line.startswith("error "):
            raise NotMeasured(f"peer: {line[6:]}")
        return line

    def time(self, cmd="run", timeout_s=120.0):
        self.proc.stdin.write(cmd + "\n")
        self.proc.stdin.flush()
        return float(self._read(timeout_s))

    def close(self):
        if self.proc.poll() is None:
            try:
                self.proc.stdin.write("quit\n")
                self.proc.stdin.flush()
                self.proc.wait(timeout=10)
            except (OSError, subprocess.TimeoutExpired):
                self.proc.kill()
                self.proc.wait()


class PsinsPeer:
    """A user's PSINS build under DIR, run per the psins_bench contract."""

    def __init__(self, directory, data_dir, dtheta, dv, lat, lon, height, euler):
        exe = Path(directory).expanduser() / "psins_bench"
        if not (exe.is_file() and os.access(exe, os.X_OK)):
            raise NotMeasured(f"no executable psins_bench in {directory}")
        path = Path(data_dir) / "increments_f64.bin"
        np.ascontiguousarray(np.hstack([dtheta, dv]), dtype="<f8").tofile(path)
        self.cmd = [str(exe), str(path), str(dtheta.shape[0]), repr(1.0 / TICK_HZ),
                    repr(lat), repr(lon), repr(height)] + [repr(float(e)) for e in euler]

    def time(self):
        res = subprocess.run(self.cmd, capture_output=True, text=True, timeout=600)
        if res.returncode != 0:
            raise NotMeasured(f"psins_bench exited {res.returncode}: {res.stderr.strip()[-200:]}")
        try:
            return float(res.stdout.strip().splitlines()[-1])
        except (IndexError, ValueError):
            raise NotMeasured("psins_bench printed no elapsed seconds as its last line")

    def close(self):
        pass


# ---------------------------------------------------------------------------
# the core, raw calls (what the rounds time)
# ---------------------------------------------------------------------------
def core_timers(cfg, samples):
    lib, ffi = native.lib, native.ffi
    n = samples.shape[0]
    sample_ptr = ffi.cast("pyins_sample *", ffi.from_buffer(samples))
    outputs = np.empty(n, dtype=native.OUTPUT_DTYPE)
    out_ptr = ffi.cast("pyins_output *", ffi.from_buffer(outputs, require_writable=True))
    cap = n // 100 + 1
    dec = np.empty(cap, dtype=native.OUTPUT_DTYPE)
    dec_ptr = ffi.cast("pyins_output *", ffi.from_buffer(dec, require_writable=True))
    nd = ffi.new("size_t *")
    n_out = ffi.new("size_t *")
    # the casts do not own their buffers: keep the arrays alive with the timers
    keep = (samples, outputs, dec)

    def check(status, name):
        assert keep
        if status != 0 or nd[0] != n:
            raise RuntimeError(f"{name}: status {status}, {nd[0]} of {n} samples")

    def timed(name, call):
        """Seconds of one call(core) on a fresh core (its init not timed)."""
        fw = native.Firmware(cfg)   # keep fw: it owns the core's memory
        core = fw.core
        t0 = time.perf_counter()
        status = call(core)
        t = time.perf_counter() - t0
        check(status, name)
        return t

    def null_outputs():
        return timed("pyins_run(NULL)", lambda core: lib.pyins_run(core, sample_ptr, n, ffi.NULL, nd))

    def every_100():
        return timed("pyins_run_decimated(100)",
                     lambda core: lib.pyins_run_decimated(core, sample_ptr, n, 100, dec_ptr, cap, nd, n_out))

    def every_tick():
        return timed("pyins_run", lambda core: lib.pyins_run(core, sample_ptr, n, out_ptr, nd))

    return {"core_null_outputs": null_outputs, "core_every_100": every_100,
            "core_every_tick": every_tick}


CORE_LABELS = {"core_null_outputs": "C++ core, pyins_run, NULL outputs",
               "core_every_100": "C++ core, pyins_run_decimated, 100",
               "core_every_tick": "C++ core, pyins_run, record/tick"}
PEER_LABELS = {"numba_kernel": "numba kernel (python-ins integrate)",
               "numba_integrator": "python-ins Integrator.integrate",
               "psins": "PSINS psins_bench"}


def interleaved(args, cfg, samples, dtheta, dv, st0):
    """Rounds of core and peers; returns (figures dict, printed lines)."""
    n = samples.shape[0]
    timers = core_timers(cfg, samples)
    peers = {}            # key -> (callable, closer)
    not_measured = {}     # key -> why
    info = {}
    tmp = tempfile.TemporaryDirectory(prefix="pyins_bench_")
    try:
        wanted = set(args.peer or [])
        if "numba" in wanted or args.psins:
            np.save(Path(tmp.name) / "dtheta.npy", dtheta)
            np.save(Path(tmp.name) / "dv.npy", dv)
            (Path(tmp.name) / "meta.json").write_text(json.dumps({
                "dt_s": 1.0 / TICK_HZ, "lat_rad": float(st0.lat[0]), "lon_rad": float(st0.lon[0]),
                "height_m": float(st0.height[0]), "C_bn": euler_to_mat(st0.euler)[0].tolist(),
                "with_altitude": False}))
        if "numba" in wanted:
            try:
                t0 = time.perf_counter()
                p = NumbaPeer(tmp.name)
                info["numba"] = dict(p.info, startup_and_jit_s=time.perf_counter() - t0)
                peers["numba_kernel"] = (lambda p=p: p.time("run"))
                if not args.no_integrator:
                    peers["numba_integrator"] = (lambda p=p: p.time("run_integrator"))
                closers = [p.close]
            except NotMeasured as exc:
                not_measured["numba_kernel"] = str(exc)
                closers = []
        else:
            not_measured["numba_kernel"] = "not asked (--peer numba)"
            closers = []
        if args.psins:
            try:
                ps = PsinsPeer(args.psins, tmp.name, dtheta, dv, float(st0.lat[0]), float(st0.lon[0]),
                               float(st0.height[0]), st0.euler[0])
                peers["psins"] = ps.time
            except NotMeasured as exc:
                not_measured["psins"] = str(exc)

        if args.peer_callgrind:
            if "numba_kernel" in peers:
                print(f"peer: counting the numba kernel's instructions under callgrind "
                      f"(two runs side by side, a few minutes) ...", flush=True)
                ir_peer, why_peer = callgrind_peer_ir_per_step(_peer_python(), tmp.name)
            else:
                ir_peer, why_peer = None, "the numba peer is not running"
        for f in timers.values():   # warm the core's code and the buffers
            f()
        times = {k: [] for k in list(timers) + list(peers)}
        load_before = os.getloadavg()
        t_start = time.perf_counter()
        for r in range(args.rounds):
            order = [timers, peers] if r % 2 == 0 else [peers, timers]
            for side in order:
                for key, f in list(side.items()):
                    try:
                        times[key].append(min(f() for _ in range(args.repeat)))
                    except NotMeasured as exc:   # a peer that dies mid-run
                        not_measured[key] = f"{exc} (round {r + 1})"
                        del peers[key]
                        times.pop(key)
        wall = time.perf_counter() - t_start
        load_after = os.getloadavg()
        for c in closers:
            c()
    finally:
        tmp.cleanup()

    fig = {"rounds": args.rounds, "repeat_per_round": args.repeat, "rounds_wall_s": wall,
           "loadavg_1_5_15min_before": list(load_before),
           "loadavg_1_5_15min_after": list(load_after), "peer_info": info,
           "peers_not_measured": not_measured}
    lines = [f"interleaved: {args.rounds} rounds on {n} ticks, each engine the fastest of {args.repeat} "
             f"back to back (order alternates per round), "
             f"{wall:.1f} s; load average 1/5/15 min before "
             + "/".join(f"{x:.2f}" for x in load_before) + ", after "
             + "/".join(f"{x:.2f}" for x in load_after)]
    lines.append(f"{'engine':40s} {'ns/step min':>11s} {'median':>8s} {'max':>8s}")
    for key, ts in times.items():
        ns = [1e9 * t / n for t in ts]
        fig[f"{key}_ns_per_step_min"] = min(ns)
        fig[f"{key}_ns_per_step_median"] = statistics.median(ns)
        fig[f"{key}_ns_per_step_max"] = max(ns)
        fig[f"{key}_round_s"] = ts
        label = CORE_LABELS.get(key) or PEER_LABELS[key]
        lines.append(f"{label:40s} {min(ns):11.1f} {statistics.median(ns):8.1f} {max(ns):8.1f}")
    for key, why in not_measured.items():
        lines.append(f"{PEER_LABELS[key]:40s} not measured: {why}")

    lines.append(f"paired ratios peer/core, per round ({'median [min, max]'}):")
    lines.append(f"{'peer':36s} " + " ".join(f"{h:>20s}" for h in ("NULL outputs", "every 100",
                                                                       "record every tick")))
    verdicts = []
    for pk in peers:
        cells = []
        for ck in timers:
            ratios = [p / c for p, c in zip(times[pk], times[ck])]
            med = statistics.median(ratios)
            fig[f"ratio_{pk}_vs_{ck}_median"] = med
            fig[f"ratio_{pk}_vs_{ck}_min"] = min(ratios)
            fig[f"ratio_{pk}_vs_{ck}_max"] = max(ratios)
            fig[f"ratio_{pk}_vs_{ck}_rounds"] = ratios
            cells.append(f"{med:6.2f} [{min(ratios):5.2f},{max(ratios):5.2f}]")
            if pk == "numba_kernel" and ck in ("core_null_outputs", "core_every_100"):
                verdicts.append((ck, med))
        lines.append(f"{PEER_LABELS[pk]:36s} " + " ".join(f"{c:>20s}" for c in cells))
    if verdicts:
        ok = all(m >= TARGET_RATIO for _, m in verdicts)
        fig["target_numba_kernel_ratio"] = TARGET_RATIO
        fig["target_numba_kernel_ratio_met"] = ok
        lines.append(f"target: core >= {TARGET_RATIO:g}x faster than the numba kernel (median paired "
                     f"ratio, NULL outputs and every 100) -> {'met' if ok else 'NOT met'} ("
                     + ", ".join(f"{m:.2f}x" for _, m in verdicts) + ")")
    else:
        lines.append(f"target: core >= {TARGET_RATIO:g}x faster than the numba kernel -> not measured")
    if args.peer_callgrind:
        fig["callgrind_ir_per_step_numba_kernel"] = ir_peer
        irs = args.core_ir or {}
        if ir_peer:
            parts = [f"{ir_peer / v:.2f}x {n_}" for n_, v in irs.items() if v]
            lines.append(f"callgrind: numba kernel {ir_peer:,.0f} instructions per step (difference of "
                         f"two whole-process counts, the sea-state increments)"
                         + (f"; peer/core: " + ", ".join(parts) if parts else ""))
            for n_, v in irs.items():
                if v:
                    fig[f"ratio_ir_numba_kernel_vs_{n_}"] = ir_peer / v
        else:
            lines.append(f"callgrind: numba kernel not measured: {why_peer}")
    if "numba" in info:
        i = info["numba"]
        lines.append(f"peer: python-ins {i['python_ins_version']}, numba {i['numba_version']}, "
                     f"start + JIT {i['startup_and_jit_s']:.1f} s; sanity after {i['steps']} steps: "
                     f"position drift {i['final_position_drift_m']:.1f} m, speed "
                     f"{i['final_speed_mps']:.3f} m/s, Integrator == kernel: "
                     f"{i['integrator_equals_kernel']}")
    return fig, lines


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                 epilog=__doc__[__doc__.index("Peers (optional"):],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--json", default=str(ROOT / "runs" / "bench" / "strapdown.json"),
                    help="where to write the figures as JSON")
    ap.add_argument("--hours", type=float, default=0.5,
                    help="ship time of the data set (default 0.5 h = 180,000 ticks)")
    ap.add_argument("--ref-seconds", type=float, default=60.0,
                    help="ship time the NumPy reference is timed on")
    ap.add_argument("--rounds", type=int, default=7, help="interleaved rounds (default 7)")
    ap.add_argument("--repeat", type=int, default=3,
                    help="back-to-back runs of each engine per round, the fastest kept (default 3)")
    ap.add_argument("--peer", action="append", choices=["numba"],
                    help="time this peer in the rounds (nmayorov/pyins numba kernel)")
    ap.add_argument("--psins", metavar="DIR",
                    help="directory with a PSINS build exposing psins_bench (see below)")
    ap.add_argument("--peer-callgrind", action="store_true",
                    help="also count the numba kernel's instructions per step under callgrind "
                         "(slow: 3 min idle, 8 min at load 3 on a 2-core machine)")
    ap.add_argument("--no-integrator", action="store_true",
                    help="time only the numba kernel, not python-ins Integrator.integrate")
    args = ap.parse_args(argv)
    if args.rounds < 1 or args.repeat < 1:
        ap.error("--rounds and --repeat: at least 1")

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

    # 5. instructions per step, inside the API function (callgrind)
    why_build = build_bench_step()
    irs = {}
    for api in BENCH_STEP_API:
        irs[api] = (None, why_build) if why_build else callgrind_ir_per_step(api=api)
    ir, why = irs["step"]

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
        "callgrind_ir_per_step_pyins_run_null_outputs": irs["null"][0],
        "callgrind_ir_per_step_pyins_run_decimated_100": irs["every100"][0],
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
    print(f"callgrind (tools/bench_step.c, nav): instructions per step: "
          + ", ".join(f"{BENCH_STEP_API[a]}{'' if a == 'step' else ' ' + a} "
                      + (f"{v:,.0f}" if v else f"n/a ({w})") for a, (v, w) in irs.items()))
    print(flush=True)

    # 6. interleaved rounds beside the peers
    args.core_ir = {"core_null_outputs": irs["null"][0], "core_every_100": irs["every100"][0],
                    "core_every_tick": irs["step"][0]}
    side, lines = interleaved(args, cfg, samples, dtheta, dv, st0)
    fig.update(side)
    print("\n".join(lines))

    os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
    with open(args.json, "w") as f:
        json.dump(fig, f, indent=2)
    print(f"figures written to {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
