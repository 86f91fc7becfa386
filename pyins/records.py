"""Run records on disk: what a closed-loop run streams, checkpoints and leaves.

A record directory (``fil.run_fil(record_dir=...)``) holds::

    outputs.bin       the firmware's decimated records, raw contract.OUTPUT_DTYPE
    plant.bin         the plant's at the same ticks, raw PLANT_RECORD_DTYPE
    records.json      what the two files hold: dtypes, interval, ticks done
    checkpoint.json   the last checkpoint (firmware, plant, noise generator)

A variant directory of a run (``pyins.rundir``) adds ``timeseries.npz`` and
``timeseries.csv``: the records beside their errors against the truth,
written by `score_variant` from the record files read back in chunks (with
the run's metrics), so memory stays bounded at any record rate.

Every file that a kill may interrupt is written through a temporary file
and a rename (`write_atomic`), so a kill at any moment leaves the old file
or the new one.

A directory being written is locked (`lock_dir`: ``pyins.lock``, a POSIX
record lock on a file naming the holder's pid, host and start time), so a
second writer is refused with the holder's name; the kernel drops the lock
when its process dies, so the lock of a killed run is recognised as stale
and taken over.
"""
import datetime
import errno
import fcntl
import hashlib
import json
import os
import socket
import sys
import zipfile
from dataclasses import dataclass

import numpy as np

from pyins import contract, metrics, sim
from pyins.reference import abi
from pyins.units import ARCSEC_TO_RAD

#: The plant's record at each kept tick: true table angle, rate, encoder.
PLANT_RECORD_DTYPE = np.dtype([("tick", "<i8"), ("alpha_rad", "<f8"), ("rate_rad_s", "<f8"),
                               ("encoder_rad", "<f8")])
RECORDS = "records.json"
CHECKPOINT = "checkpoint.json"
CHECKPOINT_VERSION = 1
CSV_MAX_ROWS = 20_000
#: Records read back at a time when a finished variant is scored (`score_variant`):
#: 3.5 MB of firmware records, whatever the run's length (a 72 h run with 1-s
#: records peaks at 74 MiB with these, as with 60-s records; 120 MiB with 20,000).
CHUNK_RECORDS = 5_000
_SINKS = (("outputs.bin", contract.OUTPUT_DTYPE), ("plant.bin", PLANT_RECORD_DTYPE))


@dataclass
class FilResult:
    """The records of a closed-loop run beside the truth."""
    outputs: np.ndarray       #: firmware OUTPUT_DTYPE records at the kept ticks
    plant: np.ndarray         #: PLANT_RECORD_DTYPE: true table angle, rate, encoder
    truth: sim.Truth          #: the ship's true state at the kept ticks
    dt: float


def write_atomic(path, text=None, write=None, sync=True):
    """Write ``text`` to ``path`` (or call ``write(file)`` on a binary file)
    through a temporary file and a rename, so a kill at any moment leaves
    either the old file or the new one. ``sync``: fsync before the rename
    (what a power cut needs; a kill needs only the rename)."""
    tmp = f"{path}.tmp{os.getpid()}"
    try:
        with open(tmp, "w" if write is None else "wb") as f:
            if write is None:
                f.write(text)
            else:
                write(f)
            f.flush()
            if sync:
                os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


# ---------------------------------------------------------------------------
# The lock of a directory being written
# ---------------------------------------------------------------------------
LOCK = "pyins.lock"


class LockedError(ValueError):
    """The directory is being written by another live process (one line)."""


def _holder_text(info):
    return (f"pid {info.get('pid', '?')} on {info.get('host', '?')}, started {info.get('started', '?')}"
            + (f" ({info['command']})" if info.get("command") else ""))


def is_locked(directory):
    """The holder (a dict) if a live process holds ``directory``'s lock, else
    None. Not for a lock this process holds: closing any descriptor of the
    file drops a POSIX lock of its process."""
    path = os.path.join(directory, LOCK)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_CLOEXEC)
    except OSError:
        return None
    try:
        try:
            # a shared-lock test: F_GETLK through lockf is not offered, so try and drop
            fcntl.lockf(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
        except OSError as exc:
            if exc.errno in (errno.EACCES, errno.EAGAIN):
                data = os.read(fd, 65536)
                try:
                    return json.loads(data.decode() or "null") or {}
                except ValueError:
                    return {}
            return None
        return None
    finally:
        os.close(fd)


class DirLock:
    """A held lock (`lock_dir`); ``release()`` (or the with block) drops it."""

    def __init__(self, fd, path, taken_over):
        self.fd, self.path, self.taken_over = fd, path, taken_over

    def release(self):
        if self.fd is None:
            return
        try:
            if os.path.exists(self.path) and os.stat(self.path).st_ino == os.fstat(self.fd).st_ino:
                os.remove(self.path)
        finally:
            os.close(self.fd)
            self.fd = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.release()


def drop_stale_lock(directory):
    """Remove ``directory``'s lock file if the process that held it is gone
    (a pool worker killed mid-run, or cut short in its release by a second
    Ctrl-C); leave a live holder's. True if a stale lock was removed."""
    if not os.path.exists(os.path.join(directory, LOCK)):
        return False
    try:
        lock_dir(directory).release()       # takes the stale lock over, then removes it
    except LockedError:
        return False
    return True


def lock_dir(directory, what="run directory", notice=None):
    """Lock ``directory`` (made if missing) for this process: LockedError
    naming the holder (pid, host, start time) if a live process holds it. A
    lock left by a process that died (kill -9, a lost machine) is taken
    over; ``notice(text)`` is told so. Returns a DirLock.

    The lock is a POSIX record lock (fcntl.lockf) on ``pyins.lock``: the
    kernel drops it when its process dies, it is not inherited by forked
    children (pool workers), and it works on NFS."""
    os.makedirs(directory, exist_ok=True)
    path = os.path.join(directory, LOCK)
    for _ in range(10):
        fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
        try:
            fcntl.lockf(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as exc:
            data = os.read(fd, 65536)
            os.close(fd)
            if exc.errno not in (errno.EACCES, errno.EAGAIN):
                raise
            try:
                holder = json.loads(data.decode() or "null") or {}
            except ValueError:
                holder = {}
            raise LockedError(f"{directory}: this {what} is being written by {_holder_text(holder)}; "
                              "wait for it to end, or use another directory") from None
        try:
            same = os.stat(path).st_ino == os.fstat(fd).st_ino
        except FileNotFoundError:
            same = False
        if not same:                 # released and removed while we waited: try the new file
            os.close(fd)
            continue
        old = os.read(fd, 65536)
        taken_over = None
        if old.strip():              # a holder that ended cleanly removes the file: this one died
            try:
                taken_over = json.loads(old.decode()) or {}
            except ValueError:
                taken_over = {}
            if notice is not None:
                notice(f"{directory}: taking over the stale lock of {_holder_text(taken_over)}: "
                       "that process is gone")
        me = dict(pid=os.getpid(), host=socket.gethostname(),
                  started=datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M:%S UTC"),
                  command=" ".join(["pyins" if sys.argv[0].endswith("__main__.py") else os.path.basename(sys.argv[0])]
                                   + sys.argv[1:])[:200])
        os.ftruncate(fd, 0)
        os.lseek(fd, 0, os.SEEK_SET)
        os.write(fd, json.dumps(me).encode())
        os.fsync(fd)
        return DirLock(fd, path, taken_over)
    raise LockedError(f"{directory}: the lock file {LOCK} keeps changing: another process is taking it")


# ---------------------------------------------------------------------------
# The record directory
# ---------------------------------------------------------------------------
def write_records_json(record_dir, every, dt, duration_ticks, done):
    """records.json: the dtypes of the two files and how far the run got."""
    write_atomic(os.path.join(record_dir, RECORDS), json.dumps(
        {"outputs.bin": str(contract.OUTPUT_DTYPE.descr), "plant.bin": str(PLANT_RECORD_DTYPE.descr),
         "every_ticks": every, "dt_s": dt, "ticks": int(duration_ticks), "ticks_done": int(done),
         "complete": bool(done >= duration_ticks)}, indent=2))


def load_written(record_dir):
    """Every whole record a run wrote to ``record_dir`` up to where it
    stopped (a Ctrl-C, a kill), past its last checkpoint too: (outputs,
    plant) memory-mapped, the two cut to the same length; (None, None)
    when it wrote none. What a report of a stopped run shows; `--resume`
    continues from the checkpoint instead."""
    counts = []
    for name, dtype in _SINKS:
        path = os.path.join(record_dir, name)
        counts.append(os.path.getsize(path) // dtype.itemsize if os.path.exists(path) else 0)
    n = min(counts)
    if n == 0:
        return None, None
    return tuple(np.memmap(os.path.join(record_dir, name), dtype=dtype, mode="r", shape=(n,))
                 for name, dtype in _SINKS)


def _record_count(record_dir):
    """(records.json info, the number of whole records in both files up to the
    last checkpointed or completed tick)."""
    with open(os.path.join(record_dir, RECORDS)) as f:
        info = json.load(f)
    ck = os.path.join(record_dir, CHECKPOINT)
    n = None
    if os.path.exists(ck) and not info.get("complete"):
        with open(ck) as f:
            n = json.load(f)["n_records"]
    counts = []
    for name, dtype in _SINKS:
        count = os.path.getsize(os.path.join(record_dir, name)) // dtype.itemsize
        counts.append(count if n is None else min(n, count))
    return info, counts


def load_records(record_dir):
    """The records a run streamed to ``record_dir`` (complete or not), memory-
    mapped, cut to the last checkpointed or completed tick: (outputs, plant,
    info) with info the records.json dict."""
    info, counts = _record_count(record_dir)
    arrays = []
    for (name, dtype), count in zip(_SINKS, counts):
        path = os.path.join(record_dir, name)
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
#: timeseries.npz's error arrays, in its order: (name, the metrics.NavErrors field, shape per record).
_TS_ERRORS = (("time_s", "time_s", ()), ("north_m", "north_m", ()), ("east_m", "east_m", ()),
              ("horizontal_m", "horizontal_m", ()), ("vel_err_n_mps", "vel_n_mps", (3,)),
              ("att_err_n_rad", "att_n_rad", (3,)))


def timeseries(res):
    """The arrays of timeseries.npz of a FilResult: every record and its
    errors against the truth."""
    e = metrics.nav_errors(res)
    return {**{name: getattr(e, field) for name, field, _ in _TS_ERRORS},
            "outputs": np.asarray(res.outputs), "plant": np.asarray(res.plant)}


def write_timeseries(vdir, res):
    """timeseries.npz (every record and its errors) and timeseries.csv (the
    errors, at most CSV_MAX_ROWS rows) of a FilResult held in memory
    (`score_variant` writes the same from the records on disk)."""
    arrays = timeseries(res)
    e, out = metrics.nav_errors(res), arrays["outputs"]
    write_atomic(os.path.join(vdir, "timeseries.npz"), write=lambda f: np.savez(f, **arrays), sync=False)
    step = max(1, -(-len(out) // CSV_MAX_ROWS))
    _write_csv(vdir, _csv_columns(e, out, np.arange(0, len(out), step)))


def _csv_columns(e, out, k):
    """timeseries.csv's columns at records k of errors e and firmware records out."""
    return np.column_stack([e.time_s[k], e.north_m[k], e.east_m[k], e.horizontal_m[k],
                            e.vel_n_mps[k], e.att_n_rad[k] / ARCSEC_TO_RAD,
                            out["table_angle_rad"][k], out["yaw_p_rad"][k], out["mode"][k]])


def _write_csv(vdir, cols):
    write_atomic(os.path.join(vdir, "timeseries.csv"), sync=False, write=lambda f: np.savetxt(
        f, cols, delimiter=",", fmt="%.10g", comments="",
        header="time_s,north_m,east_m,horizontal_m,vel_err_e_mps,vel_err_n_mps,vel_err_u_mps,"
               "att_err_e_arcsec,att_err_n_arcsec,att_err_u_arcsec,table_angle_rad,yaw_p_rad,mode"))


def load_variant(record_dir, motion, dt):
    """The records in ``record_dir`` (complete or partial) beside the truth
    of ``motion``: (FilResult, records.json info), or (None, None) when the
    run wrote nothing."""
    if not os.path.exists(os.path.join(record_dir, RECORDS)):
        return None, None
    outputs, plant, info = load_records(record_dir)
    truth = sim.truth_at(motion, np.asarray(outputs["tick"]), dt=dt)
    return FilResult(outputs=outputs, plant=plant, truth=truth, dt=dt), info


# ---------------------------------------------------------------------------
# A finished variant scored from its records, chunk by chunk
# ---------------------------------------------------------------------------
def _read_chunk(path, dtype, start, count):
    """Records start .. start + count - 1 of a raw record file, read into memory
    (not mapped: the pages of a mapping stay resident while it lives)."""
    with open(path, "rb") as f:
        f.seek(start * dtype.itemsize)
        return np.fromfile(f, dtype=dtype, count=count)


def _npy_member(zf, name, dtype, shape, chunks):
    """One .npy member of an .npz (as np.savez writes it: stored, zip64), its
    data from ``chunks`` (arrays or raw bytes, in order)."""
    with zf.open(name + ".npy", "w", force_zip64=True) as fid:
        np.lib.format.write_array_header_1_0(fid, {"descr": np.lib.format.dtype_to_descr(dtype),
                                                   "fortran_order": False, "shape": shape})
        for c in chunks:
            fid.write(c if isinstance(c, bytes) else np.ascontiguousarray(c).tobytes())


def _file_blocks(path, nbytes, block=1 << 22):
    """The first ``nbytes`` of a file, in blocks of 4 MiB."""
    with open(path, "rb") as f:
        left = nbytes
        while left > 0:
            b = f.read(min(block, left))
            if not b:
                raise OSError(f"{path}: shorter than its records.json says")
            left -= len(b)
            yield b


def score_variant(vdir, spec, chunk=CHUNK_RECORDS):
    """A variant's records (``vdir``/records, complete or stopped) read back
    ``chunk`` records at a time, so memory stays bounded for a run of any
    length and record rate: its run metrics (`pyins.metrics.start`, the
    same figures as `metrics.run_metrics` on the whole records), its
    alignment (`metrics.aligned_at`) and ``timeseries.npz`` / ``.csv``
    with the arrays `write_timeseries` writes. Returns (metrics, aligned,
    records.json info); ({}, None, None) when the run wrote nothing."""
    rdir = os.path.join(vdir, "records")
    if not os.path.exists(os.path.join(rdir, RECORDS)):
        return {}, None, None
    info, (n, n_plant) = _record_count(rdir)
    n = min(n, n_plant)
    if n == 0:
        return {}, None, info
    out_path, plant_path = (os.path.join(rdir, name) for name, _ in _SINKS)
    last = _read_chunk(out_path, contract.OUTPUT_DTYPE, n - 1, 1)
    run = metrics.start(spec, float(last["tick"][0]) * spec.dt)
    step = max(1, -(-n // CSV_MAX_ROWS))
    rows, first_nav = [], None
    tmp = {name: os.path.join(vdir, f".{name}.part{os.getpid()}") for name, _, _ in _TS_ERRORS}
    try:
        files = {name: open(path, "wb") for name, path in tmp.items()}
        try:
            for i in range(0, n, chunk):
                m = min(chunk, n - i)
                out = _read_chunk(out_path, contract.OUTPUT_DTYPE, i, m)
                plant = _read_chunk(plant_path, PLANT_RECORD_DTYPE, i, m)
                truth = sim.truth_at(spec.motion, np.asarray(out["tick"]), dt=spec.dt)
                res = FilResult(outputs=out, plant=plant, truth=truth, dt=spec.dt)
                e = metrics.nav_errors(res)
                run.add(res, e)
                for name, field, _ in _TS_ERRORS:
                    files[name].write(np.ascontiguousarray(getattr(e, field)).tobytes())
                if first_nav is None:
                    nav = np.flatnonzero(out["mode"] == abi.PYINS_MODE_NAVIGATE)
                    first_nav = out[nav[0]].copy() if len(nav) else None
                k = np.arange((-i) % step, m, step)
                rows.append(_csv_columns(e, out, k))
        finally:
            for f in files.values():
                f.close()

        def write_npz(f):
            with zipfile.ZipFile(f, mode="w", compression=zipfile.ZIP_STORED, allowZip64=True) as zf:
                for name, _, tail in _TS_ERRORS:
                    _npy_member(zf, name, np.dtype("<f8"), (n, *tail),
                                _file_blocks(tmp[name], n * 8 * (tail[0] if tail else 1)))
                _npy_member(zf, "outputs", contract.OUTPUT_DTYPE, (n,),
                            _file_blocks(out_path, n * contract.OUTPUT_DTYPE.itemsize))
                _npy_member(zf, "plant", PLANT_RECORD_DTYPE, (n,),
                            _file_blocks(plant_path, n * PLANT_RECORD_DTYPE.itemsize))
        write_atomic(os.path.join(vdir, "timeseries.npz"), write=write_npz, sync=False)
    finally:
        for path in tmp.values():
            if os.path.exists(path):
                os.remove(path)
    _write_csv(vdir, np.concatenate(rows))
    return metrics.scored(run), metrics.aligned_at(spec.config, 1.0 / spec.dt, first_nav), info
