"""The project's own IMU file format: an .npz and a CSV with one header line
(moved here from pyins.sim.io, which keeps these names).

One row per 10-ms sample: tick number, angle increment dtheta_p [rad] and
velocity increment dv_p [m/s] over the tick in the IMU frame p, and the
table (encoder) angle at the end of the tick [rad] (docs/design.md §3).

- .npz: arrays ``tick`` (int64), ``dtheta_p`` (N, 3), ``dv_p`` (N, 3),
  ``table_angle_rad`` (N,), the scalar ``dt`` [s] and ``metadata``, a JSON
  string. Loaded with ``allow_pickle=False``.
- CSV: the header line `CSV_HEADER`, then one line per sample, floats written
  with ``%.17g`` (17 significant digits round-trip every float64 exactly),
  ticks as integers. The CSV does not store dt.

Malformed input raises ValueError naming the file, and for CSV the line
(1-based, the header is line 1) and column.
"""
import json
import os
from dataclasses import dataclass, field

import zipfile

import numpy as np

CSV_COLUMNS = ("tick", "dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad",
               "dv_x_mps", "dv_y_mps", "dv_z_mps", "table_angle_rad")
CSV_HEADER = ",".join(CSV_COLUMNS)
_NPZ_KEYS = ("tick", "dtheta_p", "dv_p", "table_angle_rad", "dt", "metadata")


@dataclass
class ImuData:
    """IMU samples as stored in a file."""
    tick: np.ndarray             #: (N,) int64, strictly increasing
    dtheta_p: np.ndarray         #: (N, 3) [rad]
    dv_p: np.ndarray             #: (N, 3) [m/s]
    table_angle_rad: np.ndarray  #: (N,) [rad]
    dt: float = None             #: tick length [s] (None when the file has none)
    metadata: dict = field(default_factory=dict)


def _check_arrays(name, tick, dtheta_p, dv_p, table_angle_rad):
    dtheta_p = np.asarray(dtheta_p, dtype=float)
    dv_p = np.asarray(dv_p, dtype=float)
    table_angle_rad = np.asarray(table_angle_rad, dtype=float)
    n = dtheta_p.shape[0] if dtheta_p.ndim == 2 else -1
    if dtheta_p.shape != (n, 3) or dv_p.shape != (n, 3) or table_angle_rad.shape != (n,):
        raise ValueError(f"{name}: expected dtheta_p (N, 3), dv_p (N, 3), table_angle_rad (N,); "
                         f"got {dtheta_p.shape}, {dv_p.shape}, {table_angle_rad.shape}")
    if tick is None:
        tick = np.arange(1, n + 1, dtype=np.int64)
    tick = np.asarray(tick)
    if tick.shape != (n,) or not np.issubdtype(tick.dtype, np.integer):
        raise ValueError(f"{name}: tick must be an (N,) integer array, got {tick.dtype} {tick.shape}")
    tick = tick.astype(np.int64)
    bad = np.nonzero(np.diff(tick) <= 0)[0]
    if bad.size:
        i = bad[0] + 1
        raise ValueError(f"{name}: tick not strictly increasing at sample {i} "
                         f"({tick[i - 1]} then {tick[i]})")
    return tick, dtheta_p, dv_p, table_angle_rad


def save_npz(path, dtheta_p, dv_p, table_angle_rad, dt, metadata=None, tick=None):
    """Write samples to ``path`` (exactly that name; no suffix is added).

    Parameters
    ----------
    path : str or PathLike
    dtheta_p, dv_p : array_like (N, 3)
        Increments [rad], [m/s].
    table_angle_rad : array_like (N,)
        Table angle at the end of each tick [rad].
    dt : float
        Tick length [s].
    metadata : dict, optional
        Anything JSON can encode (profile name, seed, sensor preset, ...).
    tick : array_like of int (N,), optional
        Tick numbers; default 1..N.
    """
    name = os.fspath(path)
    tick, dtheta_p, dv_p, table_angle_rad = _check_arrays(name, tick, dtheta_p, dv_p,
                                                          table_angle_rad)
    meta = json.dumps(metadata if metadata is not None else {}, sort_keys=True)
    with open(path, "wb") as f:
        np.savez(f, tick=tick, dtheta_p=dtheta_p, dv_p=dv_p,
                 table_angle_rad=table_angle_rad, dt=np.float64(dt),
                 metadata=np.array(meta))


def _npz_why(exc):
    """What numpy said of a file that is not an npz, in a few words (a text file
    reads to numpy as pickled data: it is not a zip archive)."""
    text = str(exc)
    if not text or "No data left" in text:
        return "empty"
    if "pickle" in text:
        return "not a zip archive"
    return text


def load_npz(path, file=None):
    """Read a file written by `save_npz`; returns `ImuData`. ``file``: a binary
    file object to read instead of opening ``path`` (pyins.logs' reader hands in
    decompressed bytes)."""
    name = os.fspath(path)
    try:
        npz = np.load(path if file is None else file, allow_pickle=False)
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:
        raise ValueError(f"{name}: not a readable .npz file ({_npz_why(exc)}): cut, damaged or not an npz") from exc
    with npz:
        missing = [k for k in _NPZ_KEYS if k not in npz.files]
        if missing:
            raise ValueError(f"{name}: missing arrays {missing} (has {sorted(npz.files)})")
        arrays = {k: npz[k] for k in _NPZ_KEYS}
    if arrays["dt"].shape != ():
        raise ValueError(f"{name}: dt must be a scalar, got shape {arrays['dt'].shape}")
    try:
        metadata = json.loads(str(arrays["metadata"]))
    except json.JSONDecodeError as exc:
        raise ValueError(f"{name}: metadata is not valid JSON ({exc})") from exc
    tick, dtheta_p, dv_p, angle = _check_arrays(name, arrays["tick"], arrays["dtheta_p"],
                                                arrays["dv_p"], arrays["table_angle_rad"])
    return ImuData(tick, dtheta_p, dv_p, angle, float(arrays["dt"]), metadata)


def save_csv(path, dtheta_p, dv_p, table_angle_rad, tick=None):
    """Write samples as CSV (header `CSV_HEADER`, floats as ``%.17g``)."""
    name = os.fspath(path)
    tick, dtheta_p, dv_p, table_angle_rad = _check_arrays(name, tick, dtheta_p, dv_p,
                                                          table_angle_rad)
    with open(path, "w", newline="\n") as f:
        f.write(CSV_HEADER + "\n")
        for k, th, v, a in zip(tick.tolist(), dtheta_p.tolist(), dv_p.tolist(),
                               table_angle_rad.tolist()):
            f.write("%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n"
                    % (k, th[0], th[1], th[2], v[0], v[1], v[2], a))


def _parse_tick(text, where):
    try:
        return int(text)
    except ValueError:
        raise ValueError(f"{where}: tick {text.strip()!r} is not an integer") from None


def load_csv(path, dt=None, file=None):
    """Read a CSV written by `save_csv` (or by hand in the same layout).

    Blank lines are skipped. Fields may carry surrounding spaces.

    Parameters
    ----------
    path : str or PathLike
    dt : float, optional
        Tick length to record in the result (the CSV does not store it).
    file : text file object, optional
        Read from it instead of opening ``path`` (which still names the file
        in messages): pyins.logs' reader hands in decompressed text.

    Returns
    -------
    ImuData
    """
    name = os.fspath(path)
    ncol = len(CSV_COLUMNS)
    ticks, values = [], []
    with (open(path, "r", newline="") if file is None else file) as f:
        header = f.readline()
        if header.rstrip("\r\n").lstrip("\ufeff").strip() != CSV_HEADER:
            raise ValueError(f"{name}: line 1: header must be {CSV_HEADER!r}, "
                             f"got {header.rstrip(chr(13) + chr(10))!r}")
        for lineno, line in enumerate(f, start=2):
            line = line.rstrip("\r\n")
            if not line.strip():
                continue
            fields = line.split(",")
            if len(fields) != ncol:
                raise ValueError(f"{name}: line {lineno}: expected {ncol} columns "
                                 f"({CSV_HEADER}), got {len(fields)}")
            tick = _parse_tick(fields[0], f"{name}: line {lineno}, column 1 ({CSV_COLUMNS[0]})")
            row = []
            for c in range(1, ncol):
                try:
                    row.append(float(fields[c]))
                except ValueError:
                    raise ValueError(f"{name}: line {lineno}, column {c + 1} "
                                     f"({CSV_COLUMNS[c]}): {fields[c].strip()!r} is not a number"
                                     ) from None
            if ticks and tick <= ticks[-1][0]:
                raise ValueError(f"{name}: line {lineno}, column 1 ({CSV_COLUMNS[0]}): tick "
                                 f"{tick} does not increase (previous tick {ticks[-1][0]} "
                                 f"on line {ticks[-1][1]})")
            ticks.append((tick, lineno))
            values.append(row)
    arr = np.array(values, dtype=float).reshape(-1, ncol - 1)
    tick = np.array([t for t, _ in ticks], dtype=np.int64)
    return ImuData(tick, arr[:, 0:3].copy(), arr[:, 3:6].copy(), arr[:, 6].copy(),
                   None if dt is None else float(dt), {})
