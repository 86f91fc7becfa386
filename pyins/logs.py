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

Blocks
------
`LogReader` reads a log in blocks of ``block`` samples with every check of
`read_log` (the same errors, naming the same lines, across block
boundaries), deciding the nominal dt and the gravity check on the first
``probe`` samples; `read_log` is `LogReader` read whole. Text, binary,
named-column CSV and PSINS .imu stream (compressed too); npz and the
project's CSV are read whole and handed out in blocks. `LogWriter` writes a
log block by block (`write_log` takes an iterable of blocks too) under a
temporary name renamed at the end; `GapBridge` bridges gaps in blocks;
`NpzWriter` and `iter_npz` write and read an npz's arrays in rows.

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
import json
import lzma
import os
import zipfile
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


def _decode(raw, path, name, strip=True):
    """The UTF-8 text of a file's bytes; not UTF-8 is a LogError naming the byte."""
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        comp = compression_of(path)
        what = f"after {comp} decompression, " if comp else ""
        raise LogError(f"{name}: {what}byte offset {exc.start}: not UTF-8 text (a binary log? "
                       f"pass fmt='binary')") from None
    return text.lstrip("\ufeff") if strip else text


def _text_lines(path, name):
    """(1-based line number, line) of a text file, decompressed, UTF-8, read whole."""
    text = _decode(_read_bytes(path, name), path, name)
    return enumerate(_io.StringIO(text, newline=None), start=1)


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
class _Where:
    """Positions in a window of the log (the probe, or a block with the last
    sample before it as row 0): 1-based file lines for text (``numbers``),
    0-based records for binary and 0-based samples for npz, both counted
    from the start of the file (``start`` is the window's row 0)."""

    def __init__(self, kind, columns, start=0, numbers=None, n=0):
        self.kind, self.columns, self.start, self.numbers, self.n = kind, columns, start, numbers, n

    def at(self, k, col=None):
        if self.kind == "lines":
            s = f"line {self.numbers[k]}"
            return s if col is None else f"{s}, column {col + 1} ({self.columns[col]})"
        g = self.start + int(k)
        if self.kind == "records":
            s = f"record {g} (0-based, byte offset {g * 8 * len(self.columns)})"
            return s if col is None else f"{s}, field {col + 1} ({self.columns[col]})"
        return f"sample {g} (0-based)"

    def span(self):
        if self.kind == "lines":
            return f"lines {self.numbers[0]}-{self.numbers[-1]}"
        what = "records" if self.kind == "records" else "samples"
        return f"{what} {self.start}-{self.start + self.n - 1} (0-based)"


class _Layout:
    """What a parser found out about the file before its first rows: the
    columns, whether the table angle is one, the kind of positions; the
    PSINS header; ``project`` for the project's own csv/npz (read by
    `pyins.sim.io`); ``n`` the samples when the size tells (plain binary)."""
    time_col = None
    has_table = False
    columns = None
    kind = "lines"
    header = None
    project = None
    n = None

    def set(self, time_col, has_table, kind="lines"):
        self.time_col, self.has_table, self.kind = time_col, bool(has_table), kind
        self.columns = _columns(time_col, has_table)


# ---------------------------------------------------------------------------
# Parsing: each parser yields (values (m, ncol) float array, line numbers or
# None) chunks of at most `size` rows (size None: one chunk of all rows)
# ---------------------------------------------------------------------------
TEXT_CHUNK_BYTES = 1 << 20   #: bytes read at a time from a text log


def _full(size):
    return size is None


def _read_exact(f, n, comp, name):
    """Up to ``n`` bytes (fewer only at the end; None: all); a broken stream is a LogError."""
    parts, got = [], 0
    while n is None or got < n:
        try:
            raw = f.read() if n is None else f.read(n - got)
        except (OSError, EOFError, lzma.LZMAError, ValueError) as exc:
            if comp is None:
                raise
            raise LogError(f"{name}: not a complete {comp} stream ({exc}): the file is cut or "
                           f"damaged") from None
        if not raw:
            break
        if n is None:
            return raw
        parts.append(raw)
        got += len(raw)
    return b"".join(parts)


def _stream_lines(path, name):
    """(1-based line number, line) of a text file, decompressed, UTF-8, read
    TEXT_CHUNK_BYTES at a time: `_text_lines` in bounded memory. Chunks are cut
    after a b"\\n" (never inside a UTF-8 sequence or a \\r\\n pair), so the lines
    and the byte offset of a decoding error are those of the whole file."""
    comp, opener = _opener(path)
    offset, carry, first, lineno = 0, b"", True, 0
    with opener(path, "rb") as f:
        while True:
            raw = _read_exact(f, TEXT_CHUNK_BYTES, comp, name)
            buf = carry + raw
            if raw:
                cut = buf.rfind(b"\n") + 1
                if cut == 0:
                    carry = buf
                    continue
                piece, carry = buf[:cut], buf[cut:]
            else:
                piece, carry = buf, b""
            if piece:
                try:
                    text = piece.decode("utf-8")
                except UnicodeDecodeError as exc:
                    what = f"after {comp} decompression, " if comp else ""
                    raise LogError(f"{name}: {what}byte offset {offset + exc.start}: not UTF-8 "
                                   f"text (a binary log? pass fmt='binary')") from None
                if first:
                    text, first = text.lstrip("\ufeff"), False
                for line in _io.StringIO(text, newline=None):
                    lineno += 1
                    yield lineno, line
                offset += len(piece)
            if not raw:
                return


def _lines(path, name, size):
    """The lines of a text log: the whole file decoded first when read whole
    (`read_log`: a decoding error anywhere comes first, as it always did),
    else streamed."""
    return _text_lines(path, name) if _full(size) else _stream_lines(path, name)


def _chunk(rows, numbers):
    return np.array(rows, dtype=float), np.array(numbers)


def _chunks_text(path, name, opt, lay, size):
    base = 6 + (opt.time_col != "none")
    ncol = None if opt.table is None else base + bool(opt.table)
    if ncol is not None:
        lay.set(opt.time_col, ncol > base)
    rows, numbers, any_rows = [], [], False
    first_line = None
    for lineno, line in _lines(path, name, size):
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
            lay.set(opt.time_col, ncol > base)
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
        if not _full(size) and len(rows) >= size:
            yield _chunk(rows, numbers)
            rows, numbers, any_rows = [], [], True
    if rows:
        yield _chunk(rows, numbers)
    elif not any_rows:
        raise LogError(f"{name}: no data lines (only blank or comment lines)")


def _chunks_binary(path, name, opt, lay, size):
    lay.set("first", opt.table, kind="records")
    columns = lay.columns
    rec = 8 * len(columns)
    kind = "with the table angle" if opt.table else "without the table angle"

    def wrong_size(total):
        n, rest = divmod(total, rec)
        return LogError(f"{name}: size {total} bytes is not a whole number of {rec}-byte "
                        f"records ({kind}): {_plural(n, 'whole record')} and {rest} bytes "
                        f"over")

    comp, opener = _opener(path)
    if comp is None:       # the size tells: refused before a record is read
        total = os.path.getsize(path)
        if total % rec:
            raise wrong_size(total)
        if total == 0:
            raise LogError(f"{name}: no records (empty file)")
        lay.n = total // rec
    want = None if _full(size) else size * rec
    total = 0
    with opener(path, "rb") as f:
        while True:
            raw = _read_exact(f, want, comp, name)
            total += len(raw)
            whole = len(raw) // rec * rec
            last = want is None or len(raw) < want
            if last and len(raw) % rec:
                raise wrong_size(total)
            if total == 0:
                raise LogError(f"{name}: no records (empty file)")
            if whole:
                yield (np.frombuffer(raw, dtype="<f8", count=whole // 8)
                       .reshape(whole // rec, len(columns)).astype(float), None)
            if last:
                return


def _chunks_csv(path, name, opt, lay, size):
    """A CSV whose header line names the columns: chunks in the text layout
    "first" (or "none" without a time column); nothing, with
    ``lay.project`` set, for the project's own header (pyins.sim.io reads it)."""
    lines = _lines(path, name, size)
    header = None
    for lineno, line in lines:
        if line.strip() and line.lstrip()[0] not in "#%":
            header = line
            break
    if header is None:
        raise LogError(f"{name}: no header line (only blank or comment lines)")
    header_line = lineno
    if lineno == 1 and header.strip() == io.CSV_HEADER:
        lay.project = "csv"
        return
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
    lay.set(opt.time_col, has_table)
    columns = lay.columns
    roles = [time_role if c == "t" else c for c in columns]
    take = [index[r] for r in roles]

    def chunk(rows, numbers):
        values, numbers = _chunk(rows, numbers)
        if time_role == "tick":
            values[:, 0] = values[:, 0] * opt.dt
        return values, numbers

    rows, numbers, any_rows = [], [], False
    for lineno, line in lines:
        if not line.strip() or line.lstrip()[0] in "#%":
            continue
        tokens = line.rstrip("\n").split(sep) if sep else line.split()
        if len(tokens) != len(fields):
            raise LogError(f"{name}: line {lineno}: expected {len(fields)} fields like the header "
                           f"(line {header_line}), got {len(tokens)}")
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
        if not _full(size) and len(rows) >= size:
            yield chunk(rows, numbers)
            rows, numbers, any_rows = [], [], True
    if rows:
        yield chunk(rows, numbers)
    elif not any_rows:
        raise LogError(f"{name}: no data lines after the header (line {header_line})")


def _chunks_npz(path, name, opt, lay, size):
    """An npz is read whole (see `LogReader`): one chunk; nothing, with
    ``lay.project`` set, for the project's own arrays."""
    parsed = _parse_npz(path, name, opt)
    if parsed is None:
        lay.project = "npz"
        return
    values, where, has_table = parsed
    lay.set(opt.time_col, has_table, kind="samples")
    yield values, None


def _chunks_psins(path, name, opt, lay, size):
    """PSINS's compact SIMU text file (.imu, written and read by PSINS's
    base/io/imufile.m): '%' comment lines, the first naming 'PSINS' and 'SIMU';
    three header lines (attitude and velocity; position, t0 [s], the sampling
    interval [ms] and g [m/s^2]; the gyro scale factors [arcsec] and the
    accelerometer scale factors [ug*s, ug = 1e-6 of that g]); then integer
    counts g_x g_y g_z a_x a_y a_z in x-right y-forward z-up axes, and an
    optional 7th column, the sampling-time dither [us]. Sample k (1-based)
    is stamped t0 + k ts + 1e-6 sum(dither[1..k]). Chunks in the "first"
    layout; ``lay.header`` the header's numbers by name."""
    lay.set("first", False)
    lines = _lines(path, name, size)
    first = next(lines, (1, ""))[1]
    if "PSINS" not in first or "SIMU" not in first:
        raise LogError(f"{name}: line 1: not a PSINS-format SIMU file (its first line names "
                       f"'PSINS' and 'SIMU'), got {first.strip()[:60]!r}")
    head, rows, numbers, ncol = [], [], [], None
    state = dict(k=0, dither=0.0, checked=False)

    def chunk(rows, numbers):
        if not state["checked"]:       # the header's interval and g, before the first counts are used
            ts_ms, g = lay.header["ts_ms"], lay.header["g_mps2"]
            if not (np.isfinite(ts_ms / 1000.0) and ts_ms / 1000.0 > 0 and np.isfinite(g) and g > 0):
                raise LogError(f"{name}: header line 2: sampling interval {ts_ms!r} ms and g "
                               f"{g!r} m/s^2 must be positive")
            state["checked"] = True
        ts, g = lay.header["ts_ms"] / 1000.0, lay.header["g_mps2"]
        counts = np.array(rows, dtype=float)
        m = counts.shape[0]
        k = np.arange(state["k"] + 1, state["k"] + m + 1)
        state["k"] += m
        t = lay.header["t0_s"] + k * ts
        if ncol == 7:
            # the running sum continued from the chunks before (sequential, as one cumsum)
            dither = np.cumsum(np.concatenate(([state["dither"]], counts[:, 6])))[1:]
            state["dither"] = dither[-1]
            t = t + dither * 1e-6
        values = np.empty((m, 7))
        values[:, 0] = t
        # imufile.m: scales = [gf * glv.sec, af * 1e-6 * g] with the header's g
        values[:, 1:4] = counts[:, 0:3] * (np.array(head[2][0:3]) * ARCSEC_TO_RAD)
        values[:, 4:7] = counts[:, 3:6] * (np.array(head[2][3:6]) * (1e-6 * g))
        return values, np.array(numbers)

    any_rows = False
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
            if len(head) == 3:
                lay.header = {key: value for keys, values in zip(PSINS_HEADER, head)
                              for key, value in zip(keys, values)}
                if opt.dt is None:
                    opt.dt = lay.header["ts_ms"] / 1000.0
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
        if not _full(size) and len(rows) >= size:
            yield chunk(rows, numbers)
            rows, numbers, any_rows = [], [], True
    if len(head) < 3:
        raise LogError(f"{name}: the PSINS header has {len(head)} of its 3 number lines "
                       f"({'; '.join(' '.join(h) for h in PSINS_HEADER)})")
    if rows:
        yield chunk(rows, numbers)
    elif not any_rows:
        raise LogError(f"{name}: no data lines after the PSINS header")


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
    return np.hstack(parts), None, has_table


#: PSINS .imu: the data header's three lines (imufile.m, PSINS base/io)
PSINS_HEADER = (("pitch0_deg", "roll0_deg", "yaw0_deg", "ve0_mps", "vn0_mps", "vu0_mps"),
                ("lat0_deg", "lon0_deg", "height0_m", "t0_s", "ts_ms", "g_mps2"),
                ("gf_x_arcsec", "gf_y_arcsec", "gf_z_arcsec", "af_x_ugs", "af_y_ugs",
                 "af_z_ugs"))



_PARSERS = {"text": _chunks_text, "binary": _chunks_binary, "csv": _chunks_csv,
            "npz": _chunks_npz, "psins": _chunks_psins}


def _is_number(token):
    try:
        float(token)
        return True
    except ValueError:
        return False


# ---------------------------------------------------------------------------
# Checks: the log seen in windows, each finding counted across all of them
# ---------------------------------------------------------------------------
def _nominal_dt(steps, dt):
    """``dt``, or the median step rounded to 1 ns (unrounded if that would give 0)."""
    if dt is not None:
        return dt
    median = float(np.median(steps))
    return float(np.round(median, 9)) or median


_GYRO_HINTS = {
    ("increments", "rad"): "these look like deg, not rad (gyro_unit='deg')",
    ("increments", "deg"): "these look like rates, not increments (kind='rates')",
    ("rates", "rad/s"): "these look like deg/s, not rad/s (gyro_unit='deg/s')",
    ("rates", "deg/s"): "these look like deg/h, not deg/s (gyro_unit='deg/h')",
    ("rates", "deg/h"): "check gyro_unit and kind",
}

_ACCEL_READINGS = (("increments", "m/s", "m/s increments"), ("rates", "m/s^2", "m/s^2 rates"),
                   ("rates", "g", "g rates"))


def _check_gravity(name, where, kind, accel_unit, accel_raw, dt_nom):
    """The accelerometer's half of the unit checks: median |f| outside
    GRAVITY_BAND. Returns (issues, the kind the accelerometer says the log
    is, or None). It goes before the gyro's: gravity tells increments from
    rates more surely than any gyro level, and its verdict on the kind, if
    any, becomes the gyro's hint."""
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
    return issues, other_kind


def _check_magnitudes(name, where, kind, gyro_unit, accel_unit, gyro_raw, accel_raw, dt_nom):
    """Unit mix-ups: median |f| outside GRAVITY_BAND, gyro rate above GYRO_RATE_LIMIT
    (the project's own files, read whole)."""
    issues, other_kind = _check_gravity(name, where, kind, accel_unit, accel_raw, dt_nom)
    scan = _Scan(name, None, kind, gyro_unit, plausibility=True)
    scan.dt_nom, scan.other_kind = dt_nom, other_kind
    scan.gyro_check(gyro_raw, where, 0)
    return issues + scan.gyro_issues()


class _Scan:
    """The checks of `read_log` (module docstring, Validation) over a log seen
    in windows: the probe (the first samples, whole), then one block at a time
    with the last sample before it as row 0, so that every step is checked
    once, across block boundaries too. Each finding keeps its first place and
    its count over the whole log; `issues` words them as `read_log` always
    has, in its order (a non-finite value before any time error, a time error
    before the magnitudes)."""

    def __init__(self, name, timed, kind, gyro_unit, plausibility, dt=None, accel_unit=None):
        self.name, self.timed, self.kind, self.gyro_unit = name, timed, kind, gyro_unit
        self.accel_unit = accel_unit
        self.plausibility, self.dt = plausibility, dt
        self.dt_nom = dt
        self.finite = self.mono = self.one = self.median = self.short = None
        self.n_finite = self.n_mono = self.n_short = 0
        self.gaps, self.n_gaps, self.missing, self.gap_more_at = [], 0, 0, None
        self.irregular, self.n_irregular = None, 0
        self.tick0, self.tick0_value = None, None
        self.gravity, self.other_kind = [], None
        self.gyro, self.n_gyro = None, 0

    # -- the probe: what is decided once, on the first samples ----------------
    def probe(self, values, t, where, accel_raw, eof):
        """The nominal dt (the median step, or dt checked against it), the
        first tick number and the gravity check, from the probe's samples."""
        name = self.name
        if not np.all(np.isfinite(values)):
            return                      # the finite error comes first; nothing else is said
        if self.timed:
            steps = np.diff(t)
            if np.any(steps <= 0.0):
                return                  # the time error comes first
            if steps.size == 0 and self.dt is None:
                self.one = LogIssue("error", f"{name}: {where.at(0)}: one sample: the time step "
                                             f"cannot be inferred; pass dt")
                return
            self.dt_nom = _nominal_dt(steps, self.dt) if steps.size else self.dt
            if steps.size and self.dt is not None:
                median = float(np.median(steps))
                if abs(median - self.dt) > TIME_TOL * self.dt:
                    self.median = LogIssue("error", f"{name}: {where.span()}: median time step "
                                                    f"{median:.9g} s differs from dt={self.dt:g} s "
                                                    f"by more than {TIME_TOL:.0%} (another rate, or "
                                                    f"time not in seconds?)")
                    return
            tick0 = np.floor(t[0] / self.dt_nom + 0.5)
            if not abs(tick0) < 2.0 ** 62:
                self.tick0 = LogIssue("error", f"{name}: {where.at(0)}: time {float(t[0])!r} s is "
                                               f"too large for tick numbers of {self.dt_nom:g} s")
            self.tick0_value = tick0
        if self.plausibility:
            self.gravity, self.other_kind = _check_gravity(name, where, self.kind, self.accel_unit,
                                                           accel_raw, self.dt_nom)

    # -- every window ----------------------------------------------------------
    def window(self, values, t, where, off, gyro_raw):
        """The checks of one window (``off`` = 1 when row 0 of ``t`` and
        ``where`` is the sample before it); returns the ticks each step
        advances (None when the time says nothing yet)."""
        name = self.name
        bad = np.argwhere(~np.isfinite(values))
        if bad.size:
            if self.finite is None:
                k, c = bad[0]
                self.finite = (f"{name}: {where.at(k + off, c)}: {float(values[k, c])!r} is not "
                               f"finite")
            self.n_finite += len(bad)
        ticks = None
        if self.timed:
            steps = np.diff(t)
            bad = np.nonzero(steps <= 0.0)[0]
            if bad.size:
                if self.mono is None:
                    k = bad[0] + 1
                    what = "repeats" if t[k] == t[k - 1] else "goes back from"
                    self.mono = (f"{name}: {where.at(k)}: time {float(t[k])!r} {what} "
                                 f"{float(t[k - 1])!r} at {where.at(k - 1)}: time must increase")
                self.n_mono += bad.size
            if self.dt_nom is None:
                return None
            dt_nom = self.dt_nom
            ratio = steps / dt_nom
            short = np.nonzero(ratio < MIN_STEP_TICKS)[0]
            if short.size:
                if self.short is None:
                    k = short[0] + 1
                    self.short = (f"{name}: {where.at(k)}: time step {steps[k - 1]:.9g} s after "
                                  f"{where.at(k - 1)} is less than half the tick dt={dt_nom:g} s (a "
                                  f"repeated or extra sample?)")
                self.n_short += short.size
            ticks = np.maximum(1, np.floor(ratio + 0.5)).astype(np.int64)
            gaps = np.nonzero(ratio > GAP_TICKS)[0]
            if gaps.size:
                for k in gaps[:max(0, MAX_LISTED - self.n_gaps)]:
                    missing = ticks[k] - 1
                    self.gaps.append(f"{name}: {where.at(k + 1)}: gap of {steps[k]:.9g} s after "
                                     f"{where.at(k)} (t={float(t[k])!r}): "
                                     f"{_plural(missing, 'missing tick')} of {dt_nom:g} s")
                if self.gap_more_at is None and self.n_gaps + gaps.size > MAX_LISTED:
                    self.gap_more_at = where.at(gaps[MAX_LISTED - self.n_gaps] + 1)
                self.n_gaps += gaps.size
                self.missing += int(np.sum(ticks[gaps] - 1))
            irregular = np.nonzero((np.abs(ratio - 1.0) > TIME_TOL) & (ratio <= GAP_TICKS))[0]
            if irregular.size:
                if self.irregular is None:
                    k = irregular[0] + 1
                    self.irregular = (f"{name}: {where.at(k)}: irregular time step "
                                      f"{steps[k - 1]:.9g} s, more than {TIME_TOL:.0%} from the "
                                      f"tick dt={dt_nom:g} s")
                self.n_irregular += irregular.size
        if self.plausibility and self.dt_nom is not None:
            self.gyro_check(gyro_raw, where, off)
        return ticks

    def gyro_check(self, gyro_raw, where, off):
        per_s = 1.0 / self.dt_nom if self.kind == "increments" else 1.0
        rate = np.linalg.norm(gyro_raw, axis=1) * (GYRO_UNITS[self.kind][self.gyro_unit] * per_s)
        over = np.nonzero(rate > GYRO_RATE_LIMIT)[0]
        if over.size:
            if self.gyro is None:
                self.gyro = (where.at(over[0] + off), rate[over[0]])
            self.n_gyro += over.size

    def gyro_issues(self):
        if self.gyro is None:
            return []
        at, rate = self.gyro
        kind = self.kind
        more = f"; {self.n_gyro} samples in all" if self.n_gyro > 1 else ""
        if self.other_kind is not None:
            hint = (f"the accelerometer says these are {self.other_kind}, not {kind} "
                    f"(kind={self.other_kind!r})")
        else:
            hint = _GYRO_HINTS.get((kind, self.gyro_unit), "check gyro_unit, the scale and kind")
        return [LogIssue("error", f"{self.name}: {at}: gyro rate {rate:.4g} rad/s (read as "
                                  f"{self.gyro_unit} {kind}) exceeds {GYRO_RATE_LIMIT:g} "
                                  f"rad/s{more}: {hint}")]

    # -- the verdict -----------------------------------------------------------
    def fatal(self, strict):
        """The log will be refused (an error, or a warning when strict): the
        rest is read only to word the refusal as `read_log` does."""
        return bool(self.finite or self.mono or self.one or self.median or self.short
                    or self.tick0 or self.gravity or self.gyro
                    or (strict and (self.gaps or self.irregular)))

    def issues(self):
        """The findings in `read_log`'s order (errors and warnings)."""
        if self.finite:
            more = (f" ({self.n_finite} non-finite values in all)" if self.n_finite > 1 else "")
            return [LogIssue("error", self.finite + more)]
        out = []
        if self.timed:
            if self.mono:
                more = f" ({self.n_mono} such steps in all)" if self.n_mono > 1 else ""
                return [LogIssue("error", self.mono + more)]
            if self.one:
                return [self.one]
            if self.median:
                return [self.median]
            if self.short:
                more = f" ({self.n_short} such steps in all)" if self.n_short > 1 else ""
                return [LogIssue("error", self.short + more)]
            out += [LogIssue("warning", g) for g in self.gaps]
            if self.n_gaps > MAX_LISTED:
                out.append(LogIssue("warning", f"{self.name}: {self.gap_more_at}: and "
                                               f"{self.n_gaps - MAX_LISTED} more gaps; "
                                               f"{self.n_gaps} gaps, {self.missing} missing "
                                               f"ticks in all"))
            if self.irregular:
                out.append(LogIssue("warning", f"{self.irregular} "
                                               f"({_plural(self.n_irregular, 'such step')} in "
                                               f"all)"))
            if self.tick0:
                out.append(self.tick0)
                return out
        if self.plausibility:
            out += self.gravity + self.gyro_issues()
        return out


# ---------------------------------------------------------------------------
# Reading
# ---------------------------------------------------------------------------
DEFAULT_BLOCK = 1 << 16  #: samples a block (655 s at 100 Hz; ~4 MB of values, ~8 MB converted)
PROBE = 1 << 16          #: samples the rate and the gravity check are decided on (see LogReader)


def split_blocks(data, block=DEFAULT_BLOCK):
    """``data`` (an ImuData) in blocks of ``block`` samples (None: whole), views."""
    n = len(data.tick)
    if block is None or n <= block:
        yield data
        return
    for a in range(0, n, block):
        b = a + block
        yield ImuData(data.tick[a:b], data.dtheta_p[a:b], data.dv_p[a:b],
                      data.table_angle_rad[a:b], data.dt, data.metadata)


def _concat(blocks, metadata):
    if len(blocks) == 1:
        return blocks[0]
    if not blocks:
        raise LogError("no samples")
    return ImuData(np.concatenate([b.tick for b in blocks]),
                   np.concatenate([b.dtheta_p for b in blocks]),
                   np.concatenate([b.dv_p for b in blocks]),
                   np.concatenate([b.table_angle_rad for b in blocks]), blocks[0].dt, metadata)


class LogReader:
    """A log read in blocks, with every check of `read_log`, in bounded memory.

    ``LogReader(path, fmt, block=..., **options)`` takes the options of
    `read_log`. Opening it reads the probe, the first ``probe`` samples
    (`PROBE` = 65,536: 655 s at 100 Hz): the nominal dt (their median step)
    and the gravity check (their median |f|) are decided on them, and any
    error in them is raised here, before a block is handed out. Then:

    - ``dt``: the nominal tick [s]; ``rate_hz`` its inverse; ``metadata`` as
      `read_log` gives it (``"warnings"`` added at the end); ``n`` the
      samples when the size tells (a plain binary file), else None;
    - `blocks`: ImuData blocks of at most ``block`` samples, in order, each
      sample once; every other check (time strictly increasing, steps, gaps,
      finite values, the gyro limit) runs on each block with the last sample
      before it, so it holds across block boundaries and names the same line
      or record as `read_log`;
    - ``warnings``: when the last block is out, the warnings (gaps,
      irregular steps) of `read_log` with ``strict=False``.

    A log that `read_log` refuses raises the same `LogError` here, with the
    same message: at once when the probe shows it, else when the block
    showing it is reached (the blocks before it are out: a caller writes its
    results under a temporary name until the last block, as `pyins replay`
    does). To word the refusal as `read_log` does (the first finding of the
    highest rank, the counts "in all"), the reader reads the rest of the log
    first, checking only.

    ``probe=None``: the decisions on the whole log, read whole (what
    `read_log` does: with ``block=None`` too, one block, the whole log);
    ``block=None`` with a probe: blocks of `DEFAULT_BLOCK` after the probe. The two agree bit for
    bit on any log of at most ``probe`` samples, and on longer ones whenever
    the probe's median step rounds to the same nanosecond as the whole log's
    and its median |f| passes the same check (any log of a steady rate that
    starts with gravity in it).

    Streamed: text (and KF-GINS/PSINS text), binary, named-column CSV, PSINS
    .imu, each also gzip/xz/bzip2-compressed. Read whole and handed out in
    blocks: npz (a zip archive: its arrays are members one after the other,
    so a sample's fields are in different places of the file; and the
    project's own npz/csv, read by `pyins.sim.io`); about 64 bytes a sample.
    """

    def __init__(self, path, fmt=None, *, block=DEFAULT_BLOCK, probe=PROBE, dt=None,
                 kind="increments", gyro_unit=None, accel_unit=None, axes="rfu", time_col=None,
                 table=None, table_unit="rad", table_angle=None, strict=True, plausibility=True,
                 gyro_scale=1.0, accel_scale=1.0, columns=None,
                 strict_hint="read_log(..., strict=False) accepts it", _collect=False):
        for label, value in (("block", block), ("probe", probe)):
            if value is not None and not (isinstance(value, (int, np.integer)) and value >= 1):
                raise ValueError(f"{label} must be a positive number of samples or None, got "
                                 f"{value!r}")
        self.path, self.name = path, os.fspath(path)
        self.opt = _options(path, fmt, dt=dt, kind=kind, gyro_unit=gyro_unit,
                            accel_unit=accel_unit, axes=axes, time_col=time_col, table=table,
                            table_unit=table_unit, writing=False, gyro_scale=gyro_scale,
                            accel_scale=accel_scale, columns=columns)
        self.block = None if block is None else int(block)
        self.probe = None if probe is None else max(2, int(probe))
        self.strict, self.strict_hint, self.plausibility = strict, strict_hint, plausibility
        self.table_angle = table_angle
        self.dt, self.metadata, self.n, self.warnings, self.issues = None, {}, None, None, None
        self.samples = 0     #: samples handed out so far
        self._collect = _collect
        self._gen = self._run()
        next(self._gen, None)          # the probe: the header facts, or its error
        self._taken = False

    @property
    def rate_hz(self):
        return None if not self.dt else 1.0 / self.dt

    def blocks(self):
        """The ImuData blocks, once (a second call is a RuntimeError)."""
        if self._taken:
            raise RuntimeError(f"{self.name}: the blocks were taken already")
        self._taken = True
        for data in self._gen:
            self.samples += len(data.tick)
            yield data

    def __iter__(self):
        return self.blocks()

    def read(self):
        """The whole log as one ImuData (what `read_log` returns)."""
        data = _concat(list(self.blocks()), self.metadata)
        data.metadata["warnings"] = self.warnings
        return data

    # -- the work ----------------------------------------------------------------
    def _refuse(self, issues):
        for issue in issues:
            if issue.level == "error":
                raise LogError(issue.message)
        if self.strict and issues:
            raise LogError(f"{issues[0].message} ({self.strict_hint})")

    def _done(self, issues):
        self.issues = issues
        if not self._collect:
            self._refuse(issues)
        self.warnings = [issue.message for issue in issues]
        self.metadata["warnings"] = list(self.warnings)

    def _run(self):
        opt, name, lay = self.opt, self.name, _Layout()
        size = None if self.probe is None else (self.block or DEFAULT_BLOCK)
        chunks = _PARSERS[opt.fmt](self.path, name, opt, lay, size)
        first = next(chunks, None)
        if lay.project:                  # the project's own csv/npz: pyins.sim.io reads them whole
            text = (_decode(_read_bytes(self.path, name), self.path, name, strip=False)
                    if lay.project == "csv" else None)
            data, issues = _load_project(self.path, name, opt, self.plausibility,
                                         self.table_angle, text=text)
            if data is not None:
                self.dt, self.n, self.metadata = data.dt, len(data.tick), data.metadata
            self._done(issues)
            if self._collect:
                return
            yield None
            yield from split_blocks(data, self.block)
            return
        if lay.has_table and self.table_angle is not None:
            raise ValueError(f"{name}: table_angle given, but the file has a table-angle column")
        self.n = lay.n
        cols = lay.columns
        gi, ai = cols.index("gyro_x"), cols.index("accel_x")
        ti = cols.index("t") if "t" in cols else None
        timed = opt.time_col != "none"
        scan = _Scan(name, timed, opt.kind, opt.gyro_unit, self.plausibility, dt=opt.dt,
                     accel_unit=opt.accel_unit)

        def raw(values):
            return (values[:, gi:gi + 3] * opt.gyro_scale, values[:, ai:ai + 3] * opt.accel_scale)

        # the probe: exactly `probe` samples (all when None), whatever the block size
        pending, count, eof = [first], len(first[0]), False
        while self.probe is None or count < self.probe:
            c = next(chunks, None)
            if c is None:
                eof = True
                break
            pending.append(c)
            count += len(c[0])
        rest = None
        if self.probe is not None and count > self.probe:
            values, numbers = pending[-1]
            keep = len(values) - (count - self.probe)
            pending[-1] = (values[:keep], None if numbers is None else numbers[:keep])
            rest = (values[keep:], None if numbers is None else numbers[keep:])
        values = pending[0][0] if len(pending) == 1 else np.concatenate([p[0] for p in pending])
        numbers = None if pending[0][1] is None else (
            pending[0][1] if len(pending) == 1 else np.concatenate([p[1] for p in pending]))
        del pending
        where = _Where(lay.kind, cols, 0, numbers, len(values))
        t = values[:, ti] if timed else None
        gyro_raw, accel_raw = raw(values)
        scan.probe(values, t, where, accel_raw, eof)
        steps = scan.window(values, t, where, 0, gyro_raw)
        if self._collect:                # check_log: read whole, every finding listed
            self._done(scan.issues())
            return
        dt_nom = scan.dt_nom
        self.dt = dt_nom
        self.metadata = {"source": name, "format": opt.fmt, "kind": opt.kind,
                         "gyro_unit": opt.gyro_unit, "accel_unit": opt.accel_unit,
                         "table_unit": opt.table_unit if lay.has_table else None,
                         "axes": opt.axes_spec if isinstance(opt.axes_spec, str)
                         else opt.axes.tolist(),
                         "time_col": opt.time_col, "dt_inferred": opt.dt is None,
                         "t_first": None if t is None else float(t[0])}
        if opt.gyro_scale != 1.0 or opt.accel_scale != 1.0:
            self.metadata.update(gyro_scale=opt.gyro_scale, accel_scale=opt.accel_scale)
        if lay.header:
            self.metadata["psins_header"] = lay.header
        perm, sign = _perm_sign(opt.axes)
        state = dict(index=0, t=None, tick=None)

        def convert(values, t, steps, gyro_raw, accel_raw):
            m = values.shape[0]
            g0 = state["index"]
            if not timed:
                ticks = np.arange(g0 + 1, g0 + m + 1, dtype=np.int64)
                intervals = np.full(m, dt_nom)
            elif state["t"] is None:
                ticks = np.concatenate(([0], np.cumsum(steps))) + np.int64(scan.tick0_value)
                intervals = np.concatenate(([dt_nom], np.diff(t)))
            else:
                ticks = np.cumsum(steps) + np.int64(state["tick"])
                intervals = np.diff(t)
                t = t[1:]
            gyro = gyro_raw * GYRO_UNITS[opt.kind][opt.gyro_unit]
            accel = accel_raw * ACCEL_UNITS[opt.kind][opt.accel_unit]
            if opt.kind == "rates":  # rectangular rule: rate at t_k held over [t_{k-1}, t_k]
                gyro = gyro * intervals[:, None]
                accel = accel * intervals[:, None]
            dtheta_p = gyro[:, perm] * sign
            dv_p = accel[:, perm] * sign
            if lay.has_table:
                angle = values[:, cols.index("table")] * TABLE_UNITS[opt.table_unit]
            else:
                angle = np.full(m, 0.0 if self.table_angle is None else float(self.table_angle))
            state["index"] = g0 + m
            state["tick"] = ticks[-1]
            if timed:
                state["t"] = t[-1]
            return ImuData(ticks, dtheta_p, dv_p, angle, dt_nom, self.metadata)

        def windows():
            """The chunks after the probe, each with the last sample before it."""
            for values, numbers in ([rest] if rest is not None else []):
                yield values, numbers
            yield from chunks

        # the probe's verdict, its blocks
        prev_t = None if t is None else t[-1]
        prev_number = None if numbers is None else numbers[-1]
        start = len(values)
        if scan.fatal(self.strict):
            self._drain(scan, windows(), prev_t, prev_number, start, lay, raw, ti)
        yield None
        data = convert(values, t, steps, gyro_raw, accel_raw)
        del values, t, numbers, gyro_raw, accel_raw, steps
        yield from split_blocks(data, self.block)
        del data
        for values, numbers in windows():
            m = len(values)
            ext_t = None if not timed else np.concatenate(([prev_t], values[:, ti]))
            ext_numbers = None if numbers is None else np.concatenate(([prev_number], numbers))
            where = _Where(lay.kind, cols, start - 1, ext_numbers, m + 1)
            gyro_raw, accel_raw = raw(values)
            steps = scan.window(values, ext_t, where, 1, gyro_raw)
            if scan.fatal(self.strict):
                self._drain(scan, chunks, None if ext_t is None else ext_t[-1],
                            None if numbers is None else numbers[-1], start + m, lay, raw, ti)
            prev_t = None if ext_t is None else ext_t[-1]
            prev_number = None if numbers is None else numbers[-1]
            start += m
            yield convert(values, ext_t, steps, gyro_raw, accel_raw)
        self._done(scan.issues())

    def _drain(self, scan, chunks, prev_t, prev_number, start, lay, raw, ti):
        """The rest of the log, checked only, then the refusal (LogError)."""
        for values, numbers in chunks:
            m = len(values)
            ext_t = None if ti is None else np.concatenate(([prev_t], values[:, ti]))
            ext_numbers = None if numbers is None else np.concatenate(([prev_number], numbers))
            where = _Where(lay.kind, lay.columns, start - 1, ext_numbers, m + 1)
            scan.window(values, ext_t, where, 1, raw(values)[0])
            prev_t = None if ext_t is None else ext_t[-1]
            prev_number = None if numbers is None else numbers[-1]
            start += m
        issues = scan.issues()
        self._refuse(issues)
        raise AssertionError("a fatal scan gave no refusal")     # pragma: no cover


def iter_log(path, fmt=None, *, block=DEFAULT_BLOCK, **options):
    """The blocks of a log (`LogReader`): ``for data in iter_log(path): ...``."""
    return LogReader(path, fmt, block=block, **options).blocks()


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
    where = _Where("samples", None, 0, None, n)
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
    """Read an IMU log into the project's samples: `LogReader` read whole
    (one block, the decisions on the whole log). `LogReader` reads the same
    log in blocks, in bounded memory.

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
    return LogReader(path, fmt, block=None, probe=None, dt=dt, kind=kind, gyro_unit=gyro_unit,
                     accel_unit=accel_unit, axes=axes, time_col=time_col, table=table,
                     table_unit=table_unit, table_angle=table_angle, strict=strict,
                     plausibility=plausibility, gyro_scale=gyro_scale, accel_scale=accel_scale,
                     columns=columns, strict_hint=strict_hint).read()


def parse_columns(text, option="columns"):
    """``"t=stamp,gyro_x=a"`` -> ``{"t": "stamp", "gyro_x": "a"}`` (the CLI's
    --columns); a malformed list is a ValueError naming ``option``."""
    pairs = [item.partition("=") for item in text.split(",") if item.strip()]
    if not pairs or any(not eq or not role.strip() or not col.strip() for role, eq, col in pairs):
        raise ValueError(f"{option} {text!r}: expected ROLE=NAME,... (roles: "
                         f"{', '.join(dict.fromkeys(CSV_ROLES + NPZ_ROLES))})")
    return {role.strip(): col.strip() for role, _, col in pairs}


def _bridged(data, how, warnings):
    """(bridged ImuData, ticks added) of one piece of a log: see `bridge_gaps`."""
    tick = np.asarray(data.tick, dtype=np.int64)
    steps = np.diff(tick)
    gaps = np.nonzero(steps > 1)[0]
    if gaps.size == 0:
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
    return ImuData(np.concatenate(pieces["tick"]), np.concatenate(pieces["dtheta_p"]),
                   np.concatenate(pieces["dv_p"]), np.concatenate(pieces["table_angle_rad"]),
                   data.dt, data.metadata), int(np.sum(steps[gaps] - 1))


def _bridge_note(source, added, how):
    return (f"{source}: {_plural(added, 'missing tick')} bridged by linear interpolation "
            f"of the neighbouring samples ({how}); the motion in them is not in the log")


def bridge_gaps(data, how="bridge_gaps"):
    """``data`` with every skipped tick filled in, and the number of ticks added.

    The rule is the firmware's own for a sequence gap in navigation
    (docs/core.md, "skipped ticks"): the increments of the j-th of m missing
    ticks are interpolated linearly between the sample before the gap and the
    one after it, ``x_prev + (x_next - x_prev) * j / (m + 1)``, the table angle
    along the shorter turn between its two readings. What moved during the
    gap is not in the log, so the bridge is a guess that keeps the clock right
    (each sample is one tick to the firmware): callers say that they used it.
    `GapBridge` does the same to a log in blocks.

    The result's ``metadata["warnings"]`` is the input's (the gaps as
    `read_log` found them) and, when ticks were added, a last line saying how
    many and that ``how`` bridged them.
    """
    warnings = list(data.metadata.get("warnings", ()))
    out, added = _bridged(data, how, warnings)
    if not added:
        data.metadata["warnings"] = warnings
        return data, 0
    source = data.metadata.get("source", "the log")
    warnings.append(_bridge_note(source, added, how))
    out.metadata = dict(data.metadata, bridged_ticks=added, warnings=warnings)
    return out, added


class GapBridge:
    """`bridge_gaps` over a log in blocks: ``GapBridge(how).blocks(reader.blocks())``
    yields the blocks with every skipped tick filled in, the same samples,
    bit for bit, as `bridge_gaps` on the whole log (a gap across a block
    boundary is bridged from the last sample of the block before, kept for
    it). ``added``: the ticks added so far; `note`: the line `bridge_gaps`
    appends to the warnings, once the blocks are out (None when none was
    added)."""

    def __init__(self, how="bridge_gaps"):
        self.how, self.added, self.source = how, 0, "the log"

    def blocks(self, blocks):
        prev = None
        for data in blocks:
            self.source = data.metadata.get("source", "the log")
            if prev is not None and len(data.tick) and data.tick[0] - prev.tick[-1] > 1:
                ext = ImuData(np.concatenate((prev.tick[-1:], data.tick)),
                              np.concatenate((prev.dtheta_p[-1:], data.dtheta_p)),
                              np.concatenate((prev.dv_p[-1:], data.dv_p)),
                              np.concatenate((prev.table_angle_rad[-1:], data.table_angle_rad)),
                              data.dt, data.metadata)
                out, added = _bridged(ext, self.how, None)
                out = ImuData(out.tick[1:], out.dtheta_p[1:], out.dv_p[1:],
                              out.table_angle_rad[1:], out.dt, out.metadata)
            else:
                out, added = _bridged(data, self.how, None)
            self.added += added
            if len(data.tick):
                prev = data
            yield out

    def note(self):
        return _bridge_note(self.source, self.added, self.how) if self.added else None


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
        return LogReader(path, fmt, block=None, probe=None, strict=False, _collect=True,
                         **full).issues
    except LogError as exc:
        return [LogIssue("error", str(exc))]


# ---------------------------------------------------------------------------
# Writing
# ---------------------------------------------------------------------------
COPY_BYTES = 1 << 22     #: bytes copied at a time (assembling an npz, compressing)


def _tmp_name(path, what="tmp"):
    return f"{os.fspath(path)}.{what}{os.getpid()}"


def _remove(*paths):
    for p in paths:
        if p and os.path.exists(p):
            os.remove(p)


def _copy(src, dst):
    while True:
        chunk = src.read(COPY_BYTES)
        if not chunk:
            return
        dst.write(chunk)


class _Closing:
    """A writer as a context manager: `close` when the block ends, `abort`
    when it raises (nothing half-written keeps the final name)."""

    def __enter__(self):
        return self

    def __exit__(self, exc_type, *exc):
        if exc_type is None:
            self.close()
        else:
            self.abort()


class NpzWriter(_Closing):
    """An .npz written block by block, in bounded memory: `append` sends an
    array's rows to a raw file beside ``path`` as they come, `put` keeps a
    small array whole; `close` assembles the archive (the members np.savez
    writes: ``NAME.npy``, stored, zip64; `numpy.load` reads it as it reads
    np.savez's) under a temporary name and renames it, so a kill at any time
    leaves no file that looks complete. ``compress``: "gzip", "xz" or
    "bzip2" to compress the archive as a whole (a .npz.gz). `abort` removes
    everything written so far. Also a context manager: an exception in the
    block aborts."""

    def __init__(self, path, compress=None):
        self.path, self.compress = os.fspath(path), compress
        self._raw = {}        # name -> [raw path, file, dtype, tail shape, rows]
        self._whole = {}      # name -> array
        self._order = []
        self.closed = False

    def append(self, name, array):
        a = np.ascontiguousarray(array)
        part = self._raw.get(name)
        if part is None:
            tmp = _tmp_name(self.path, f"{name}.part")
            part = self._raw[name] = [tmp, open(tmp, "wb"), a.dtype, a.shape[1:], 0]
            self._order.append(name)
        elif a.dtype != part[2] or a.shape[1:] != part[3]:
            raise ValueError(f"{self.path}: {name}: rows of {a.dtype} {a.shape[1:]} after rows of "
                             f"{part[2]} {part[3]}")
        part[1].write(a.tobytes())
        part[4] += a.shape[0]

    def put(self, name, array):
        if name not in self._whole and name not in self._raw:
            self._order.append(name)
        self._whole[name] = np.asanyarray(array)

    def rows(self, name):
        """Rows appended to ``name`` so far."""
        part = self._raw.get(name)
        return 0 if part is None else part[4]

    def close(self):
        if self.closed:
            return
        for part in self._raw.values():
            part[1].close()
        tmp = _tmp_name(self.path)
        packed = _tmp_name(self.path, "zip") if self.compress else tmp
        try:
            with zipfile.ZipFile(packed, "w", zipfile.ZIP_STORED, allowZip64=True) as zf:
                for name in self._order:
                    with zf.open(f"{name}.npy", "w", force_zip64=True) as f:
                        if name in self._whole:
                            np.lib.format.write_array(f, self._whole[name], allow_pickle=False)
                            continue
                        raw, _, dtype, tail, n = self._raw[name]
                        header = {"descr": np.lib.format.dtype_to_descr(dtype),
                                  "fortran_order": False, "shape": (n,) + tuple(tail)}
                        try:
                            np.lib.format.write_array_header_1_0(f, header)
                        except ValueError:      # a header longer than 64 KiB
                            np.lib.format.write_array_header_2_0(f, header)
                        with open(raw, "rb") as src:
                            _copy(src, f)
            if self.compress:
                opener = next(o for c, _, o in COMPRESSIONS.values() if c == self.compress)
                with open(packed, "rb") as src, opener(tmp, "wb") as dst:
                    _copy(src, dst)
                _remove(packed)
            os.replace(tmp, self.path)
        except BaseException:
            _remove(tmp, packed)
            self.abort()
            raise
        self._discard()
        self.closed = True

    def _discard(self):
        for part in self._raw.values():
            part[1].close()
            _remove(part[0])
        self._raw.clear()

    def abort(self):
        """Remove what was written (the final name is never written before close)."""
        self._discard()
        self.closed = True


def _npz_header(f, path, name):
    version = np.lib.format.read_magic(f)
    if version == (1, 0):
        shape, fortran, dtype = np.lib.format.read_array_header_1_0(f)
    else:
        shape, fortran, dtype = np.lib.format.read_array_header_2_0(f)
    if fortran or not shape or dtype.hasobject:
        raise ValueError(f"{os.fspath(path)}: {name}: not a C-ordered array of rows")
    return shape, dtype


def npz_shape(path, name):
    """The shape of array ``name`` of an .npz, from its header alone."""
    with zipfile.ZipFile(path) as zf, zf.open(f"{name}.npy") as f:
        return _npz_header(f, path, name)[0]


def iter_npz(path, name, block=DEFAULT_BLOCK):
    """The rows of array ``name`` of an .npz, ``block`` rows at a time,
    without reading the whole array (members stored as np.savez and
    `NpzWriter` write them; a compressed member is decompressed as it is
    read): e.g. a 72 h replay's navigation.npz (112 MB of records) decimated
    in bounded memory. Yields read-only arrays."""
    with zipfile.ZipFile(path) as zf, zf.open(f"{name}.npy") as f:
        shape, dtype = _npz_header(f, path, name)
        row = dtype.itemsize * int(np.prod(shape[1:], dtype=np.int64))
        for start in range(0, shape[0], block):
            m = min(block, shape[0] - start)
            raw = _read_exact(f, m * row, None, os.fspath(path))
            if len(raw) != m * row:
                raise ValueError(f"{os.fspath(path)}: {name}: the member ends at row {start + len(raw) // row} "
                                 f"of {shape[0]}")
            yield np.frombuffer(raw, dtype).reshape((m,) + tuple(shape[1:]))


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


class LogWriter(_Closing):
    """A log written block by block in one of the layouts `read_log` reads,
    in bounded memory: ``with LogWriter(path, fmt, **options) as w:
    w.write(block)`` for each ImuData block, in tick order. The options are
    `write_log`'s; the file is the one `write_log` writes from the blocks
    joined (the same bytes for binary, text and csv; the same arrays for
    npz). It is written under a temporary name beside ``path`` and renamed
    at `close`, so a kill or an error mid-write leaves no file that looks
    complete (and an older file of that name untouched); `abort` (or an
    exception in the ``with`` block) removes it. A compressed name (.gz, .xz,
    .bz2) is compressed at close.

    ``metadata``: what an npz stores (default: the first block's). Text with
    ``table=None`` writes the table-angle column when any angle is not +0.0:
    if the first such angle comes after lines without the column, those are
    rewritten with a 0 in it (once), as `write_log` would have written them.
    """

    def __init__(self, path, fmt=None, *, dt=None, kind="increments", gyro_unit=None,
                 accel_unit=None, axes="rfu", time_col=None, table=None, table_unit="rad",
                 header=True, metadata=None):
        if format_of(path, fmt) == "psins":
            raise ValueError(f"{os.fspath(path)}: writing PSINS .imu is not supported (it rounds "
                             f"the increments to pulse counts); write text, time_col='last', for "
                             f"PSINS")
        self.path = self.name = os.fspath(path)
        plain, self.comp = _split_compression(path)
        if self.comp is not None and fmt is None:
            fmt = format_of(plain)
        self.opt = _options(plain, fmt, dt=dt, kind=kind, gyro_unit=gyro_unit,
                            accel_unit=accel_unit, axes=axes, time_col=time_col, table=table,
                            table_unit=table_unit, writing=True)
        self.header, self.metadata = header, metadata
        self.dt = self.opt.dt
        self.samples = 0
        self.closed = False
        self._last_tick = None
        self._last_t = None
        self._has_table = self.opt.table
        self._provisional = self.opt.fmt == "text" and self._has_table is None
        if self._has_table is None:
            self._has_table = False
        self._perm, self._sign = _perm_sign(self.opt.axes)
        self._plain = _tmp_name(self.path, "part") if self.comp else _tmp_name(self.path)
        self._npz = None
        self._file = None
        if self.opt.fmt == "npz":
            self._npz = NpzWriter(self.path, compress=self.comp)
        else:
            self._file = open(self._plain, "wb")

    # -- the blocks ----------------------------------------------------------------
    def write(self, data):
        """Append the samples of ``data`` (an ImuData, ticks after the last block's)."""
        if self.closed:
            raise ValueError(f"{self.name}: the writer is closed")
        name, opt = self.name, self.opt
        tick, dtheta, dv, angle = _data_arrays(name, data)
        if not len(tick):
            return
        if self._last_tick is not None and tick[0] <= self._last_tick:
            raise ValueError(f"{name}: tick must be strictly increasing integers (block starting at "
                             f"tick {tick[0]} after tick {self._last_tick})")
        if self.dt is None:
            self.dt = data.dt
        dt = self.dt
        if opt.fmt == "npz":
            if dt is None:
                raise ValueError(f"{name}: an npz stores dt: data.dt is None, pass dt")
            if self.metadata is None:
                self.metadata = data.metadata
            for key, a in (("tick", tick), ("dtheta_p", dtheta), ("dv_p", dv),
                           ("table_angle_rad", angle)):
                self._npz.append(key, a)
        elif opt.fmt == "csv":
            if self._last_tick is None:
                self._file.write((io.CSV_HEADER + "\n").encode())
            self._file.write("".join(
                "%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n"
                % (k, th[0], th[1], th[2], v[0], v[1], v[2], a)
                for k, th, v, a in zip(tick.tolist(), dtheta.tolist(), dv.tolist(),
                                       angle.tolist())).encode())
        else:
            self._write_rows(tick, dtheta, dv, angle, dt)
        self._last_tick = int(tick[-1])
        self.samples += len(tick)

    def _write_rows(self, tick, dtheta, dv, angle, dt):
        name, opt = self.name, self.opt
        if dt is None and (opt.time_col != "none" or opt.kind == "rates"):
            raise ValueError(f"{name}: data.dt is None: pass dt to write times or rates")
        if self._provisional and not self._has_table and bool(
                np.any((angle != 0.0) | np.signbit(angle))):
            # any angle but +0.0 (a -0.0 too, so that text round-trips bit for bit)
            self._add_table_column()
        if not self._has_table and np.any(angle != 0.0):
            raise ValueError(f"{name}: table=False would drop non-zero table angles; pass "
                             f"table=True")
        if opt.time_col == "none":
            steps = np.diff(tick) if self._last_tick is None else np.diff(
                np.concatenate(([self._last_tick], tick)))
            if np.any(steps != 1):
                raise ValueError(f"{name}: ticks skip, and time_col='none' cannot show the gaps")
            t = None
            intervals = np.full(tick.shape[0], dt)
        else:
            t = tick * float(dt)
            if self._last_t is None:
                intervals = np.concatenate(([dt], np.diff(t)))   # what the reader will use
            else:
                intervals = np.diff(np.concatenate(([self._last_t], t)))
            self._last_t = t[-1]
        perm, sign = self._perm, self._sign
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
        columns = _columns(opt.time_col, self._has_table)
        matrix = np.column_stack([parts[c] for c in columns])
        if opt.fmt == "binary":
            self._file.write(matrix.astype("<f8").tobytes())
            return
        if self._last_tick is None and self.header:
            self._file.write(self._header_line(columns).encode())
        line = " ".join(["%.17g"] * len(columns)) + "\n"
        self._file.write("".join(line % tuple(row) for row in matrix.tolist()).encode())

    def _header_line(self, columns):
        opt = self.opt
        units = {"gyro": opt.gyro_unit, "accel": opt.accel_unit, "t": "s", "table": opt.table_unit}
        names = " ".join(f"{c}[{units[c.split('_')[0]]}]" for c in columns)
        return f"% columns: {names}; kind={opt.kind}; axes={_axes_label(opt)}\n"

    def _add_table_column(self):
        """The first angle that is not +0.0 after lines without the column: the
        lines so far get it (their angles were all +0.0, written "0")."""
        self._has_table = True
        self._provisional = False
        if self._last_tick is None:
            return
        self._file.close()
        redo = _tmp_name(self.path, "redo")
        try:
            with open(self._plain, "rb") as src, open(redo, "wb") as dst:
                first = self.header
                for line in src:
                    if first:
                        dst.write(self._header_line(_columns(self.opt.time_col, True)).encode())
                        first = False
                        continue
                    dst.write(line[:-1] + b" 0\n")
            os.replace(redo, self._plain)
        finally:
            _remove(redo)
        self._file = open(self._plain, "ab")

    # -- the end -------------------------------------------------------------------
    def close(self):
        """The file under its name (nothing is there before)."""
        if self.closed:
            return
        try:
            if self._npz is not None:
                if self.dt is None:
                    raise ValueError(f"{self.name}: an npz stores dt: no block gave it, pass dt")
                self._npz.put("dt", np.float64(self.dt))
                meta = json.dumps(self.metadata if self.metadata is not None else {},
                                  sort_keys=True)
                self._npz.put("metadata", np.array(meta))
                if not self._npz.rows("tick"):
                    for key, shape in (("tick", (0,)), ("dtheta_p", (0, 3)), ("dv_p", (0, 3)),
                                       ("table_angle_rad", (0,))):
                        self._npz.append(key, np.zeros(shape, np.int64 if key == "tick" else float))
                self._npz.close()
            else:
                if self.opt.fmt == "csv" and self._last_tick is None:
                    self._file.write((io.CSV_HEADER + "\n").encode())
                elif (self.opt.fmt == "text" and self._last_tick is None and self.header):
                    self._file.write(self._header_line(
                        _columns(self.opt.time_col, self._has_table)).encode())
                self._file.close()
                if self.comp:
                    tmp = _tmp_name(self.path)
                    opener = next(o for c, _, o in COMPRESSIONS.values() if c == self.comp)
                    try:
                        with open(self._plain, "rb") as src, opener(tmp, "wb") as dst:
                            _copy(src, dst)
                        os.replace(tmp, self.path)
                    finally:
                        _remove(tmp)
                    _remove(self._plain)
                else:
                    os.replace(self._plain, self.path)
        except BaseException:
            self.abort()
            raise
        self.closed = True

    def abort(self):
        """Remove what was written; the final name is left as it was."""
        if self._npz is not None:
            self._npz.abort()
        if self._file is not None:
            self._file.close()
        _remove(self._plain)
        self.closed = True


def write_log(path, data, fmt=None, *, dt=None, kind="increments", gyro_unit=None,
              accel_unit=None, axes="rfu", time_col=None, table=None, table_unit="rad",
              header=True):
    """Write samples in one of the layouts `read_log` reads.

    Parameters
    ----------
    path : str or PathLike
    data : ImuData, or an iterable of ImuData blocks
        (or anything with ``tick``, ``dtheta_p``, ``dv_p``,
        ``table_angle_rad``, ``dt`` and ``metadata``); blocks in tick order
        are written as they come (`LogWriter`), in bounded memory.
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
    the name without it, as when reading). The file appears under its name
    only when complete (a temporary name and a rename).
    """
    blocks = [data] if hasattr(data, "tick") else data
    with LogWriter(path, fmt, dt=dt, kind=kind, gyro_unit=gyro_unit, accel_unit=accel_unit,
                   axes=axes, time_col=time_col, table=table, table_unit=table_unit,
                   header=header) as w:
        for block in blocks:
            w.write(block)


def _axes_label(opt):
    if isinstance(opt.axes_spec, str):
        return opt.axes_spec
    return "M=" + str(opt.axes.tolist()).replace(" ", "")
