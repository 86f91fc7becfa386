"""Run records on disk: what a closed-loop run streams, checkpoints and leaves.

A record directory (``fil.run_fil(record_dir=...)``) holds::

    outputs.bin       the firmware's decimated records, raw native.OUTPUT_DTYPE
    plant.bin         the plant's at the same ticks, raw PLANT_RECORD_DTYPE
    records.json      what the two files hold: dtypes, interval, ticks done
    checkpoint.json   the last checkpoint (firmware, plant, noise generator)

A variant directory of a run (``pyins.runs``) adds ``timeseries.npz`` and
``timeseries.csv``: the records beside their errors against the truth.

Every file that a kill may interrupt is written through a temporary file
and a rename (`write_atomic`), so a kill at any moment leaves the old file
or the new one.
"""
import hashlib
import json
import os
from dataclasses import dataclass

import numpy as np

from pyins import metrics, native, sim
from pyins.units import ARCSEC_TO_RAD

#: The plant's record at each kept tick: true table angle, rate, encoder.
PLANT_RECORD_DTYPE = np.dtype([("tick", "<i8"), ("alpha_rad", "<f8"), ("rate_rad_s", "<f8"),
                               ("encoder_rad", "<f8")])
RECORDS = "records.json"
CHECKPOINT = "checkpoint.json"
CHECKPOINT_VERSION = 1
CSV_MAX_ROWS = 20_000
_SINKS = (("outputs.bin", native.OUTPUT_DTYPE), ("plant.bin", PLANT_RECORD_DTYPE))


@dataclass
class FilResult:
    """The records of a closed-loop run beside the truth."""
    outputs: np.ndarray       #: firmware OUTPUT_DTYPE records at the kept ticks
    plant: np.ndarray         #: PLANT_RECORD_DTYPE: true table angle, rate, encoder
    truth: sim.Truth          #: the ship's true state at the kept ticks
    dt: float


def write_atomic(path, text):
    """Write ``text`` to ``path`` through a temporary file and a rename, so a
    kill at any moment leaves either the old file or the new one."""
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


# ---------------------------------------------------------------------------
# The record directory
# ---------------------------------------------------------------------------
def write_records_json(record_dir, every, dt, duration_ticks, done):
    """records.json: the dtypes of the two files and how far the run got."""
    write_atomic(os.path.join(record_dir, RECORDS), json.dumps(
        {"outputs.bin": str(native.OUTPUT_DTYPE.descr), "plant.bin": str(PLANT_RECORD_DTYPE.descr),
         "every_ticks": every, "dt_s": dt, "ticks": int(duration_ticks), "ticks_done": int(done),
         "complete": bool(done >= duration_ticks)}, indent=2))


def load_records(record_dir):
    """The records a run streamed to ``record_dir`` (complete or not), memory-
    mapped, cut to the last checkpointed or completed tick: (outputs, plant,
    info) with info the records.json dict."""
    with open(os.path.join(record_dir, RECORDS)) as f:
        info = json.load(f)
    ck = os.path.join(record_dir, CHECKPOINT)
    n = None
    if os.path.exists(ck) and not info.get("complete"):
        with open(ck) as f:
            n = json.load(f)["n_records"]
    arrays = []
    for name, dtype in _SINKS:
        path = os.path.join(record_dir, name)
        count = os.path.getsize(path) // dtype.itemsize
        count = count if n is None else min(n, count)
        arrays.append(np.memmap(path, dtype=dtype, mode="r", shape=(count,)) if count
                      else np.zeros(0, dtype=dtype))
    return arrays[0], arrays[1], info


class RecordSink:
    """outputs.bin and plant.bin open for appending after ``n_records``
    records (what was written after them, past a checkpoint, is cut off)."""

    def __init__(self, record_dir, n_records, mode):
        self.n_records = n_records
        self.files = tuple(open(os.path.join(record_dir, name), mode) for name, _ in _SINKS)
        for f, (_, dtype) in zip(self.files, _SINKS):
            f.truncate(n_records * dtype.itemsize)     # drop what was written after the checkpoint
            f.seek(n_records * dtype.itemsize)

    def write(self, outputs, plant):
        self.files[0].write(outputs.tobytes())
        self.files[1].write(plant.tobytes())
        self.n_records += len(outputs)

    def sync(self):
        """Flush both files to disk (before a checkpoint names them)."""
        for f in self.files:
            f.flush()
            os.fsync(f.fileno())

    def close(self):
        for f in self.files:
            f.close()


# ---------------------------------------------------------------------------
# Checkpoints
# ---------------------------------------------------------------------------
def run_digest(motion, duration_ticks, cfg, errors, seed, table, every, chunk_ticks, dt, nodes,
               engine="native"):
    """What a checkpoint must match to be resumed: everything that decides
    the records, the engine that wrote it included (a checkpoint of another
    run is refused, never mixed in)."""
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
    what = dict(motion=type(motion).__name__, motion_state=motion, ticks=int(duration_ticks), cfg=cfg,
                errors=errors, seed=seed, table=table, every=every, chunk=chunk_ticks, dt=dt, nodes=nodes)
    if engine != "native":       # the native engine's digests are those of the runs before the choice
        what["engine"] = engine
    blob = json.dumps(plain(what), sort_keys=True, default=repr)
    return hashlib.sha256(blob.encode()).hexdigest()


def read_checkpoint(path, digest):
    """The checkpoint at ``path`` as a dict (firmware and plant as bytes),
    ValueError if it belongs to another run."""
    with open(path) as f:
        ck = json.load(f)
    if ck.get("version") != CHECKPOINT_VERSION or ck.get("run_digest") != digest:
        raise ValueError(f"{path}: the checkpoint belongs to another run (motion, errors, "
                         "seed, configuration or chunking differ); remove it or use another "
                         "record_dir")
    ck["firmware"], ck["plant"] = bytes.fromhex(ck["firmware"]), bytes.fromhex(ck["plant"])
    return ck


def write_checkpoint(path, digest, done, n_records, firmware, plant, rng_state):
    """checkpoint.json: the firmware snapshot and plant state (bytes), the
    noise generator's state, ticks done and records written."""
    write_atomic(path, json.dumps(dict(
        version=CHECKPOINT_VERSION, run_digest=digest, done_ticks=done, n_records=n_records,
        firmware=firmware.hex(), plant=plant.hex(), rng=rng_state)))


# ---------------------------------------------------------------------------
# A run's variant directory
# ---------------------------------------------------------------------------
def write_timeseries(vdir, res):
    """timeseries.npz (every record and its errors) and timeseries.csv (the
    errors, at most CSV_MAX_ROWS rows) of a FilResult."""
    e = metrics.nav_errors(res)
    out = np.asarray(res.outputs)
    np.savez(os.path.join(vdir, "timeseries.npz"), time_s=e.time_s, north_m=e.north_m, east_m=e.east_m,
             horizontal_m=e.horizontal_m, vel_err_n_mps=e.vel_n_mps, att_err_n_rad=e.att_n_rad,
             outputs=out, plant=np.asarray(res.plant))
    step = max(1, -(-len(out) // CSV_MAX_ROWS))
    k = np.arange(0, len(out), step)
    cols = np.column_stack([e.time_s[k], e.north_m[k], e.east_m[k], e.horizontal_m[k],
                            e.vel_n_mps[k], e.att_n_rad[k] / ARCSEC_TO_RAD,
                            out["table_angle_rad"][k], out["yaw_p_rad"][k], out["mode"][k]])
    np.savetxt(os.path.join(vdir, "timeseries.csv"), cols, delimiter=",", fmt="%.10g",
               header="time_s,north_m,east_m,horizontal_m,vel_err_e_mps,vel_err_n_mps,vel_err_u_mps,"
                      "att_err_e_arcsec,att_err_n_arcsec,att_err_u_arcsec,table_angle_rad,yaw_p_rad,mode",
               comments="")


def load_variant(record_dir, motion, dt):
    """The records in ``record_dir`` (complete or partial) beside the truth
    of ``motion``: (FilResult, records.json info), or (None, None) when the
    run wrote nothing."""
    if not os.path.exists(os.path.join(record_dir, RECORDS)):
        return None, None
    outputs, plant, info = load_records(record_dir)
    truth = sim.truth_at(motion, np.asarray(outputs["tick"]), dt=dt)
    return FilResult(outputs=outputs, plant=plant, truth=truth, dt=dt), info
