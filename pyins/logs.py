"""IMU logs from the field: read, check and write the text and binary layouts
of other INS tools, and the project's own .npz and CSV (`pyins.sim.io`).

Every reader returns a `pyins.sim.io.ImuData` in the project's terms
(docs/design.md §2-§3): one sample per tick, the angle increment
``dtheta_p`` [rad] and the velocity increment ``dv_p`` [m/s] over the tick
``[t_{k-1}, t_k]`` in the IMU frame p (x right, y forward, z up), and the table
angle at ``t_k`` [rad]. docs/log-formats.md has the same content with examples.

Formats (``fmt``; when None, taken from the extension)
------------------------------------------------------
- ``"npz"`` (.npz) and ``"csv"`` (.csv): the project's files, read and written
  by `pyins.sim.io`; they take no unit, axis or layout options. `read_log`
  runs the magnitude checks on them too and reports skipped ticks as gaps.
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
(default) or "deg", ``accel_unit`` "m/s" (default).
``kind="rates"``: angular rate, ``gyro_unit`` "rad/s" (default), "deg/s" or
"deg/h", and specific force, ``accel_unit`` "m/s^2" (default) or "g"
(standard gravity G0 = 9.80665 m/s^2). Rates become increments by the
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
import os
from dataclasses import dataclass

import numpy as np

from pyins.units import DEG_TO_RAD, DPH_TO_RPS, DT, G0
from pyins.sim import io
from pyins.sim.io import ImuData

FORMATS = ("npz", "csv", "text", "binary")
EXTENSIONS = {".npz": "npz", ".csv": "csv", ".txt": "text", ".dat": "text", ".asc": "text",
              ".bin": "binary"}
KINDS = ("increments", "rates")
TIME_COLS = ("last", "first", "none")

#: Unit -> factor to SI, per kind.
GYRO_UNITS = {"increments": {"rad": 1.0, "deg": DEG_TO_RAD},
              "rates": {"rad/s": 1.0, "deg/s": DEG_TO_RAD, "deg/h": DPH_TO_RPS}}
ACCEL_UNITS = {"increments": {"m/s": 1.0},
               "rates": {"m/s^2": 1.0, "g": G0}}
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
def format_of(path, fmt=None):
    """The format of ``path``: ``fmt`` checked, or the one its extension names."""
    if fmt is not None:
        if fmt not in FORMATS:
            raise ValueError(f"fmt {fmt!r} is not one of {FORMATS}")
        return fmt
    ext = os.path.splitext(os.fspath(path))[1].lower()
    if ext not in EXTENSIONS:
        raise ValueError(f"{os.fspath(path)}: cannot tell the format from the extension {ext!r} "
                         f"(known: {', '.join(EXTENSIONS)}); pass fmt= one of {FORMATS}")
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


def _options(path, fmt, *, dt, kind, gyro_unit, accel_unit, axes, time_col, table,
             table_unit, writing):
    fmt = format_of(path, fmt)
    if fmt in ("npz", "csv"):
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
    return _Options(fmt, kind, gyro_unit, accel_unit, table_unit, axes_matrix(axes), axes,
                    time_col, table, dt)


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
    try:
        with open(path, "r", encoding="utf-8", newline=None) as f:
            for lineno, line in enumerate(f, start=1):
                tokens = line.lstrip("\ufeff").split()
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
    except UnicodeDecodeError as exc:
        raise LogError(f"{name}: byte offset {exc.start}: not UTF-8 text (a binary log? "
                       f"pass fmt='binary')") from None
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
        return " (this reader splits on whitespace; the project's CSV is fmt='csv')"
    return ""


def _parse_binary(path, name, opt):
    columns = _columns("first", opt.table)
    size = 8 * len(columns)
    raw = open(path, "rb").read()
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
        declared = next(label for k, unit, label in _ACCEL_READINGS
                        if (k, unit) == (kind, accel_unit))
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
            hint = _GYRO_HINTS[kind, gyro_unit]
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
    if opt.fmt in ("npz", "csv"):
        return _load_project(path, name, opt, plausibility, table_angle)
    if opt.fmt == "text":
        values, where, has_table = _parse_text(path, name, opt)
    else:
        values, where, has_table = _parse_binary(path, name, opt)
    if has_table and table_angle is not None:
        raise ValueError(f"{name}: table_angle given, but the file has a table-angle column")
    issues = _check_finite(name, values, where)
    if issues:
        return None, issues
    cols = _columns(opt.time_col, has_table)
    gyro_raw = values[:, cols.index("gyro_x"):cols.index("gyro_x") + 3]
    accel_raw = values[:, cols.index("accel_x"):cols.index("accel_x") + 3]
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
    return ImuData(ticks, dtheta_p, dv_p, angle, dt_nom, metadata), issues


def _load_project(path, name, opt, plausibility, table_angle):
    if table_angle is not None:
        raise ValueError(f"{name}: table_angle does not apply: {opt.fmt} files hold the angle")
    try:
        data = io.load_npz(path) if opt.fmt == "npz" else io.load_csv(path, dt=opt.dt)
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
             strict=True, plausibility=True):
    """Read an IMU log into the project's samples.

    Parameters
    ----------
    path : str or PathLike
    fmt : {'npz', 'csv', 'text', 'binary'} or None
        None: from the extension (.npz, .csv, .txt/.dat/.asc, .bin).
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
        plausibility=plausibility))
    for issue in issues:
        if issue.level == "error":
            raise LogError(issue.message)
    if strict and issues:
        raise LogError(f"{issues[0].message} (read_log(..., strict=False) accepts it)")
    data.metadata["warnings"] = [issue.message for issue in issues]
    return data


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
                plausibility=True)
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

    Floats are written with ``%.17g``, which round-trips every float64.
    """
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
