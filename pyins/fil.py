"""Firmware-in-the-loop runs: the C++ firmware closing the loop through a
simulated turntable, over hours or days of ship time.

The ship's motion is open loop (it does not feel the table): its body rate
and specific force at the quadrature nodes of every tick come from
``pyins.sim`` in NumPy, once per period for periodic profiles (static,
swings, heading swings) or chunk by chunk otherwise. The closed loop itself,
per tick (firmware command -> motor -> table angle inside the tick ->
increments of the turning IMU -> sensor errors -> firmware), runs in the
compiled plant (``csrc/plant``, mirrored by ``pyins.sim.turntable``). Only
decimated records (every ``every`` ticks) come back, so memory stays bounded
for any duration.
"""
import hashlib
import json
import math
import os
import sys
import time
from dataclasses import dataclass

import numpy as np

from pyins import native, runner, sim
from pyins.sim.turntable import TableConfig, error_matrices


@dataclass
class FilResult:
    outputs: np.ndarray       #: firmware OUTPUT_DTYPE records at the kept ticks
    plant: np.ndarray         #: PLANT_RECORD_DTYPE: true table angle, rate, encoder
    truth: sim.Truth          #: the ship's true state at the kept ticks
    dt: float


PLANT_RECORD_DTYPE = np.dtype([("tick", "<i8"), ("alpha_rad", "<f8"), ("rate_rad_s", "<f8"),
                               ("encoder_rad", "<f8")])


class TextProgress:
    """A one-line progress bar on stderr: ship time done, ticks per second,
    time left. Silent when stderr is not a terminal (CI, pipes)."""

    def __init__(self, dt=0.01, stream=None, width=30):
        self.dt, self.width = dt, width
        self.stream = stream if stream is not None else sys.stderr
        self.t0 = time.perf_counter()
        self.active = hasattr(self.stream, "isatty") and self.stream.isatty()

    def __call__(self, done, total):
        if not self.active:
            return
        el = time.perf_counter() - self.t0
        rate = done / el if el > 0 else 0.0
        left = (total - done) / rate if rate > 0 else float("nan")
        n = int(self.width * done / total)
        self.stream.write(f"\r[{'#' * n}{'.' * (self.width - n)}] {done * self.dt / 3600:.2f}/"
                          f"{total * self.dt / 3600:.2f} h ship time, {rate / 1e6:.2f} M ticks/s, "
                          f"{left:.0f} s left ")
        if done >= total:
            self.stream.write("\n")
        self.stream.flush()


def periodic_ticks(motion, dt, limit=2_000_000):
    """Ticks after which the ship's body rate and force repeat exactly, or
    None. Static: 1. Swings: the least common multiple of each active
    frequency's whole-tick period (at most 1000 cycles). A ShipAtSea: the
    same over the base swing's and the linear motion's frequencies (1 when
    nothing moves)."""
    if isinstance(motion, sim.Static):
        return 1
    if isinstance(motion, sim.ShipAtSea):
        freqs = motion.frequencies_hz
    elif isinstance(motion, sim.Swing):
        freqs = [f for amp, f in zip(motion.amplitude, motion.frequency_hz)
                 if amp != 0.0 and f != 0.0]
    else:
        return None
    period = 1
    for f in freqs:
        ticks_per_cycle = 1.0 / (f * dt)
        for cycles in range(1, 1001):
            p = cycles * ticks_per_cycle
            if abs(p - round(p)) < 1e-9 * p:
                break
        else:
            return None
        period = math.lcm(period, int(round(p)))
        if period > limit:
            return None
    return period


def _errors_struct(errors):
    e = native.ffi.new("pyins_imu_errors *")
    m = error_matrices(errors)
    for i in range(9):
        e.gyro_m[i] = m["gyro_m"].ravel()[i]
        e.accel_m[i] = m["accel_m"].ravel()[i]
    for i in range(3):
        e.gyro_bias_rad_s[i] = m["gyro_bias"][i]
        e.accel_bias_mps2[i] = m["accel_bias"][i]
    e.gyro_quantum_rad = m["gyro_quantum"]
    e.accel_quantum_mps = m["accel_quantum"]
    return e


def _table_struct(table):
    t = native.ffi.new("pyins_table_config *")
    t.rate_max_rad_s, t.accel_max_rad_s2 = table.rate_max_rad_s, table.accel_max_rad_s2
    t.encoder_lsb_rad, t.jump_rad = table.encoder_lsb_rad, table.jump_rad
    t.fault_tick, t.fault = table.fault_tick, table.fault
    return t


CHECKPOINT = "checkpoint.json"
CHECKPOINT_VERSION = 1


def _run_digest(motion, duration_ticks, cfg, errors, seed, table, every, chunk_ticks, dt, nodes):
    """What a checkpoint must match to be resumed: everything that decides
    the records (a checkpoint of another run is refused, never mixed in)."""
    def plain(v):
        if isinstance(v, np.ndarray):
            return hashlib.sha256(np.ascontiguousarray(v).tobytes()).hexdigest() + str(v.shape)
        if isinstance(v, dict):
            return {k: plain(x) for k, x in sorted(v.items())}
        if isinstance(v, (list, tuple)):
            return [plain(x) for x in v]
        if hasattr(v, "__dict__"):      # public attributes only: caches filled later are private
            return {k: plain(x) for k, x in sorted(vars(v).items()) if not k.startswith("_")}
        return v if isinstance(v, (int, float, str, bool, type(None))) else repr(v)
    blob = json.dumps(plain(dict(motion=type(motion).__name__, motion_state=motion,
                                 ticks=int(duration_ticks), cfg=cfg, errors=errors, seed=seed,
                                 table=table, every=every, chunk=chunk_ticks, dt=dt, nodes=nodes)),
                      sort_keys=True, default=repr)
    return hashlib.sha256(blob.encode()).hexdigest()


def _write_atomic(path, text):
    """Write ``text`` to ``path`` through a temporary file and a rename, so a
    kill at any moment leaves either the old file or the new one."""
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


def _records_json(record_dir, every, dt, duration_ticks, done):
    _write_atomic(os.path.join(record_dir, "records.json"), json.dumps(
        {"outputs.bin": str(native.OUTPUT_DTYPE.descr), "plant.bin": str(PLANT_RECORD_DTYPE.descr),
         "every_ticks": every, "dt_s": dt, "ticks": int(duration_ticks), "ticks_done": int(done),
         "complete": bool(done >= duration_ticks)}, indent=2))


def load_records(record_dir):
    """The records a run streamed to ``record_dir`` (complete or not), memory-
    mapped, cut to the last checkpointed or completed tick: (outputs, plant,
    info) with info the records.json dict."""
    with open(os.path.join(record_dir, "records.json")) as f:
        info = json.load(f)
    ck = os.path.join(record_dir, CHECKPOINT)
    n = None
    if os.path.exists(ck) and not info.get("complete"):
        with open(ck) as f:
            n = json.load(f)["n_records"]
    arrays = []
    for name, dtype in (("outputs.bin", native.OUTPUT_DTYPE), ("plant.bin", PLANT_RECORD_DTYPE)):
        path = os.path.join(record_dir, name)
        count = os.path.getsize(path) // dtype.itemsize
        count = count if n is None else min(n, count)
        arrays.append(np.memmap(path, dtype=dtype, mode="r", shape=(count,)) if count
                      else np.zeros(0, dtype=dtype))
    return arrays[0], arrays[1], info


def run_fil(motion, duration_ticks, config=None, errors=None, seed=0, table=None, every=100,
            chunk_ticks=500_000, dt=0.01, nodes=5, progress=None, record_dir=None,
            checkpoint_ticks=None, resume=False):
    """Run the closed loop for ``duration_ticks``.

    ``config``: firmware configuration overrides (default: the true initial
    state, table at 0, no alignment, no indexing); ``errors``: a
    ``pyins.sim.SensorErrors`` (None: error-free) with noise drawn from
    ``seed`` exactly as ``pyins.sim.SensorModel`` draws it; ``table``: a
    ``TableConfig``. ``progress(done_ticks, total_ticks)`` is called after
    every chunk (``TextProgress()`` draws a bar). With ``record_dir`` the
    decimated records are streamed to ``outputs.bin`` and ``plant.bin`` there
    (raw OUTPUT_DTYPE / PLANT_RECORD_DTYPE, described in ``records.json``)
    chunk by chunk and returned memory-mapped, so memory stays bounded for
    any duration. Returns a FilResult.

    Checkpoints (need ``record_dir``): every ``checkpoint_ticks`` (rounded up
    to whole chunks) the firmware snapshot, the plant state, the noise
    generator's state and the number of records written go to
    ``checkpoint.json`` (temporary file + rename, after the records are
    flushed to disk). With ``resume=True`` a run killed at any moment
    continues from its last checkpoint: the records written after it are cut
    off and recomputed, and the result is bit-identical to an uninterrupted
    run. A checkpoint of a different run (other motion, errors, seed,
    configuration, chunking) is refused with ValueError. The plant state is
    stored as raw bytes: resume on the machine kind that wrote it.
    """
    if (checkpoint_ticks is not None or resume) and record_dir is None:
        raise ValueError("run_fil: checkpoint_ticks and resume need record_dir")
    if checkpoint_ticks is not None and checkpoint_ticks <= 0:
        raise ValueError(f"run_fil: checkpoint_ticks must be > 0, got {checkpoint_ticks}")
    if native.plant is None:
        raise RuntimeError("the plant library libpyins_plant.so is not installed; run `pip install .`")
    ffi = native.ffi
    errors = errors if errors is not None else sim.SensorErrors()
    table = table if table is not None else TableConfig()
    cfg = runner.initial_config(motion, None, **(config or {}))
    fw = native.Firmware(cfg)
    st = ffi.new("pyins_plant_state *")
    st.alpha_rad = cfg.get("table_angle_rad", 0.0)
    err_c = _errors_struct(errors)
    tab_c = _table_struct(table)
    rng = np.random.default_rng(seed)
    noisy = errors.gyro_arw > 0.0 or errors.accel_vrw > 0.0
    sq = math.sqrt(dt)

    period = periodic_ticks(motion, dt)
    if period is not None:
        omega, force, x, w = sim.node_rates(motion, np.arange(period), dt=dt, nodes=nodes)
        omega, force = np.ascontiguousarray(omega), np.ascontiguousarray(force)
    x_c = w_c = None
    outs, recs = [], []
    sinks = None
    done = 0
    n_records = 0
    if record_dir is not None:
        os.makedirs(record_dir, exist_ok=True)
        digest = _run_digest(motion, duration_ticks, cfg, errors, seed, table, every, chunk_ticks,
                             dt, nodes)
        ck_path = os.path.join(record_dir, CHECKPOINT)
        mode = "wb"
        if resume and os.path.exists(ck_path):
            with open(ck_path) as f:
                ck = json.load(f)
            if ck.get("version") != CHECKPOINT_VERSION or ck.get("run_digest") != digest:
                raise ValueError(f"{ck_path}: the checkpoint belongs to another run (motion, errors, "
                                 "seed, configuration or chunking differ); remove it or use another "
                                 "record_dir")
            fw.restore(bytes.fromhex(ck["firmware"]))
            ffi.memmove(st, bytes.fromhex(ck["plant"]), ffi.sizeof("pyins_plant_state"))
            rng.bit_generator.state = ck["rng"]
            done, n_records = ck["done_ticks"], ck["n_records"]
            mode = "r+b"
        sinks = (open(os.path.join(record_dir, "outputs.bin"), mode),
                 open(os.path.join(record_dir, "plant.bin"), mode))
        for f, dtype in zip(sinks, (native.OUTPUT_DTYPE, PLANT_RECORD_DTYPE)):
            f.truncate(n_records * dtype.itemsize)     # drop what was written after the checkpoint
            f.seek(n_records * dtype.itemsize)
        if mode == "wb" and os.path.exists(ck_path):
            os.remove(ck_path)
        last_ck = done
    n_done_p = ffi.new("size_t *")
    n_out_p = ffi.new("size_t *")
    while done < duration_ticks:
        n = min(chunk_ticks, duration_ticks - done)
        if period is None:
            omega, force, x, w = sim.node_rates(motion, np.arange(done, done + n), dt=dt, nodes=nodes)
            omega, force = np.ascontiguousarray(omega), np.ascontiguousarray(force)
            per, phase0 = n, 0
        else:
            per, phase0 = period, done % period
        x_c, w_c = np.ascontiguousarray(x), np.ascontiguousarray(w)
        if noisy:
            z = rng.standard_normal((n, 6))
            g_noise = np.ascontiguousarray((errors.gyro_arw * sq) * z[:, :3])
            a_noise = np.ascontiguousarray((errors.accel_vrw * sq) * z[:, 3:])
            g_ptr = ffi.from_buffer("double[]", g_noise)
            a_ptr = ffi.from_buffer("double[]", a_noise)
        else:
            g_ptr = a_ptr = ffi.NULL
        cap = n // every + 1
        out = np.empty(cap, dtype=native.OUTPUT_DTYPE)
        rec = np.empty(cap, dtype=PLANT_RECORD_DTYPE)
        status = native.plant.pyins_fil_run(
            fw.core, st, tab_c, err_c, ffi.from_buffer("double[]", omega), ffi.from_buffer("double[]", force),
            ffi.from_buffer("double[]", x_c), ffi.from_buffer("double[]", w_c), len(x_c), per, phase0,
            g_ptr, a_ptr, n, dt, every, ffi.from_buffer("pyins_output[]", out, require_writable=True),
            ffi.cast("pyins_plant_record *", ffi.from_buffer(rec, require_writable=True)), cap,
            n_done_p, n_out_p)
        if sinks is not None:
            sinks[0].write(out[:n_out_p[0]].tobytes())
            sinks[1].write(rec[:n_out_p[0]].tobytes())
            n_records += n_out_p[0]
        else:
            outs.append(out[:n_out_p[0]].copy())
            recs.append(rec[:n_out_p[0]].copy())
        if status != 0:
            if sinks is not None:
                for f in sinks:
                    f.close()
            raise native.CoreError(status, f"pyins_fil_run at tick {done + n_done_p[0]}")
        done += n
        if sinks is not None and (done >= duration_ticks or
                                  (checkpoint_ticks is not None and done - last_ck >= checkpoint_ticks)):
            for f in sinks:
                f.flush()
                os.fsync(f.fileno())
            if checkpoint_ticks is not None or resume:
                _write_atomic(ck_path, json.dumps(dict(
                    version=CHECKPOINT_VERSION, run_digest=digest, done_ticks=done, n_records=n_records,
                    firmware=fw.snapshot().hex(),
                    plant=bytes(ffi.buffer(st, ffi.sizeof("pyins_plant_state"))).hex(),
                    rng=rng.bit_generator.state)))
            _records_json(record_dir, every, dt, duration_ticks, done)
            last_ck = done
        if progress is not None:
            progress(done, duration_ticks)
    if sinks is not None:
        for f in sinks:
            f.close()
        if done >= duration_ticks and not os.path.exists(os.path.join(record_dir, "records.json")):
            _records_json(record_dir, every, dt, duration_ticks, done)
        outputs, plant, _ = load_records(record_dir)
    else:
        outputs = np.concatenate(outs)
        plant = np.concatenate(recs)
    truth = sim.truth_at(motion, np.asarray(outputs["tick"]), dt=dt)
    return FilResult(outputs=outputs, plant=plant, truth=truth, dt=dt)
