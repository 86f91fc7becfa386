"""IMU logs from the field: read, check and write the text and binary layouts
of other INS tools, and the project's own .npz and CSV (`pyins.sim.io`).

Every reader returns a `pyins.sim.io.ImuData` in the project's terms
(docs/design.md §2-§3): one sample per tick, the angle increment
``dtheta_p`` [rad] and the velocity increment ``dv_p`` [m/s] over the tick
``[t_{k-1}, t_k]`` in the IMU frame p (x right, y forward, z up), and the table
angle at ``t_k`` [rad]. docs/log-formats.md has the same content with examples.

Formats (``fmt``; when None, taken from the extension)
------------------------------------------------------
- ``"npz"`` (.npz): the project's file, read and written by `pyins.sim.io`;
  no unit, axis or layout options. `read_log` runs the magnitude checks on it
  too and reports skipped ticks as gaps.
- ``"csv"`` (.csv): a header line names the columns, mapped to roles by name
  (`CSV_ALIASES`, or ``columns=``); ``#``/``%`` comment lines; the text
  options below apply. The project's own header (`pyins.sim.io.CSV_HEADER`
  on line 1) is read by `pyins.sim.io` as before.
- ``"psins"`` (.imu): PSINS's compact SIMU file (base/io/imufile.m): three
  header lines (initial state; position, t0, ts [ms], g; scale factors in
  arcsec and ug*s), then integer pulse counts, x right, y forward, z up.
- Any of them gzip/xz/bzip2-compressed: the extension is looked through for
  the format, the first bytes tell the compression (`compression_of`).
- ``"text"`` (.txt, .dat, .asc): whitespace-separated numbers, one sample a
  line. Blank lines and lines whose first non-blank character is ``#`` or
  ``%`` are skipped. Columns, with ``g`` the gyro triad and ``a`` the
  accelerometer triad, each x y z in the file's axes:

  ==================  ===========================  ============================
  ``time_col``        columns                      typical source
  ==================  ===========================  ============================
  ``"last"`` (text    ``g(3) a(3) t [alpha]``      PSINS ``imu = [wm vm t]``
  default)                                         (increments, right-fwd-up)
  ``"first"``         ``t g(3) a(3) [alpha]``      KF-GINS / OB_GINS ``.txt``
                                                   (increments, fwd-right-down,
                                                   ``axes="frd"``); rate logs
  ``"none"``          ``g(3) a(3) [alpha]``        PSINS ``[wm vm]``; needs dt
  ==================  ===========================  ============================

  ``alpha``, the table angle, is always the last column (the 8th, or the 7th
  without time), so the toolbox's own 7 columns keep their places. ``table``
  says whether it is there; None (default) lets the first data line decide.
- ``"binary"`` (.bin): headerless little-endian float64 records
  ``(t, g[3], a[3])`` (56 bytes, the i2Nav binary IMU layout) or, with
  ``table=True``, ``(t, g[3], a[3], alpha)`` (64 bytes). The layout cannot be
  told from the file, so ``table`` defaults to False when reading.

Units and kinds (text and binary)
---------------------------------
``kind="increments"`` (default): per-sample increments, ``gyro_unit`` "rad"
(default), "deg" or "arcsec", ``accel_unit`` "m/s" (default), "mm/s" or
"ug*s".
``kind="rates"``: angular rate, ``gyro_unit`` "rad/s" (default), "deg/s",
"deg/h" or "arcsec/s", and specific force, ``accel_unit`` "m/s^2" (default),
"g", "mg" or "ug" (standard gravity G0 = 9.80665 m/s^2). Pulse counts:
``gyro_scale``/``accel_scale``, the unit of one count. Rates become increments by the
rectangular rule: ``increment_k = rate_k * (t_k - t_{k-1})``, the rate at
``t_k`` held over the interval that ends there; the first sample, which has no
previous time, uses the nominal dt. Table angle: ``table_unit`` "rad"
(default) or "deg". Conversions use the named constants of
`pyins.reference.earth` (DEG_TO_RAD, DPH_TO_RPS, G0).

Axes
----
``axes`` names the file's sensor axes; the reader maps them to p, the writer
maps p to them: ``v_p = M @ v_file`` and ``v_file = M.T @ v_p``. Names:

- ``"rfu"`` (aliases ``"enu"``, ``"p"``): right, forward, up: M = I (PSINS).
- ``"frd"`` (alias ``"ned"``): forward, right, down, the aerospace body frame
  (KF-GINS, PX4), "NED-like" because it lines up with North-East-Down when the
  vehicle is level and heads North: M = [[0, 1, 0], [1, 0, 0], [0, 0, -1]].
- ``"flu"`` (alias ``"nwu"``): forward, left, up, the ROS REP 103 body frame:
  M = [[0, -1, 0], [1, 0, 0], [0, 0, 1]].

A string ``"frd->rfu"`` says the same as ``"frd"`` (the target must be rfu,
the frame p). Any other mounting: a 3x3 signed permutation matrix M with
determinant +1 (``v_p = M @ v_file``). Signed permutations move and negate
columns and never round, so axis mapping is bit-exact both ways.

Validation
----------
Positions are named as 1-based file lines for text (comment lines count),
0-based record indices (with the byte offset) for binary, 0-based sample
indices for npz/csv. Errors (the log cannot be used as declared):

- wrong column count, a token that is not a number, non-UTF-8 text, no data;
  binary size not a whole number of records;
- NaN or Inf anywhere;
- time not strictly increasing; a step shorter than half the nominal dt (a
  repeated or extra sample); with ``dt`` given, a median step more than
  TIME_TOL (1 %) away from it (wrong rate, or time not in seconds);
- implausible magnitudes, with a hint at the likely unit: a gyro rate above
  GYRO_RATE_LIMIT (10 rad/s, 573 deg/s; a ship stays below 1 rad/s), or a
  median specific force outside GRAVITY_BAND (0.5 g to 2 g; an IMU at sea
  always measures about 1 g). The hint tries the other readings of the
  accelerometer column (m/s increments, m/s^2, g) and names the one that
  gives about 1 g ("these look like m/s^2 rates, not m/s increments"). The
  median, not a single sample, is tested, so shocks do not trip it; logs
  without gravity (bench tests of the gyros) need ``plausibility=False``.

Warnings (irregular but usable; `read_log` raises them too unless
``strict=False``, which returns the data with the warnings in
``metadata["warnings"]``):

- a gap: a step longer than GAP_TICKS (1.5) nominal dt, reported with the
  number of missing ticks and the lines around it; tick numbers skip there;
- an irregular step: between half and 1.5 dt but more than TIME_TOL (1 %)
  away from dt. Why 1 %: printed or stored time stamps round far finer (1 us
  at 100 Hz is 0.01 %), so a step 1 % off is a real timing fault (a late
  sample, a clock slip), not rounding; and the firmware integrates every
  sample as exactly one tick, so each such sample moves a 1 % share of its
  gravity and Earth-rate compensation to the wrong time.

Time and ticks: the nominal dt is the ``dt`` argument or, without it, the
median step rounded to the nearest nanosecond (so a 100 Hz log gives exactly
0.01). Tick numbers are ``round(t_0 / dt)`` for the first sample, then each
step adds ``round(step / dt)`` (1 except across gaps). Without a time column
the ticks are 1..N. All reader errors are `LogError` (a ValueError) with a
one-line message ``"<file>: <where>: <reason>"``; wrong options (unknown
unit, bad axes matrix, ...) are plain ValueErrors.
"""
import bz2
import gzip
import io as _io
import lzma
import os
from dataclasses import dataclass

import numpy as np

from pyins.units import ARCSEC_TO_RAD, DEG_TO_RAD, DPH_TO_RPS, DT, G0, UG_TO_MPS2
from pyins.sim import io
from pyins.sim.io import ImuData

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

TIME_TOL = 0.01          #: allowed step deviation, fraction of dt (see the module docstring)
GAP_TICKS = 1.5          #: a step longer than this many dt is a gap
MIN_STEP_TICKS = 0.5     #: a step shorter than this many dt is an error
GYRO_RATE_LIMIT = 10.0   #: [rad/s] above this the gyro unit is wrong
GRAVITY_BAND = (0.5 * G0, 2.0 * G0)  #: [m/s^2] plausible median |specific force|
DEFAULT_DT = DT                     #: [s] for plausibility checks of a CSV without dt
MAX_LISTED = 10          #: gaps listed one by one before a summary


class LogError(ValueError):
    """A log that cannot be used as declared: "<file>: <where>: <reason>"."""


@dataclass(frozen=True)
class LogIssue:
    """One finding of `check_log`."""
    level: str      #: "error" or "warning"
    message: str    #: one line, "<file>: <where>: <reason>"

    def __str__(self):
        return f"{self.level}: {self.message}"


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


def compression_of(path):
    """The compression of the file at ``path`` from its first bytes ("gzip", "xz",
    "bzip2"), else None; the extension does not decide (a .gz that is plain
    text is read as plain text)."""
    with open(path, "rb") as f:
        head = f.read(6)
    for name, magic, _ in COMPRESSIONS.values():
        if head.startswith(magic):
            return name
    return None


def _opener(path):
    comp = compression_of(path)
    for name, _, opener in COMPRESSIONS.values():
        if name == comp:
            return comp, opener
    return None, open


def _read_bytes(path, name):
    """The whole file, decompressed; a broken stream is a LogError."""
    comp, opener = _opener(path)
    try:
        with opener(path, "rb") as f:
            return f.read()
    except (OSError, EOFError, lzma.LZMAError, ValueError) as exc:
        if comp is None:
            raise
        raise LogError(f"{name}: not a complete {comp} stream ({exc}): the file is cut or "
                       f"damaged") from None


def _text_lines(path, name):
    """(1-based line number, line) of a text file, decompressed, UTF-8."""
    raw = _read_bytes(path, name)
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        comp = compression_of(path)
        what = f"after {comp} decompression, " if comp else ""
        raise LogError(f"{name}: {what}byte offset {exc.start}: not UTF-8 text (a binary log? "
                       f"pass fmt='binary')") from None
    return enumerate(_io.StringIO(text.lstrip("\ufeff"), newline=None), start=1)


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
            raise ValueError(f"psins: a PSINS .imu file states its units, scale factors and "
                             f"time in its header; options {sorted(extra)} do not apply")
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


# ---------------------------------------------------------------------------
# Where in the file
# ---------------------------------------------------------------------------
class _Lines:
    """Text positions: 1-based file lines."""

    def __init__(self, numbers, columns):
        self.numbers, self.columns = numbers, columns

    def at(self, k, col=None):
        s = f"line {self.numbers[k]}"
        return s if col is None else f"{s}, column {col + 1} ({self.columns[col]})"

    def span(self):
        return f"lines {self.numbers[0]}-{self.numbers[-1]}"


class _Records:
    """Binary positions: 0-based records."""

    def __init__(self, n, columns):
        self.n, self.columns = n, columns
        self.size = 8 * len(columns)

    def at(self, k, col=None):
        k = int(k) % self.n
        s = f"record {k} (0-based, byte offset {k * self.size})"
        return s if col is None else f"{s}, field {col + 1} ({self.columns[col]})"

    def span(self):
        return f"records 0-{self.n - 1} (0-based)"


class _Samples:
    """npz/csv positions: 0-based sample indices."""

    def __init__(self, n):
        self.n = n

    def at(self, k, col=None):
        return f"sample {int(k) % self.n} (0-based)"

    def span(self):
        return f"samples 0-{self.n - 1} (0-based)"


# ---------------------------------------------------------------------------
# Parsing
# ---------------------------------------------------------------------------
def _parse_text(path, name, opt):
    """(values (N, ncol) float array, _Lines) from a text log."""
    base = 6 + (opt.time_col != "none")
    ncol = None if opt.table is None else base + bool(opt.table)
    rows, numbers = [], []
    first_line = None
    for lineno, line in _text_lines(path, name):
        tokens = line.split()
        if not tokens or tokens[0][0] in "#%":
            continue
        if ncol is None:
            if len(tokens) not in (base, base + 1):
                cols = " ".join(_columns(opt.time_col, False))
                raise LogError(f"{name}: line {lineno}: expected {base} or {base + 1} "
                               f"columns ({cols} [table]), got {len(tokens)}"
                               f"{_comma_hint(tokens)}")
            ncol = len(tokens)
            first_line = lineno
        elif len(tokens) != ncol:
            cols = " ".join(_columns(opt.time_col, ncol > base))
            like = f", like line {first_line}" if first_line else ""
            raise LogError(f"{name}: line {lineno}: expected {ncol} columns ({cols})"
                           f"{like}, got {len(tokens)}{_comma_hint(tokens)}")
        elif first_line is None:
            first_line = lineno
        try:
            rows.append([float(tok) for tok in tokens])
        except ValueError:
            _bad_token(name, lineno, tokens, _columns(opt.time_col, ncol > base))
        numbers.append(lineno)
    if not rows:
        raise LogError(f"{name}: no data lines (only blank or comment lines)")
    columns = _columns(opt.time_col, ncol > base)
    return np.array(rows, dtype=float), _Lines(np.array(numbers), columns), ncol > base


def _bad_token(name, lineno, tokens, columns):
    for c, tok in enumerate(tokens):
        try:
            float(tok)
        except ValueError:
            raise LogError(f"{name}: line {lineno}, column {c + 1} ({columns[c]}): {tok!r} "
                           f"is not a number{_comma_hint([tok])}") from None


def _plural(n, words):
    return f"{n} {words}" if n == 1 else f"{n} {words}s"


def _comma_hint(tokens):
    if any("," in tok or ";" in tok for tok in tokens):
        return " (this reader splits on whitespace; a CSV with a header line is fmt='csv')"
    return ""


def _parse_binary(path, name, opt):
    columns = _columns("first", opt.table)
    size = 8 * len(columns)
    raw = _read_bytes(path, name)
    n, rest = divmod(len(raw), size)
    kind = "with the table angle" if opt.table else "without the table angle"
    if rest:
        raise LogError(f"{name}: size {len(raw)} bytes is not a whole number of {size}-byte "
                       f"records ({kind}): {_plural(n, 'whole record')} and {rest} bytes "
                       f"over")
    if n == 0:
        raise LogError(f"{name}: no records (empty file)")
    values = np.frombuffer(raw, dtype="<f8").reshape(n, len(columns)).astype(float)
    return values, _Records(n, columns), bool(opt.table)


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


def _csv_name(field):
    """A header field compared by name: lower case, no spaces, no unit suffix
    in brackets ("gyro_x [rad]" -> "gyro_x")."""
    field = field.strip().strip('"').lower()
    for opening in "[(":
        if opening in field:
            field = field[:field.index(opening)]
    return field.strip().replace(" ", "_")


def _parse_csv(path, name, opt):
    """A CSV whose header line names the columns: (values, where, has_table)
    in the text layout "first" (or "none" without a time column); (None,
    text) for the project's own header, which pyins.sim.io reads."""
    lines = list(_text_lines(path, name))
    header_at = next((k for k, (_, line) in enumerate(lines)
                      if line.strip() and line.lstrip()[0] not in "#%"), None)
    if header_at is None:
        raise LogError(f"{name}: no header line (only blank or comment lines)")
    lineno, header = lines[header_at]
    if lineno == 1 and header.strip() == io.CSV_HEADER:
        raw = _read_bytes(path, name).decode("utf-8")
        return None, raw
    sep = next((c for c in ",;\t" if c in header), None)
    fields = [_csv_name(f) for f in (header.split(sep) if sep else header.split())]
    try:
        [float(f) for f in fields]
        numeric = True
    except ValueError:
        numeric = False
    if numeric:
        raise LogError(f"{name}: line {lineno}: expected a header line naming the columns "
                       f"(t, dtheta_x, ..., dv_z), got numbers; for a headerless log use "
                       f"fmt='text' (whitespace) or pass the names")
    index = {}
    for role in CSV_ROLES:
        wanted = ((_csv_name(opt.columns[role]),) if opt.columns and role in opt.columns
                  else CSV_ALIASES[role])
        hits = [c for c, f in enumerate(fields) if f in wanted]
        if len(hits) > 1:
            raise LogError(f"{name}: line {lineno}: columns {hits[0] + 1} and {hits[1] + 1} both "
                           f"answer to {role} ({fields[hits[0]]!r}, {fields[hits[1]]!r}); say "
                           f"which with columns={{{role!r}: ...}}")
        if hits:
            index[role] = hits[0]
        elif opt.columns and role in opt.columns:
            raise LogError(f"{name}: line {lineno}: no column {opt.columns[role]!r} for {role} "
                           f"(the header has {', '.join(fields)})")
    missing = [r for r in CSV_ROLES[3:9] if r not in index]
    if missing:
        r = missing[0]
        raise LogError(f"{name}: line {lineno}: the header names no column for {r} (expected "
                       f"one of {', '.join(CSV_ALIASES[r][:6])}, ...; or map it with "
                       f"columns={{{r!r}: NAME}}); it has {', '.join(fields)}")
    has_table = "table" in index if opt.table is None else bool(opt.table)
    if has_table and "table" not in index:
        raise LogError(f"{name}: line {lineno}: table=True, but no table-angle column (expected "
                       f"one of {', '.join(CSV_ALIASES['table'])})")
    if "t" in index:
        opt.time_col, time_role = "first", "t"
    elif "tick" in index:
        if opt.dt is None:
            raise LogError(f"{name}: line {lineno}: a tick column and no time column: pass dt")
        opt.time_col, time_role = "first", "tick"
    else:
        if opt.dt is None:
            raise LogError(f"{name}: line {lineno}: no time column (expected one of "
                           f"{', '.join(CSV_ALIASES['t'])}): pass dt")
        opt.time_col, time_role = "none", None
    columns = _columns(opt.time_col, has_table)
    roles = [time_role if c == "t" else c for c in columns]
    take = [index[r] for r in roles]
    rows, numbers = [], []
    for lineno, line in lines[header_at + 1:]:
        if not line.strip() or line.lstrip()[0] in "#%":
            continue
        tokens = line.rstrip("\n").split(sep) if sep else line.split()
        if len(tokens) != len(fields):
            raise LogError(f"{name}: line {lineno}: expected {len(fields)} fields like the header "
                           f"(line {lines[header_at][0]}), got {len(tokens)}")
        try:
            rows.append([float(tokens[c]) for c in take])
        except ValueError:
            for c, col in zip(take, columns):
                try:
                    float(tokens[c])
                except ValueError:
                    raise LogError(f"{name}: line {lineno}, column {c + 1} ({fields[c]}, read "
                                   f"as {col}): {tokens[c].strip()!r} is not a number") from None
        numbers.append(lineno)
    if not rows:
        raise LogError(f"{name}: no data lines after the header (line {lines[header_at][0]})")
    values = np.array(rows, dtype=float)
    if time_role == "tick":
        values[:, 0] = values[:, 0] * opt.dt
    return values, _Lines(np.array(numbers), columns), has_table


#: npz arrays by role: a triad as one (N, 3) array or three (N,) arrays
NPZ_ALIASES = {"t": ("t", "time", "timestamp", "time_s"), "tick": ("tick",),
               "gyro": ("dtheta", "dtheta_p", "gyro", "gyr", "wm", "w", "omega", "dang"),
               "accel": ("dv", "dv_p", "accel", "acc", "vm", "f", "dvel"),
               "table": ("table", "alpha", "table_angle", "table_angle_rad")}
for _axis in "xyz":
    NPZ_ALIASES[f"gyro_{_axis}"] = CSV_ALIASES[f"gyro_{_axis}"]
    NPZ_ALIASES[f"accel_{_axis}"] = CSV_ALIASES[f"accel_{_axis}"]
NPZ_ROLES = tuple(NPZ_ALIASES)


def _parse_npz(path, name, opt):
    """An npz of other arrays than the project's, found by name (`NPZ_ALIASES`
    or ``columns=``): (values, where, has_table) in the text layout "first"
    (or "none"); None for the project's own file (its arrays, no mapping)."""
    raw = _read_bytes(path, name)
    try:
        npz = np.load(_io.BytesIO(raw), allow_pickle=False)
        files = list(npz.files)
    except (OSError, ValueError) as exc:
        raise LogError(f"{name}: not a readable .npz file ({exc})") from None
    if opt.columns is None and all(k in files for k in io._NPZ_KEYS):
        return None
    lower = {f.lower(): f for f in files}

    def find(role):
        if opt.columns and role in opt.columns:
            key = opt.columns[role]
            if key not in files:
                raise LogError(f"{name}: no array {key!r} for {role} (the file has "
                               f"{', '.join(files)})")
            return key
        return next((lower[a] for a in NPZ_ALIASES[role] if a in lower), None)

    def array(key, shape):
        try:
            a = np.asarray(npz[key], dtype=float)
        except (TypeError, ValueError) as exc:
            raise LogError(f"{name}: array {key!r}: not numbers ({exc})") from None
        if a.shape[1:] != shape[1:] or a.ndim != len(shape):
            raise LogError(f"{name}: array {key!r}: expected shape {('N',) + shape[1:]}, got "
                           f"{a.shape}")
        return a

    triads = {}
    with npz:
        for sensor in ("gyro", "accel"):
            key = find(sensor)
            if key is not None:
                triads[sensor] = array(key, (0, 3))
                continue
            keys = [find(f"{sensor}_{axis}") for axis in "xyz"]
            if None in keys:
                raise LogError(f"{name}: no {sensor} array (expected one (N, 3) array named "
                               f"{' or '.join(NPZ_ALIASES[sensor][:4])}, ..., or three named "
                               f"like {sensor}_x; or map it with columns={{{sensor!r}: NAME}}); "
                               f"the file has {', '.join(files)}")
            triads[sensor] = np.column_stack([array(k, (0,)) for k in keys])
        t_key, tick_key, table_key = find("t"), find("tick"), find("table")
        t = array(t_key, (0,)) if t_key else None
        if t is None and tick_key is not None:
            if opt.dt is None:
                raise LogError(f"{name}: a tick array and no time array: pass dt")
            t = array(tick_key, (0,)) * opt.dt
        has_table = table_key is not None if opt.table is None else bool(opt.table)
        if has_table and table_key is None:
            raise LogError(f"{name}: table=True, but no table-angle array")
        table = array(table_key, (0,)) if has_table else None
    n = triads["gyro"].shape[0]
    for label, a in (("accel", triads["accel"]), ("time", t), ("table", table)):
        if a is not None and a.shape[0] != n:
            raise LogError(f"{name}: the {label} array has {a.shape[0]} samples, the gyro {n}")
    if t is None:
        if opt.dt is None:
            raise LogError(f"{name}: no time array (expected one of "
                           f"{', '.join(NPZ_ALIASES['t'])}): pass dt")
        opt.time_col = "none"
    else:
        opt.time_col = "first"
    parts = ([] if t is None else [t[:, None]]) + [triads["gyro"], triads["accel"]]
    if has_table:
        parts.append(table[:, None])
    if n == 0:
        raise LogError(f"{name}: no samples")
    return np.hstack(parts), _Samples(n), has_table


#: PSINS .imu: the data header's three lines (imufile.m, PSINS base/io)
PSINS_HEADER = (("pitch0_deg", "roll0_deg", "yaw0_deg", "ve0_mps", "vn0_mps", "vu0_mps"),
                ("lat0_deg", "lon0_deg", "height0_m", "t0_s", "ts_ms", "g_mps2"),
                ("gf_x_arcsec", "gf_y_arcsec", "gf_z_arcsec", "af_x_ugs", "af_y_ugs",
                 "af_z_ugs"))


def _parse_psins(path, name, opt):
    """PSINS's compact SIMU text file (.imu, written and read by PSINS's
    base/io/imufile.m): '%' comment lines, the first naming 'PSINS' and 'SIMU';
    three header lines (attitude and velocity; position, t0 [s], the sampling
    interval [ms] and g [m/s^2]; the gyro scale factors [arcsec] and the
    accelerometer scale factors [ug*s, ug = 1e-6 of that g]); then integer
    counts g_x g_y g_z a_x a_y a_z in x-right y-forward z-up axes, and an
    optional 7th column, the sampling-time dither [us]. Sample k (1-based)
    is stamped t0 + k ts + 1e-6 sum(dither[1..k]).
    Returns (values, where, has_table=False, header) in the "first" layout."""
    lines = _text_lines(path, name)
    first = next(lines, (1, ""))[1]
    if "PSINS" not in first or "SIMU" not in first:
        raise LogError(f"{name}: line 1: not a PSINS-format SIMU file (its first line names "
                       f"'PSINS' and 'SIMU'), got {first.strip()[:60]!r}")
    head, rows, numbers, ncol = [], [], [], None
    for lineno, line in lines:
        tokens = line.split()
        if not tokens or tokens[0][0] == "%":
            continue
        try:
            numbers_ = [float(tok) for tok in tokens]
        except ValueError:
            bad = next(t for t in tokens if not _is_number(t))
            raise LogError(f"{name}: line {lineno}: {bad!r} is not a number") from None
        if len(head) < 3:
            if len(numbers_) not in (6, 7):
                raise LogError(f"{name}: line {lineno}: header line {len(head) + 1} of 3 expected "
                               f"6 numbers ({' '.join(PSINS_HEADER[len(head)])}), got "
                               f"{len(numbers_)}")
            head.append(numbers_[:6])
            continue
        if ncol is None:
            if len(numbers_) not in (6, 7):
                raise LogError(f"{name}: line {lineno}: expected 6 counts (g_x g_y g_z a_x a_y "
                               f"a_z) or 7 (and the time dither [us]), got {len(numbers_)}")
            ncol = len(numbers_)
        elif len(numbers_) != ncol:
            raise LogError(f"{name}: line {lineno}: expected {ncol} columns like the first data "
                           f"line, got {len(numbers_)}")
        rows.append(numbers_)
        numbers.append(lineno)
    if len(head) < 3:
        raise LogError(f"{name}: the PSINS header has {len(head)} of its 3 number lines "
                       f"({'; '.join(' '.join(h) for h in PSINS_HEADER)})")
    if not rows:
        raise LogError(f"{name}: no data lines after the PSINS header")
    header = {key: value for keys, values in zip(PSINS_HEADER, head)
              for key, value in zip(keys, values)}
    ts, g = header["ts_ms"] / 1000.0, header["g_mps2"]
    if not (np.isfinite(ts) and ts > 0 and np.isfinite(g) and g > 0):
        raise LogError(f"{name}: header line 2: sampling interval {header['ts_ms']!r} ms and g "
                       f"{g!r} m/s^2 must be positive")
    counts = np.array(rows, dtype=float)
    k = np.arange(1, counts.shape[0] + 1)
    t = header["t0_s"] + k * ts
    if ncol == 7:
        t = t + np.cumsum(counts[:, 6]) * 1e-6
    values = np.empty((counts.shape[0], 7))
    values[:, 0] = t
    # imufile.m: scales = [gf * glv.sec, af * 1e-6 * g] with the header's g
    values[:, 1:4] = counts[:, 0:3] * (np.array(head[2][0:3]) * ARCSEC_TO_RAD)
    values[:, 4:7] = counts[:, 3:6] * (np.array(head[2][3:6]) * (1e-6 * g))
    if opt.dt is None:
        opt.dt = ts
    return values, _Lines(np.array(numbers), _columns("first", False)), False, header


def _is_number(token):
    try:
        float(token)
        return True
    except ValueError:
        return False


# ---------------------------------------------------------------------------
# Checks
# ---------------------------------------------------------------------------
def _check_finite(name, values, where):
    bad = np.argwhere(~np.isfinite(values))
    if bad.size == 0:
        return []
    k, c = bad[0]
    more = f" ({len(bad)} non-finite values in all)" if len(bad) > 1 else ""
    return [LogIssue("error", f"{name}: {where.at(k, c)}: {float(values[k, c])!r} is not "
                              f"finite{more}")]


def _nominal_dt(steps, dt):
    """``dt``, or the median step rounded to 1 ns (unrounded if that would give 0)."""
    if dt is not None:
        return dt
    median = float(np.median(steps))
    return float(np.round(median, 9)) or median


def _check_time(name, t, where, dt):
    """Issues, nominal dt and per-step tick counts (None after an error)."""
    issues = []
    steps = np.diff(t)
    bad = np.nonzero(steps <= 0.0)[0]
    if bad.size:
        k = bad[0] + 1
        what = "repeats" if t[k] == t[k - 1] else "goes back from"
        more = f" ({bad.size} such steps in all)" if bad.size > 1 else ""
        issues.append(LogIssue("error", f"{name}: {where.at(k)}: time {float(t[k])!r} {what} "
                                        f"{float(t[k - 1])!r} at {where.at(k - 1)}: time must "
                                        f"increase{more}"))
        return issues, None, None
    if steps.size == 0 and dt is None:
        issues.append(LogIssue("error", f"{name}: {where.at(0)}: one sample: the time step "
                                        f"cannot be inferred; pass dt"))
        return issues, None, None
    dt_nom = _nominal_dt(steps, dt) if steps.size else dt
    if steps.size and dt is not None:
        median = float(np.median(steps))
        if abs(median - dt) > TIME_TOL * dt:
            issues.append(LogIssue("error", f"{name}: {where.span()}: median time step "
                                            f"{median:.9g} s differs from dt={dt:g} s by more "
                                            f"than {TIME_TOL:.0%} (another rate, or time not "
                                            f"in seconds?)"))
            return issues, None, None
    ratio = steps / dt_nom
    short = np.nonzero(ratio < MIN_STEP_TICKS)[0]
    if short.size:
        k = short[0] + 1
        more = f" ({short.size} such steps in all)" if short.size > 1 else ""
        issues.append(LogIssue("error", f"{name}: {where.at(k)}: time step {steps[k - 1]:.9g} s "
                                        f"after {where.at(k - 1)} is less than half the tick "
                                        f"dt={dt_nom:g} s (a repeated or extra sample?){more}"))
        return issues, None, None
    ticks = np.maximum(1, np.floor(ratio + 0.5)).astype(np.int64)
    gaps = np.nonzero(ratio > GAP_TICKS)[0]
    for k in gaps[:MAX_LISTED]:
        missing = ticks[k] - 1
        issues.append(LogIssue("warning", f"{name}: {where.at(k + 1)}: gap of {steps[k]:.9g} s "
                                          f"after {where.at(k)} (t={float(t[k])!r}): "
                                          f"{_plural(missing, 'missing tick')} of {dt_nom:g} s"))
    if gaps.size > MAX_LISTED:
        rest = gaps[MAX_LISTED:]
        issues.append(LogIssue("warning", f"{name}: {where.at(rest[0] + 1)}: and {rest.size} "
                                          f"more gaps; {gaps.size} gaps, "
                                          f"{int(np.sum(ticks[gaps] - 1))} missing ticks in all"))
    irregular = np.nonzero((np.abs(ratio - 1.0) > TIME_TOL) & (ratio <= GAP_TICKS))[0]
    if irregular.size:
        k = irregular[0] + 1
        issues.append(LogIssue("warning", f"{name}: {where.at(k)}: irregular time step "
                                          f"{steps[k - 1]:.9g} s, more than {TIME_TOL:.0%} from "
                                          f"the tick dt={dt_nom:g} s "
                                          f"({_plural(irregular.size, 'such step')} in all)"))
    return issues, dt_nom, ticks


_GYRO_HINTS = {
    ("increments", "rad"): "these look like deg, not rad (gyro_unit='deg')",
    ("increments", "deg"): "these look like rates, not increments (kind='rates')",
    ("rates", "rad/s"): "these look like deg/s, not rad/s (gyro_unit='deg/s')",
    ("rates", "deg/s"): "these look like deg/h, not deg/s (gyro_unit='deg/h')",
    ("rates", "deg/h"): "check gyro_unit and kind",
}

_ACCEL_READINGS = (("increments", "m/s", "m/s increments"), ("rates", "m/s^2", "m/s^2 rates"),
                   ("rates", "g", "g rates"))


def _check_magnitudes(name, where, kind, gyro_unit, accel_unit, gyro_raw, accel_raw, dt_nom):
    """Unit mix-ups: median |f| outside GRAVITY_BAND, gyro rate above GYRO_RATE_LIMIT.

    The accelerometer goes first: gravity tells increments from rates more
    surely than any gyro level, and its verdict on the kind, if any, becomes
    the gyro's hint.
    """
    issues = []
    other_kind = None
    raw = float(np.median(np.linalg.norm(accel_raw, axis=1)))
    lo, hi = GRAVITY_BAND

    def as_si(k, unit):
        return raw * ACCEL_UNITS[k][unit] * (1.0 / dt_nom if k == "increments" else 1.0)

    force = as_si(kind, accel_unit)
    if not lo <= force <= hi:
        fits = [(k, label) for k, unit, label in _ACCEL_READINGS
                if (k, unit) != (kind, accel_unit) and lo <= as_si(k, unit) <= hi]
        declared = next((label for k, unit, label in _ACCEL_READINGS
                         if (k, unit) == (kind, accel_unit)), f"{accel_unit} {kind}")
        if fits:
            hint = f"these look like {' or '.join(label for _, label in fits)}, not {declared}"
            if all(k != kind for k, _ in fits):
                other_kind = fits[0][0]
        else:
            hint = ("check accel_unit and kind (plausibility=False for a log without "
                    "gravity)")
        issues.append(LogIssue("error", f"{name}: {where.span()}: median specific force "
                                        f"{force:.4g} m/s^2 (read as {declared}) is far from "
                                        f"1 g = {G0} m/s^2: {hint}"))
    per_s = 1.0 / dt_nom if kind == "increments" else 1.0
    rate = np.linalg.norm(gyro_raw, axis=1) * (GYRO_UNITS[kind][gyro_unit] * per_s)
    over = np.nonzero(rate > GYRO_RATE_LIMIT)[0]
    if over.size:
        k = over[0]
        more = f"; {over.size} samples in all" if over.size > 1 else ""
        if other_kind is not None:
            hint = (f"the accelerometer says these are {other_kind}, not {kind} "
                    f"(kind={other_kind!r})")
        else:
            hint = _GYRO_HINTS.get((kind, gyro_unit), "check gyro_unit, the scale and kind")
        issues.append(LogIssue("error", f"{name}: {where.at(k)}: gyro rate {rate[k]:.4g} rad/s "
                                        f"(read as {gyro_unit} {kind}) exceeds "
                                        f"{GYRO_RATE_LIMIT:g} rad/s{more}: {hint}"))
    return issues


# ---------------------------------------------------------------------------
# Reading
# ---------------------------------------------------------------------------
def _load(path, fmt, options, writing=False):
    """(ImuData or None, issues); raises LogError when the file cannot be parsed."""
    name = os.fspath(path)
    plausibility = options.pop("plausibility")
    table_angle = options.pop("table_angle")
    opt = _options(path, fmt, writing=writing, **options)
    header = {}
    if opt.fmt == "npz":
        parsed = _parse_npz(path, name, opt)
        if parsed is None:              # the project's own arrays: pyins.sim.io reads them
            return _load_project(path, name, opt, plausibility, table_angle)
        values, where, has_table = parsed
    elif opt.fmt == "text":
        values, where, has_table = _parse_text(path, name, opt)
    elif opt.fmt == "csv":
        parsed = _parse_csv(path, name, opt)
        if parsed[0] is None:           # the project's own header: pyins.sim.io reads it
            return _load_project(path, name, opt, plausibility, table_angle, text=parsed[1])
        values, where, has_table = parsed
    elif opt.fmt == "psins":
        values, where, has_table, header = _parse_psins(path, name, opt)
    else:
        values, where, has_table = _parse_binary(path, name, opt)
    if has_table and table_angle is not None:
        raise ValueError(f"{name}: table_angle given, but the file has a table-angle column")
    issues = _check_finite(name, values, where)
    if issues:
        return None, issues
    cols = _columns(opt.time_col, has_table)
    gyro_raw = values[:, cols.index("gyro_x"):cols.index("gyro_x") + 3] * opt.gyro_scale
    accel_raw = values[:, cols.index("accel_x"):cols.index("accel_x") + 3] * opt.accel_scale
    n = values.shape[0]
    if opt.time_col == "none":
        t, dt_nom = None, opt.dt
        ticks = np.arange(1, n + 1, dtype=np.int64)
        intervals = np.full(n, dt_nom)
    else:
        t = values[:, cols.index("t")]
        time_issues, dt_nom, steps = _check_time(name, t, where, opt.dt)
        issues += time_issues
        if steps is None:
            return None, issues
        tick0 = np.floor(t[0] / dt_nom + 0.5)
        if not abs(tick0) < 2.0 ** 62:
            issues.append(LogIssue("error", f"{name}: {where.at(0)}: time {float(t[0])!r} s is "
                                            f"too large for tick numbers of {dt_nom:g} s"))
            return None, issues
        ticks = np.concatenate(([0], np.cumsum(steps))) + np.int64(tick0)
        intervals = np.concatenate(([dt_nom], np.diff(t)))
    if plausibility:
        issues += _check_magnitudes(name, where, opt.kind, opt.gyro_unit, opt.accel_unit,
                                    gyro_raw, accel_raw, dt_nom)
    if any(i.level == "error" for i in issues):
        return None, issues
    gyro = gyro_raw * GYRO_UNITS[opt.kind][opt.gyro_unit]
    accel = accel_raw * ACCEL_UNITS[opt.kind][opt.accel_unit]
    if opt.kind == "rates":     # rectangular rule: rate at t_k held over [t_{k-1}, t_k]
        gyro = gyro * intervals[:, None]
        accel = accel * intervals[:, None]
    perm, sign = _perm_sign(opt.axes)
    dtheta_p = gyro[:, perm] * sign
    dv_p = accel[:, perm] * sign
    if has_table:
        angle = values[:, cols.index("table")] * TABLE_UNITS[opt.table_unit]
    else:
        angle = np.full(n, 0.0 if table_angle is None else float(table_angle))
    metadata = {"source": name, "format": opt.fmt, "kind": opt.kind,
                "gyro_unit": opt.gyro_unit, "accel_unit": opt.accel_unit,
                "table_unit": opt.table_unit if has_table else None,
                "axes": opt.axes_spec if isinstance(opt.axes_spec, str) else opt.axes.tolist(),
                "time_col": opt.time_col, "dt_inferred": opt.dt is None,
                "t_first": None if t is None else float(t[0])}
    if opt.gyro_scale != 1.0 or opt.accel_scale != 1.0:
        metadata.update(gyro_scale=opt.gyro_scale, accel_scale=opt.accel_scale)
    if header:
        metadata["psins_header"] = header
    return ImuData(ticks, dtheta_p, dv_p, angle, dt_nom, metadata), issues


def _load_project(path, name, opt, plausibility, table_angle, text=None):
    if table_angle is not None:
        raise ValueError(f"{name}: table_angle does not apply: {opt.fmt} files hold the angle")
    if opt.fmt in ("csv", "npz"):
        default = (opt.kind == "increments" and opt.gyro_unit == "rad" and opt.accel_unit == "m/s"
                   and opt.gyro_scale == 1.0 and opt.accel_scale == 1.0 and opt.columns is None
                   and opt.table is None and np.array_equal(opt.axes, np.eye(3)))
        if not default:
            what = f"csv header ({io.CSV_HEADER})" if opt.fmt == "csv" else "npz file"
            raise ValueError(f"{name}: the project's {what} holds rad, m/s and the p axes; unit, "
                             f"axis, scale and column options do not apply")
    try:
        if opt.fmt == "npz":
            packed = compression_of(path) is not None
            data = io.load_npz(path, file=_io.BytesIO(_read_bytes(path, name)) if packed else None)
        else:
            data = io.load_csv(path, dt=opt.dt, file=_io.StringIO(text, newline=""))
    except ValueError as exc:
        raise LogError(str(exc)) from exc
    issues = []
    n = data.tick.shape[0]
    if n == 0:
        raise LogError(f"{name}: no samples")
    where = _Samples(n)
    steps = np.diff(data.tick)
    gaps = np.nonzero(steps > 1)[0]
    for k in gaps[:MAX_LISTED]:
        issues.append(LogIssue("warning", f"{name}: {where.at(k + 1)}: "
                                          f"{_plural(steps[k] - 1, 'missing tick')} after tick "
                                          f"{data.tick[k]}"))
    if gaps.size > MAX_LISTED:
        issues.append(LogIssue("warning", f"{name}: {where.at(gaps[MAX_LISTED] + 1)}: and "
                                          f"{gaps.size - MAX_LISTED} more gaps; {gaps.size} "
                                          f"gaps, {int(np.sum(steps[gaps] - 1))} missing ticks "
                                          f"in all"))
    if plausibility:
        issues += _check_magnitudes(name, where, "increments", "rad", "m/s", data.dtheta_p,
                                    data.dv_p, data.dt if data.dt else DEFAULT_DT)
    return (None if any(i.level == "error" for i in issues) else data), issues


def read_log(path, fmt=None, *, dt=None, kind="increments", gyro_unit=None, accel_unit=None,
             axes="rfu", time_col=None, table=None, table_unit="rad", table_angle=None,
             strict=True, plausibility=True, gyro_scale=1.0, accel_scale=1.0, columns=None,
             strict_hint="read_log(..., strict=False) accepts it"):
    """Read an IMU log into the project's samples.

    Parameters
    ----------
    path : str or PathLike
    fmt : {'npz', 'csv', 'text', 'binary', 'psins'} or None
        None: from the extension (.npz, .csv, .txt/.dat/.asc, .bin, .imu),
        looking through .gz/.xz/.bz2. Compressed files are recognised by their
        first bytes whatever the name.
    dt : float, optional
        Nominal tick length [s]. With a time column the median step must lie
        within 1 % of it; without, it is inferred (median step, to 1 ns).
        Required for ``time_col='none'``; for CSV it is recorded in the result.
    kind : {'increments', 'rates'}
    gyro_unit : str, optional
        'rad' or 'deg' for increments (default 'rad'); 'rad/s', 'deg/s' or
        'deg/h' for rates (default 'rad/s').
    accel_unit : str, optional
        'm/s' for increments; 'm/s^2' (default) or 'g' for rates.
    axes : str or (3, 3) array_like
        The file's axes: 'rfu' (default), 'frd', 'flu', aliases 'enu', 'ned',
        'nwu', ``'<name>->rfu'``, or a signed permutation M, v_p = M v_file.
    time_col : {'last', 'first', 'none'} or None
        Text layout; None means 'last' (PSINS) for text. Binary is always
        'first'.
    table : bool or None
        Whether the table angle is the last column. None: text decides from
        the first data line, binary means False.
    table_unit : {'rad', 'deg'}
    table_angle : float, optional
        Constant table angle [rad] for a log without the column (default 0).
    strict : bool
        True (default): warnings (gaps, irregular steps) raise too. False:
        they are returned in ``metadata['warnings']``.
    plausibility : bool
        Check the magnitudes for unit mix-ups (see the module docstring).
    gyro_scale, accel_scale : float
        The unit of one count: the file's numbers are multiplied by it, then
        read in ``gyro_unit``/``accel_unit`` (pulses: ``gyro_unit='arcsec',
        gyro_scale=0.1`` for 0.1" a pulse). Not for npz or PSINS .imu.
    columns : dict, optional
        CSV only: role -> header name for names the reader does not know
        (roles `CSV_ROLES`: t, tick, gyro_x.., accel_x.., table).
    strict_hint : str
        How the caller accepts warnings, named in the strict error.

    Returns
    -------
    ImuData
        dtheta_p [rad], dv_p [m/s], table_angle_rad [rad] in frame p; tick
        numbers; dt the nominal tick [s]; metadata names the source and the
        options (text and binary).

    Raises
    ------
    LogError
        The first error (or, when strict, warning) found, one line naming
        the file, the line or record and the reason.
    """
    data, issues = _load(path, fmt, dict(
        dt=dt, kind=kind, gyro_unit=gyro_unit, accel_unit=accel_unit, axes=axes,
        time_col=time_col, table=table, table_unit=table_unit, table_angle=table_angle,
        plausibility=plausibility, gyro_scale=gyro_scale, accel_scale=accel_scale,
        columns=columns))
    for issue in issues:
        if issue.level == "error":
            raise LogError(issue.message)
    if strict and issues:
        raise LogError(f"{issues[0].message} ({strict_hint})")
    data.metadata["warnings"] = [issue.message for issue in issues]
    return data


def parse_columns(text, option="columns"):
    """``"t=stamp,gyro_x=a"`` -> ``{"t": "stamp", "gyro_x": "a"}`` (the CLI's
    --columns); a malformed list is a ValueError naming ``option``."""
    pairs = [item.partition("=") for item in text.split(",") if item.strip()]
    if not pairs or any(not eq or not role.strip() or not col.strip() for role, eq, col in pairs):
        raise ValueError(f"{option} {text!r}: expected ROLE=NAME,... (roles: "
                         f"{', '.join(dict.fromkeys(CSV_ROLES + NPZ_ROLES))})")
    return {role.strip(): col.strip() for role, _, col in pairs}


def bridge_gaps(data, how="bridge_gaps"):
    """``data`` with every skipped tick filled in, and the number of ticks added.

    The rule is the firmware's own for a sequence gap in navigation
    (docs/core.md, "skipped ticks"): the increments of the j-th of m missing
    ticks are interpolated linearly between the sample before the gap and the
    one after it, ``x_prev + (x_next - x_prev) * j / (m + 1)``, the table angle
    along the shorter turn between its two readings. What moved during the
    gap is not in the log, so the bridge is a guess that keeps the clock right
    (each sample is one tick to the firmware): callers say that they used it.

    The result's ``metadata["warnings"]`` is the input's (the gaps as
    `read_log` found them) and, when ticks were added, a last line saying how
    many and that ``how`` bridged them.
    """
    tick = np.asarray(data.tick, dtype=np.int64)
    steps = np.diff(tick)
    gaps = np.nonzero(steps > 1)[0]
    warnings = list(data.metadata.get("warnings", ()))
    if gaps.size == 0:
        data.metadata["warnings"] = warnings
        return data, 0
    pieces = {"tick": [], "dtheta_p": [], "dv_p": [], "table_angle_rad": []}
    start = 0
    for k in gaps:
        m = int(steps[k] - 1)
        j = np.arange(1, m + 1)
        w = (j / (m + 1.0))[:, None]
        for key in ("dtheta_p", "dv_p"):
            a = getattr(data, key)
            pieces[key] += [a[start:k + 1], a[k] + (a[k + 1] - a[k]) * w]
        ang = data.table_angle_rad
        turn = np.mod(ang[k + 1] - ang[k] + np.pi, 2.0 * np.pi) - np.pi
        pieces["table_angle_rad"] += [ang[start:k + 1], ang[k] + turn * w[:, 0]]
        pieces["tick"] += [tick[start:k + 1], tick[k] + j]
        start = k + 1
    for key in pieces:
        pieces[key].append((tick if key == "tick" else getattr(data, key))[start:])
    added = int(np.sum(steps[gaps] - 1))
    source = data.metadata.get("source", "the log")
    warnings.append(f"{source}: {_plural(added, 'missing tick')} bridged by linear interpolation "
                    f"of the neighbouring samples ({how}); the motion in them is not in the log")
    metadata = dict(data.metadata, bridged_ticks=added, warnings=warnings)
    return ImuData(np.concatenate(pieces["tick"]), np.concatenate(pieces["dtheta_p"]),
                   np.concatenate(pieces["dv_p"]), np.concatenate(pieces["table_angle_rad"]),
                   data.dt, metadata), added


def check_log(path, fmt=None, **options):
    """All findings on a log, as a list of `LogIssue` (errors and warnings).

    Takes the options of `read_log` (``strict`` does not apply). An empty
    list means `read_log` with the same options returns the data. A file that
    cannot be parsed gives one error; otherwise every check runs that the
    earlier findings leave meaningful (no time checks after a NaN, no
    magnitude checks after a time error). Wrong options raise ValueError.
    """
    full = dict(dt=None, kind="increments", gyro_unit=None, accel_unit=None, axes="rfu",
                time_col=None, table=None, table_unit="rad", table_angle=None,
                plausibility=True, gyro_scale=1.0, accel_scale=1.0, columns=None)
    unknown = set(options) - set(full)
    if unknown:
        raise TypeError(f"check_log: unknown options {sorted(unknown)}")
    full.update(options)
    try:
        return _load(path, fmt, full)[1]
    except LogError as exc:
        return [LogIssue("error", str(exc))]


# ---------------------------------------------------------------------------
# Writing
# ---------------------------------------------------------------------------
def _data_arrays(name, data):
    tick = np.asarray(data.tick)
    dtheta = np.asarray(data.dtheta_p, dtype=float)
    dv = np.asarray(data.dv_p, dtype=float)
    angle = np.asarray(data.table_angle_rad, dtype=float)
    n = tick.shape[0] if tick.ndim == 1 else -1
    if dtheta.shape != (n, 3) or dv.shape != (n, 3) or angle.shape != (n,):
        raise ValueError(f"{name}: expected tick (N,), dtheta_p (N, 3), dv_p (N, 3), "
                         f"table_angle_rad (N,); got {tick.shape}, {dtheta.shape}, {dv.shape}, "
                         f"{angle.shape}")
    if not np.issubdtype(tick.dtype, np.integer) or np.any(np.diff(tick) <= 0):
        raise ValueError(f"{name}: tick must be strictly increasing integers")
    for label, a in (("dtheta_p", dtheta), ("dv_p", dv), ("table_angle_rad", angle)):
        if not np.all(np.isfinite(a)):
            raise ValueError(f"{name}: {label} has NaN or Inf; the readers would reject the file")
    return tick.astype(np.int64), dtheta, dv, angle


def write_log(path, data, fmt=None, *, dt=None, kind="increments", gyro_unit=None,
              accel_unit=None, axes="rfu", time_col=None, table=None, table_unit="rad",
              header=True):
    """Write samples in one of the layouts `read_log` reads.

    Parameters
    ----------
    path : str or PathLike
    data : ImuData
        (or anything with ``tick``, ``dtheta_p``, ``dv_p``,
        ``table_angle_rad``, ``dt`` and ``metadata``).
    fmt, kind, gyro_unit, accel_unit, axes, time_col, table_unit
        As in `read_log`; reading back with the same options gives the data
        back (bit for bit in rad, m/s and any axes; see docs/log-formats.md
        for the rounding of unit and rate conversions).
    dt : float, optional
        Tick length [s]; default ``data.dt``. Times are written as tick * dt.
    table : bool or None
        Write the table-angle column. None: text writes it when any angle is
        not +0.0; binary writes none (and refuses non-zero angles, which it
        would lose: pass True, and ``table=True`` when reading).
    header : bool
        Text only: a first line ``% columns: ...`` naming columns and units
        (``%`` is a comment for MATLAB ``load`` and for `read_log`; pass False
        for tools that take no comment lines, e.g. KF-GINS).

    Floats are written with ``%.17g``, which round-trips every float64. A
    path ending in .gz, .xz or .bz2 is written compressed (the layout from
    the name without it, as when reading).
    """
    if format_of(path, fmt) == "psins":
        raise ValueError(f"{os.fspath(path)}: writing PSINS .imu is not supported (it rounds the "
                         f"increments to pulse counts); write text, time_col='last', for PSINS")
    plain, comp = _split_compression(path)
    if comp is not None:
        if fmt is None:
            fmt = format_of(plain)
        opener = next(o for c, _, o in COMPRESSIONS.values() if c == comp)
        tmp = f"{plain}.{os.getpid()}.tmp"
        try:
            write_log(tmp, data, fmt, dt=dt, kind=kind, gyro_unit=gyro_unit,
                      accel_unit=accel_unit, axes=axes, time_col=time_col, table=table,
                      table_unit=table_unit, header=header)
            with open(tmp, "rb") as src, opener(path, "wb") as dst:
                dst.write(src.read())
        finally:
            if os.path.exists(tmp):
                os.remove(tmp)
        return
    name = os.fspath(path)
    opt = _options(path, fmt, dt=dt, kind=kind, gyro_unit=gyro_unit, accel_unit=accel_unit,
                   axes=axes, time_col=time_col, table=table, table_unit=table_unit,
                   writing=True)
    tick, dtheta, dv, angle = _data_arrays(name, data)
    dt = opt.dt if opt.dt is not None else data.dt
    if opt.fmt == "npz":
        if dt is None:
            raise ValueError(f"{name}: an npz stores dt: data.dt is None, pass dt")
        io.save_npz(path, dtheta, dv, angle, dt, metadata=data.metadata, tick=tick)
        return
    if opt.fmt == "csv":
        io.save_csv(path, dtheta, dv, angle, tick=tick)
        return
    if dt is None and (opt.time_col != "none" or opt.kind == "rates"):
        raise ValueError(f"{name}: data.dt is None: pass dt to write times or rates")
    has_table = opt.table
    if has_table is None:
        # any angle but +0.0 (a -0.0 too, so that text round-trips bit for bit)
        has_table = opt.fmt == "text" and bool(np.any((angle != 0.0) | np.signbit(angle)))
    if not has_table and np.any(angle != 0.0):
        raise ValueError(f"{name}: table=False would drop non-zero table angles; pass table=True")
    if opt.time_col == "none":
        if np.any(np.diff(tick) != 1):
            raise ValueError(f"{name}: ticks skip, and time_col='none' cannot show the gaps")
        t = None
        intervals = np.full(tick.shape[0], dt)
    else:
        t = tick * float(dt)
        intervals = np.concatenate(([dt], np.diff(t)))   # what the reader will use
    perm, sign = _perm_sign(opt.axes)
    gyro = np.empty_like(dtheta)
    accel = np.empty_like(dv)
    gyro[:, perm] = dtheta * sign
    accel[:, perm] = dv * sign
    if opt.kind == "rates":
        gyro = gyro / intervals[:, None]
        accel = accel / intervals[:, None]
    gyro = gyro / GYRO_UNITS[opt.kind][opt.gyro_unit]
    accel = accel / ACCEL_UNITS[opt.kind][opt.accel_unit]
    parts = {"gyro_x": gyro[:, 0], "gyro_y": gyro[:, 1], "gyro_z": gyro[:, 2],
             "accel_x": accel[:, 0], "accel_y": accel[:, 1], "accel_z": accel[:, 2],
             "t": t, "table": angle / TABLE_UNITS[opt.table_unit]}
    columns = _columns(opt.time_col, has_table)
    matrix = np.column_stack([parts[c] for c in columns])
    if opt.fmt == "binary":
        with open(path, "wb") as f:
            f.write(matrix.astype("<f8").tobytes())
        return
    line = " ".join(["%.17g"] * len(columns)) + "\n"
    with open(path, "w", newline="\n") as f:
        if header:
            units = {"gyro": opt.gyro_unit, "accel": opt.accel_unit, "t": "s",
                     "table": opt.table_unit}
            names = " ".join(f"{c}[{units[c.split('_')[0]]}]" for c in columns)
            f.write(f"% columns: {names}; kind={opt.kind}; axes={_axes_label(opt)}\n")
        for row in matrix.tolist():
            f.write(line % tuple(row))


def _axes_label(opt):
    if isinstance(opt.axes_spec, str):
        return opt.axes_spec
    return "M=" + str(opt.axes.tolist()).replace(" ", "")
