"""Firmware in the loop: the firmware closing the loop through a simulated
turntable, over hours or days of ship time.

The ship's motion is open loop (it does not feel the table): its body rate
and specific force at the quadrature nodes of every tick come from
``pyins.sim`` in NumPy, once per period for periodic profiles (static,
swings, heading swings) or chunk by chunk otherwise. The closed loop itself,
per tick (firmware command -> motor -> table angle inside the tick ->
increments of the turning IMU -> sensor errors -> firmware), runs in the
plant of the engine (`pyins.engine`): the compiled one (``csrc/plant``,
`pyins.native.Plant`) or its NumPy mirror (``pyins.sim.turntable``). Only
decimated records (every ``every`` ticks) come back, so memory stays bounded
for any duration; with a record directory they stream to disk
(`pyins.records`) and the run checkpoints and resumes.

External references (GNSS position and velocity, zero velocity) reach the
firmware through ``push_ref`` between plant calls: a chunk is split at the
ticks where the next reference must be pushed (`pyins.aiding.Aider`, the
open loop's rule: at its availability tick, or up to 5 s ahead of its tick,
at most 8 waiting in the firmware's queue), one plant call per refill of
the queue.

`run_fil` is a guarded prefix (what cannot run is refused before anything
starts), then named steps:

1. the loop's parts: the initial state, the firmware, the plant, the noise;
2. the record directory: a fresh one, or the state of its last checkpoint;
3. chunk by chunk: the ship's rates, the noise, the closed loop (split where
   references are pushed), the records;
4. a checkpoint when one is due;
5. the result, the records beside the truth.
"""
import hashlib
import math
import os
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from pyins import engine as engines
from pyins import contract, records, sim
from pyins.aiding import Aider, concat
from pyins.records import CHECKPOINT, PLANT_RECORD_DTYPE, FilResult, load_records
from pyins.scenario.build import initial_config
from pyins.sim.turntable import TableConfig, error_matrices
from pyins.units import DT

__all__ = ["run_fil"]

#: Ticks of normals drawn at a time into the noise's scratch buffer (2.4 MB).
NOISE_BLOCK = 50_000
#: Ticks per chunk (run_fil's default): the noise of two chunks is held
#: (this one's and the next's, drawn ahead), 4 x 3 doubles a tick: 9.6 MB at
#: 100,000 ticks (48 MB at 500,000, which took a 72 h run to 111 MiB peak
#: with 60-s records against 75 MiB). The records do not depend on it, bit
#: for bit (tests/physics/test_fil.py).
CHUNK_TICKS = 100_000


class _Loop:
    """The parts of one closed-loop run and where it stands."""

    def __init__(self, motion, cfg, errors, seed, table, dt, nodes, engine):
        self.motion, self.errors, self.dt, self.nodes = motion, errors, dt, nodes
        self.fw = engines.firmware(engine, cfg)
        self.plant = engines.plant(engine, table, error_matrices(errors), PLANT_RECORD_DTYPE,
                                   cfg.get("table_angle_rad", 0.0))
        self.rng = np.random.default_rng(seed)
        self.noisy = errors.gyro_arw > 0.0 or errors.accel_vrw > 0.0
        self.sq = math.sqrt(dt)
        self.period = sim.periodic_ticks(motion, dt)
        if self.period is not None:          # one period of the ship's rates serves every chunk
            self.omega, self.force, self.x, self.w = sim.node_rates(motion, np.arange(self.period), dt=dt,
                                                                    nodes=nodes)
            # and their weighted sums, what a tick with the table at rest takes (the same bits)
            self.sums = sim.node_sums(self.omega, self.force, self.w)
        else:
            self.sums = None
        self.done = 0
        self.bufs, self.slot, self.z = None, 1, None     # the noise's buffers (noise)

    def ship_rates(self, n):
        """(omega, force, x, w, period, phase0) of the next ``n`` ticks."""
        if self.period is None:
            omega, force, x, w = sim.node_rates(self.motion, np.arange(self.done, self.done + n),
                                                dt=self.dt, nodes=self.nodes)
            return omega, force, x, w, n, 0
        return self.omega, self.force, self.x, self.w, self.period, self.done % self.period

    def noise(self, n):
        """The white-noise increments of the next ``n`` ticks (gyro, accel), drawn
        as pyins.sim.SensorModel draws them (None, None without noise),
        and the generator's state after the draw (what a checkpoint after
        these ticks keeps). The normals go into one of two buffers kept for
        the run (a fresh array per chunk would cost as much in page faults as
        the draw), so a result is valid until the next call but one."""
        if not self.noisy:
            return None, None, None
        self.slot = 1 - self.slot
        if self.bufs is None or self.bufs[0][0].shape[0] < n:
            self.bufs = [(np.empty((n, 3)), np.empty((n, 3))) for _ in range(2)]
            self.z = np.empty((NOISE_BLOCK, 6))
        g, a = (b[:n] for b in self.bufs[self.slot])
        for i in range(0, n, NOISE_BLOCK):       # block by block: the same stream of draws
            m = min(NOISE_BLOCK, n - i)
            z = self.z[:m]
            self.rng.standard_normal(out=z)
            np.multiply(self.errors.gyro_arw * self.sq, z[:, :3], out=g[i:i + m])
            np.multiply(self.errors.accel_vrw * self.sq, z[:, 3:], out=a[i:i + m])
        return g, a, self.rng.bit_generator.state


class _Stopped(Exception):
    """A chunk cut short by a rejected sample or reference: the records
    before it and the error to raise."""

    def __init__(self, exc, outputs, records):
        super().__init__(str(exc))
        self.exc, self.outputs, self.records = exc, outputs, records


def _closed_loop(loop, aider, tick0, omega, force, x, w, period, phase0, g_noise, a_noise, n, every):
    """The next ``n`` ticks of the closed loop: (outputs, plant records).
    Without references one plant call; with them the chunk is split at the
    ticks the Aider names (`Aider.next_stop`), the references due pushed
    between the calls and at the chunk's end (so a checkpoint after it holds
    them in the firmware's queue, as `Aider.seek` assumes)."""
    if aider is None:
        try:
            return loop.plant.run(loop.fw, omega, force, x, w, period, phase0, g_noise, a_noise, n,
                                  loop.dt, every, sums=loop.sums)
        except contract.PlantError as exc:
            raise _Stopped(exc, exc.outputs, exc.records) from None
    now0 = tick0 + loop.done
    outs, recs, i = [], [], 0
    try:
        while True:
            aider.push_due(loop.fw, now0 + i)
            if i >= n:
                break
            nxt = aider.next_stop(now0 + i)
            stop = n if nxt is None else min(n, nxt - now0)
            if loop.period is None:         # this chunk's rates: the part's own
                part = (omega[i:stop], force[i:stop], x, w, stop - i, 0)
            else:                           # one period tiled: the part's phase in it
                part = (omega, force, x, w, period, (phase0 + i) % period)
            out, rec = loop.plant.run(loop.fw, *part,
                                      None if g_noise is None else g_noise[i:stop],
                                      None if a_noise is None else a_noise[i:stop],
                                      stop - i, loop.dt, every, sums=loop.sums)
            outs.append(out)
            recs.append(rec)
            i = stop
    except contract.PlantError as exc:      # the chunk's: its records and ticks before the sample
        outs.append(exc.outputs)
        recs.append(exc.records)
        out, rec = _joined(outs, recs)
        where = str(exc)[:-len(contract.status_str(exc.code)) - 2]     # "pyins_fil_run at tick T"
        raise _Stopped(contract.PlantError(exc.code, where, i + exc.n_done, out, rec), out, rec) from None
    except contract.RefError as exc:
        raise _Stopped(exc, *_joined(outs, recs)) from None
    return _joined(outs, recs)


def _joined(outs, recs):
    """The parts of a chunk as one array each (a single part as it is)."""
    return concat(outs, contract.OUTPUT_DTYPE), concat(recs, PLANT_RECORD_DTYPE)


def run_fil(motion, duration_ticks, config=None, errors=None, seed=0, table=None, every=100,
            chunk_ticks=CHUNK_TICKS, dt=DT, nodes=5, progress=None, record_dir=None,
            checkpoint_ticks=None, resume=False, engine="native", refs=None, avail_tick=None,
            keep_result=True, checkpoint_wall_s=None, draw_ahead=True):
    """Run the closed loop for ``duration_ticks``.

    ``config``: firmware configuration overrides (default: the true initial
    state, table at 0, no alignment, no indexing); ``errors``: a
    ``pyins.sim.SensorErrors`` (None: error-free) with noise drawn from
    ``seed`` exactly as ``pyins.sim.SensorModel`` draws it; ``table``: a
    ``TableConfig``; ``engine``: "native" (the compiled firmware and plant)
    or "reference" (their NumPy mirrors, `pyins.engine`).
    ``progress(done_ticks, total_ticks)`` is called after every chunk
    (``pyins.progress.TextProgress()`` draws a bar). With ``record_dir`` the decimated
    records are streamed to ``outputs.bin`` and ``plant.bin`` there (raw
    OUTPUT_DTYPE / PLANT_RECORD_DTYPE, described in ``records.json``) chunk
    by chunk and returned memory-mapped, so memory stays bounded for any
    duration. Returns a FilResult; with a record directory and
    ``keep_result=False``, None (the records are on disk; the truth beside
    them is not computed: `pyins.records.score_variant` reads them back).

    ``refs`` (REF_DTYPE, sorted by tick; e.g. ``pyins.sim.references.gnss(...)
    .refs``) are external references pushed as they become available, as
    `pyins.open_loop.navigate` pushes them (`pyins.aiding.Aider`):
    ``avail_tick`` (one per reference, >= its tick) the tick at which each
    reaches the firmware, None to push each up to 5 s ahead of its tick (the
    firmware applies it at exactly its tick). A reference the firmware
    refuses raises contract.RefError with its index in ``refs`` (the records
    before it are kept, as at a rejected sample).

    ``draw_ahead``: draw the next chunk's noise on a helper thread while
    this chunk's loop runs (a run then keeps about 1.6 cores busy); False
    draws it in the loop's own thread just before the chunk (one core; what
    a pool with a worker per core may prefer). The same draws either way.

    Checkpoints (need ``record_dir``): every ``checkpoint_ticks`` (rounded up
    to whole chunks; with ``checkpoint_wall_s``, also at least that many
    seconds of wall time after the last one; always at the end) the firmware
    snapshot, the plant state, the noise generator's state and the number of
    records written go to ``checkpoint.json`` (temporary file + rename,
    after the records are flushed to disk). With ``resume=True`` a run
    killed at any moment continues from its last checkpoint: the records written after it are cut
    off and recomputed, and the result is bit-identical to an uninterrupted
    run (with references too: which ones were pushed by a tick is a function
    of the tick, `Aider.seek`, and the firmware's snapshot holds its queue).
    A checkpoint of a different run (other motion, errors, seed,
    configuration, chunking, references or their availability) is refused
    with ValueError. The plant state is
    stored as raw bytes: resume on the machine kind that wrote it.
    """
    # the guarded prefix
    if (checkpoint_ticks is not None or resume) and record_dir is None:
        raise ValueError("run_fil: checkpoint_ticks and resume need record_dir")
    if checkpoint_ticks is not None and checkpoint_ticks <= 0:
        raise ValueError(f"run_fil: checkpoint_ticks must be > 0, got {checkpoint_ticks}")
    if checkpoint_wall_s is not None and not checkpoint_wall_s >= 0.0:
        raise ValueError(f"run_fil: checkpoint_wall_s must be >= 0, got {checkpoint_wall_s}")
    engines.check(engine)
    if engine == "native" and engines.native is not None and engines.native.plant is None:
        raise RuntimeError("the plant library libpyins_plant.so is not installed; run `pip install .`")

    # 1. the loop's parts
    errors = errors if errors is not None else sim.SensorErrors()
    table = table if table is not None else TableConfig()
    cfg = initial_config(motion, None, **(config or {}))
    loop = _Loop(motion, cfg, errors, seed, table, dt, nodes, engine)
    aider = Aider(refs, avail_tick, tick_hz=int(round(1.0 / dt))) if refs is not None else None
    tick0 = int(loop.fw.nav()["tick"])      # the firmware's tick at loop.done == 0

    # 2. the record directory, fresh or from its last checkpoint
    sink = None
    # without a record directory the records collect in arrays of the run's
    # size (one copy of each chunk's, none at the end)
    outs, recs, kept = None, None, 0
    if record_dir is not None:
        os.makedirs(record_dir, exist_ok=True)
        digest = records.run_digest(motion, duration_ticks, cfg, errors, seed, table, every,
                                    chunk_ticks, dt, nodes, engine)
        if aider is not None and len(aider.refs):     # no references: the digest of the runs before them
            digest = hashlib.sha256(f"{digest}+refs:{aider.identity()}".encode()).hexdigest()
        ck_path = os.path.join(record_dir, CHECKPOINT)
        n_records, mode = 0, "wb"
        if resume and os.path.exists(ck_path):
            ck = records.read_checkpoint(ck_path, digest)
            loop.fw.restore(ck["firmware"])
            loop.plant.restore(ck["plant"])
            loop.rng.bit_generator.state = ck["rng"]
            loop.done, n_records = ck["done_ticks"], ck["n_records"]
            if aider is not None:
                aider.seek(tick0, tick0 + loop.done)
            mode = "r+b"
        sink = records.RecordSink(record_dir, n_records, mode)
        if mode == "wb" and os.path.exists(ck_path):
            os.remove(ck_path)
        last_ck, last_ck_wall = loop.done, time.monotonic()

    # 3. chunk by chunk: the ship's rates, the noise, the closed loop, the
    #    records. The next chunk's noise is drawn on a helper thread while
    #    this chunk's loop runs (both release the GIL): the same draws in the
    #    same order as one after the other.
    ahead = ThreadPoolExecutor(max_workers=1) if draw_ahead else None
    try:
        pending = (ahead.submit(loop.noise, min(chunk_ticks, duration_ticks - loop.done))
                   if ahead is not None and loop.done < duration_ticks else None)
        while loop.done < duration_ticks:
            n = min(chunk_ticks, duration_ticks - loop.done)
            omega, force, x, w, period, phase0 = loop.ship_rates(n)
            if ahead is None:
                g_noise, a_noise, rng_state = loop.noise(n)
            else:
                g_noise, a_noise, rng_state = pending.result()
                n_next = min(chunk_ticks, duration_ticks - loop.done - n)
                pending = ahead.submit(loop.noise, n_next) if n_next > 0 else None
            try:
                out, rec = _closed_loop(loop, aider, tick0, omega, force, x, w, period, phase0,
                                        g_noise, a_noise, n, every)
            except _Stopped as stop:       # keep what was done before the rejected sample or reference
                if sink is not None:
                    sink.write(stop.outputs, stop.records)
                    sink.close()
                raise stop.exc from None
            if sink is not None:
                sink.write(out, rec)
            else:
                if outs is None:
                    cap = (duration_ticks - loop.done) // every + 1
                    outs, recs = np.empty(cap, dtype=out.dtype), np.empty(cap, dtype=rec.dtype)
                outs[kept:kept + len(out)] = out
                recs[kept:kept + len(rec)] = rec
                kept += len(out)
            loop.done += n

            # 4. a checkpoint when one is due (and at the end)
            if sink is not None and (loop.done >= duration_ticks or
                                     (checkpoint_ticks is not None and loop.done - last_ck >= checkpoint_ticks
                                      and (checkpoint_wall_s is None
                                           or time.monotonic() - last_ck_wall >= checkpoint_wall_s))):
                sink.sync()
                if checkpoint_ticks is not None or resume:
                    records.write_checkpoint(ck_path, digest, loop.done, sink.n_records, loop.fw.snapshot(),
                                             loop.plant.snapshot(),
                                             rng_state if rng_state is not None else loop.rng.bit_generator.state)
                records.write_records_json(record_dir, every, dt, duration_ticks, loop.done)
                last_ck, last_ck_wall = loop.done, time.monotonic()
            if progress is not None:
                progress(loop.done, duration_ticks)
    finally:
        if ahead is not None:
            ahead.shutdown(wait=True, cancel_futures=True)

    # 5. the result: the records beside the truth
    if sink is not None:
        sink.close()
        if loop.done >= duration_ticks and not os.path.exists(os.path.join(record_dir, records.RECORDS)):
            records.write_records_json(record_dir, every, dt, duration_ticks, loop.done)
        if not keep_result:
            return None
        outputs, plant, _ = load_records(record_dir)
    else:
        outputs = outs[:kept] if outs is not None else np.empty(0, dtype=contract.OUTPUT_DTYPE)
        plant = recs[:kept] if recs is not None else np.empty(0, dtype=PLANT_RECORD_DTYPE)
    truth = sim.truth_at(motion, np.asarray(outputs["tick"]), dt=dt)
    return FilResult(outputs=outputs, plant=plant, truth=truth, dt=dt)
