"""The options of the log readers and writers, checked: formats and their
extensions, compressions, kinds, units, axes (`axes_matrix`), the column and
array names each role answers to (`CSV_ALIASES`, `NPZ_ALIASES`,
`parse_columns`), the default block size. The meaning of each option is in
`pyins.logs`'s docstring."""
import bz2
import gzip
import lzma
import os
from dataclasses import dataclass

import numpy as np

from pyins.units import ARCSEC_TO_RAD, DEG_TO_RAD, DPH_TO_RPS, G0, UG_TO_MPS2

FORMATS = ("npz", "csv", "text", "binary", "psins")
EXTENSIONS = {".npz": "npz", ".csv": "csv", ".txt": "text", ".dat": "text", ".asc": "text",
              ".bin": "binary", ".imu": "psins"}
#: compression: extension -> (name, magic bytes at the start of the file, opener)
COMPRESSIONS = {".gz": ("gzip", b"\x1f\x8b", gzip.open), ".xz": ("xz", b"\xfd7zXZ\x00", lzma.open),
                ".bz2": ("bzip2", b"BZh", bz2.open)}
KINDS = ("increments", "rates")
TIME_COLS = ("last", "first", "none")

#: Unit -> factor to SI, per kind.
GYRO_UNITS = {"increments": {"rad": 1.0, "deg": DEG_TO_RAD, "arcsec": ARCSEC_TO_RAD},
              "rates": {"rad/s": 1.0, "deg/s": DEG_TO_RAD, "deg/h": DPH_TO_RPS,
                        "arcsec/s": ARCSEC_TO_RAD}}
#: "ug*s": a micro-g held for a second, 1e-6 G0 m/s (a pulse-count accelerometer's unit)
ACCEL_UNITS = {"increments": {"m/s": 1.0, "mm/s": 1e-3, "ug*s": UG_TO_MPS2},
               "rates": {"m/s^2": 1.0, "g": G0, "mg": 1e-3 * G0, "ug": UG_TO_MPS2}}
TABLE_UNITS = {"rad": 1.0, "deg": DEG_TO_RAD}

#: File axes -> p (right-forward-up): v_p = AXES[name] @ v_file.
AXES = {
    "rfu": np.eye(3, dtype=int),
    "frd": np.array([[0, 1, 0], [1, 0, 0], [0, 0, -1]]),
    "flu": np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1]]),
}
AXES_ALIASES = {"p": "rfu", "enu": "rfu", "ned": "frd", "nwu": "flu"}

DEFAULT_BLOCK = 1 << 16  #: samples a block (655 s at 100 Hz; ~4 MB of values, ~8 MB converted)


# ---------------------------------------------------------------------------
# Options
# ---------------------------------------------------------------------------
def _split_compression(path):
    """(path without a compression extension, the compression's name or None)."""
    base, ext = os.path.splitext(os.fspath(path))
    if ext.lower() in COMPRESSIONS:
        return base, COMPRESSIONS[ext.lower()][0]
    return os.fspath(path), None


def format_of(path, fmt=None):
    """The format of ``path``: ``fmt`` checked, or the one its extension names
    (a compression extension .gz/.xz/.bz2 is looked through: log.csv.gz is csv)."""
    if fmt is not None:
        if fmt not in FORMATS:
            raise ValueError(f"fmt {fmt!r} is not one of {FORMATS}")
        return fmt
    ext = os.path.splitext(_split_compression(path)[0])[1].lower()
    if ext not in EXTENSIONS:
        raise ValueError(f"{os.fspath(path)}: cannot tell the format from the extension {ext!r} "
                         f"(known: {', '.join(EXTENSIONS)}, each also with "
                         f"{', '.join(COMPRESSIONS)}); pass fmt= one of {FORMATS}")
    return EXTENSIONS[ext]


def axes_matrix(axes):
    """The matrix M of ``v_p = M @ v_file`` for an ``axes`` option.

    ``axes`` is a name of `AXES` or `AXES_ALIASES`, ``"<name>->rfu"``, or a
    3x3 signed permutation matrix with determinant +1. Returns an int array.
    """
    if isinstance(axes, str):
        spec = axes.replace(" ", "").lower()
        src, arrow, dst = spec.partition("->")
        if arrow and _axes_name(dst) != "rfu":
            raise ValueError(f"axes {axes!r}: the target must be the IMU frame p, 'rfu' "
                             f"(right-forward-up)")
        return AXES[_axes_name(src)].copy()
    m = np.asarray(axes)
    if m.shape != (3, 3):
        raise ValueError(f"axes: a matrix must be 3x3, got shape {m.shape}")
    if not np.all(np.isin(m, (-1, 0, 1))) or not (
            np.all(np.count_nonzero(m, axis=0) == 1) and np.all(np.count_nonzero(m, axis=1) == 1)):
        raise ValueError(f"axes: {m.tolist()} is not a signed permutation matrix (one +1 or -1 "
                         f"in every row and column, zeros elsewhere)")
    if round(np.linalg.det(m)) != 1:
        raise ValueError(f"axes: {m.tolist()} has determinant -1: it mirrors the axes into a "
                         f"left-handed triad (a sign is probably wrong)")
    return m.astype(int)


def _axes_name(name):
    name = AXES_ALIASES.get(name, name)
    if name not in AXES:
        known = sorted(AXES) + sorted(AXES_ALIASES)
        raise ValueError(f"axes: unknown frame {name!r} (known: {', '.join(known)}; or pass a "
                         f"3x3 signed permutation matrix)")
    return name


def _perm_sign(m):
    """Row i of M has its non-zero sign[i] in column perm[i]."""
    perm = np.argmax(np.abs(m), axis=1)
    sign = m[np.arange(3), perm].astype(float)
    return perm, sign


# ---------------------------------------------------------------------------
# Names: the header columns and npz arrays each role answers to
# ---------------------------------------------------------------------------
def _csv_aliases():
    """Header names each role answers to (lower case, a unit in brackets dropped)."""
    out = {"t": ("t", "time", "timestamp", "time_s", "t_s", "sec", "seconds", "gps_time",
                 "gpst", "sow"),
           "tick": ("tick",),
           "table": ("table", "alpha", "table_angle", "table_angle_rad", "encoder")}
    for axis in "xyz":
        out[f"gyro_{axis}"] = tuple(n.format(axis) for n in (
            "dtheta_{}", "dtheta_{}_rad", "gyro_{}", "gyr_{}", "g{}", "g_{}", "w{}", "w_{}",
            "wm_{}", "omega_{}", "dang_{}", "angle_inc_{}", "dtheta{}"))
        out[f"accel_{axis}"] = tuple(n.format(axis) for n in (
            "dv_{}", "dv_{}_mps", "accel_{}", "acc_{}", "a{}", "a_{}", "f{}", "f_{}", "vm_{}",
            "dvel_{}", "vel_inc_{}", "dv{}"))
    return out


CSV_ALIASES = _csv_aliases()
CSV_ROLES = tuple(CSV_ALIASES)


#: npz arrays by role: a triad as one (N, 3) array or three (N,) arrays
NPZ_ALIASES = {"t": ("t", "time", "timestamp", "time_s"), "tick": ("tick",),
               "gyro": ("dtheta", "dtheta_p", "gyro", "gyr", "wm", "w", "omega", "dang"),
               "accel": ("dv", "dv_p", "accel", "acc", "vm", "f", "dvel"),
               "table": ("table", "alpha", "table_angle", "table_angle_rad")}
for _axis in "xyz":
    NPZ_ALIASES[f"gyro_{_axis}"] = CSV_ALIASES[f"gyro_{_axis}"]
    NPZ_ALIASES[f"accel_{_axis}"] = CSV_ALIASES[f"accel_{_axis}"]
NPZ_ROLES = tuple(NPZ_ALIASES)


def parse_columns(text, option="columns"):
    """``"t=stamp,gyro_x=a"`` -> ``{"t": "stamp", "gyro_x": "a"}`` (the CLI's
    --columns); a malformed list is a ValueError naming ``option``."""
    pairs = [item.partition("=") for item in text.split(",") if item.strip()]
    if not pairs or any(not eq or not role.strip() or not col.strip() for role, eq, col in pairs):
        raise ValueError(f"{option} {text!r}: expected ROLE=NAME,... (roles: "
                         f"{', '.join(dict.fromkeys(CSV_ROLES + NPZ_ROLES))})")
    return {role.strip(): col.strip() for role, _, col in pairs}


# ---------------------------------------------------------------------------
# The options of one read or write, checked
# ---------------------------------------------------------------------------
@dataclass
class _Options:
    fmt: str
    kind: str
    gyro_unit: str
    accel_unit: str
    table_unit: str
    axes: np.ndarray
    axes_spec: object
    time_col: str
    table: object      # True, False or None (text: decided by the first data line)
    dt: float
    gyro_scale: float = 1.0     # raw gyro numbers are multiplied by it, then by the unit
    accel_scale: float = 1.0
    columns: dict = None        # csv: role -> header name, the user's mapping


def _options(path, fmt, *, dt, kind, gyro_unit, accel_unit, axes, time_col, table,
             table_unit, writing, gyro_scale=1.0, accel_scale=1.0, columns=None):
    fmt = format_of(path, fmt)
    for label, scale in (("gyro_scale", gyro_scale), ("accel_scale", accel_scale)):
        if not (isinstance(scale, (int, float)) and np.isfinite(scale) and scale > 0):
            raise ValueError(f"{label} must be a positive number (the unit per count), "
                             f"got {scale!r}")
    if columns is not None and fmt not in ("csv", "npz"):
        raise ValueError(f"columns= names CSV header columns or npz arrays; it does not apply "
                         f"to {fmt}")
    if fmt == "psins":
        given = {"kind": (kind, ("increments",)), "gyro_unit": (gyro_unit, (None,)),
                 "accel_unit": (accel_unit, (None,)), "time_col": (time_col, (None,)),
                 "table": (table, (None, False)), "gyro_scale": (gyro_scale, (1.0,)),
                 "accel_scale": (accel_scale, (1.0,))}
        extra = [k for k, (value, allowed) in given.items() if value not in allowed]
        if extra:
            raise ValueError(f"{os.fspath(path)}: a PSINS .imu file states its units, scale factors "
                             f"and time in its header; options {sorted(extra)} do not apply (a file "
                             f"of another layout: pass fmt='text', fmt='csv' or fmt='binary')")
        return _Options(fmt, "increments", "rad", "m/s", table_unit, axes_matrix(axes), axes,
                        "first", False, None if dt is None else float(dt))
    if writing and fmt in ("npz", "csv"):
        given = {"kind": (kind, ("increments",)), "gyro_unit": (gyro_unit, (None, "rad")),
                 "accel_unit": (accel_unit, (None, "m/s")), "time_col": (time_col, (None,)),
                 "table": (table, (None,)), "table_unit": (table_unit, ("rad",))}
        extra = [k for k, (value, allowed) in given.items() if value not in allowed]
        if not np.array_equal(axes_matrix(axes), np.eye(3)):
            extra.append("axes")
        if extra:
            raise ValueError(f"{fmt}: the project's {fmt} files hold rad, m/s and the p axes "
                             f"only; options {sorted(extra)} do not apply")
    if kind not in KINDS:
        raise ValueError(f"kind {kind!r} is not one of {KINDS}")
    gyro_unit = gyro_unit if gyro_unit is not None else next(iter(GYRO_UNITS[kind]))
    accel_unit = accel_unit if accel_unit is not None else next(iter(ACCEL_UNITS[kind]))
    if gyro_unit not in GYRO_UNITS[kind]:
        raise ValueError(f"gyro_unit {gyro_unit!r} does not go with kind={kind!r}; choose one "
                         f"of {list(GYRO_UNITS[kind])}")
    if accel_unit not in ACCEL_UNITS[kind]:
        raise ValueError(f"accel_unit {accel_unit!r} does not go with kind={kind!r}; choose one "
                         f"of {list(ACCEL_UNITS[kind])}")
    if table_unit not in TABLE_UNITS:
        raise ValueError(f"table_unit {table_unit!r} is not one of {list(TABLE_UNITS)}")
    if fmt == "binary":
        if time_col not in (None, "first"):
            raise ValueError(f"binary records always start with the time; time_col={time_col!r} "
                             f"does not apply")
        time_col = "first"
        if table is None:
            table = False
    elif time_col is None:
        time_col = "last"
    if time_col not in TIME_COLS:
        raise ValueError(f"time_col {time_col!r} is not one of {TIME_COLS}")
    if table not in (None, True, False):
        raise ValueError(f"table must be True, False or None, got {table!r}")
    if dt is not None:
        dt = float(dt)
        if not (np.isfinite(dt) and dt > 0.0):
            raise ValueError(f"dt must be a positive number of seconds, got {dt!r}")
    if fmt in ("text", "binary") and time_col == "none" and dt is None and not writing:
        raise ValueError("time_col='none': the file has no time column, pass dt")
    if columns is not None:
        roles = CSV_ROLES if fmt == "csv" else NPZ_ROLES
        if not isinstance(columns, dict) or not set(columns) <= set(roles):
            raise ValueError(f"columns must map roles {list(roles)} to "
                             f"{'header' if fmt == 'csv' else 'array'} names, got {columns!r}")
    return _Options(fmt, kind, gyro_unit, accel_unit, table_unit, axes_matrix(axes), axes,
                    time_col, table, dt, float(gyro_scale), float(accel_scale), columns)


def _columns(time_col, has_table):
    cols = ["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"]
    if time_col == "first":
        cols.insert(0, "t")
    elif time_col == "last":
        cols.append("t")
    if has_table:
        cols.append("table")
    return cols
