"""IMU logs from the field: read, check and write the text and binary layouts
of other INS tools, and the project's own .npz and CSV (`pyins.logs.project`).

Every reader returns an `ImuData` (`pyins.logs.project`) in the project's terms
(docs/design.md §2-§3): one sample per tick, the angle increment
``dtheta_p`` [rad] and the velocity increment ``dv_p`` [m/s] over the tick
``[t_{k-1}, t_k]`` in the IMU frame p (x right, y forward, z up), and the table
angle at ``t_k`` [rad]. docs/log-formats.md has the same content with examples.

Formats (``fmt``; when None, taken from the extension)
------------------------------------------------------
- ``"npz"`` (.npz): the project's file, read and written by `pyins.logs.project`;
  no unit, axis or layout options. `read_log` runs the magnitude checks on it
  too and reports skipped ticks as gaps.
- ``"csv"`` (.csv): a header line names the columns, mapped to roles by name
  (`CSV_ALIASES`, or ``columns=``); ``#``/``%`` comment lines; the text
  options below apply. The project's own header (`CSV_HEADER`
  on line 1) is read by `pyins.logs.project` as before.
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
`pyins.units` (DEG_TO_RAD, DPH_TO_RPS, G0).

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

Modules
-------
One concept a module; every name below is importable from ``pyins.logs``.

- `pyins.logs.options`: formats, extensions, compressions, kinds, units,
  axes, the names each column role answers to, the options checked.
- `pyins.logs.issues`: `LogError` and `LogIssue`.
- `pyins.logs.files`: compression, bytes and text in and out of files.
- `pyins.logs.where`: the positions messages name (lines, records, samples).
- `pyins.logs.formats`: the parsers, one per format.
- `pyins.logs.checks`: the checks of Validation, over a log in windows.
- `pyins.logs.reader`: `LogReader`, `read_log`, `check_log`, `split_blocks`.
- `pyins.logs.bridge`: `bridge_gaps`, `GapBridge`.
- `pyins.logs.writer`: `LogWriter`, `write_log`.
- `pyins.logs.npz_rows`: `NpzWriter`, `iter_npz`, `npz_shape`.
- `pyins.logs.project`: the project's own .npz and CSV (`ImuData`,
  `save_npz`, `load_npz`, `save_csv`, `load_csv`); ``pyins.sim.io`` keeps
  these names.
"""

from pyins.logs.bridge import GapBridge, bridge_gaps
from pyins.logs.checks import (DEFAULT_DT, GAP_TICKS, GRAVITY_BAND, GYRO_RATE_LIMIT, MAX_LISTED,
                               MIN_STEP_TICKS, TIME_TOL)
from pyins.logs.files import COPY_BYTES, TEXT_CHUNK_BYTES, _read_bytes, compression_of
from pyins.logs.formats import PSINS_HEADER
from pyins.logs.issues import LogError, LogIssue
from pyins.logs.npz_rows import NpzWriter, iter_npz, npz_shape
from pyins.logs.options import (ACCEL_UNITS, AXES, AXES_ALIASES, COMPRESSIONS, CSV_ALIASES,
                                CSV_ROLES, DEFAULT_BLOCK, EXTENSIONS, FORMATS, GYRO_UNITS, KINDS,
                                NPZ_ALIASES, NPZ_ROLES, TABLE_UNITS, TIME_COLS, axes_matrix,
                                format_of, parse_columns)
from pyins.logs.project import (CSV_COLUMNS, CSV_HEADER, ImuData, load_csv, load_npz, save_csv,
                                save_npz)
from pyins.logs.reader import PROBE, LogReader, check_log, read_log, split_blocks
from pyins.logs.writer import LogWriter, write_log

__all__ = [
    "GapBridge", "bridge_gaps",
    "DEFAULT_DT", "GAP_TICKS", "GRAVITY_BAND", "GYRO_RATE_LIMIT", "MAX_LISTED", "MIN_STEP_TICKS",
    "TIME_TOL",
    "COPY_BYTES", "TEXT_CHUNK_BYTES", "compression_of",
    "PSINS_HEADER",
    "LogError", "LogIssue",
    "NpzWriter", "iter_npz", "npz_shape",
    "ACCEL_UNITS", "AXES", "AXES_ALIASES", "COMPRESSIONS", "CSV_ALIASES", "CSV_ROLES",
    "DEFAULT_BLOCK", "EXTENSIONS", "FORMATS", "GYRO_UNITS", "KINDS", "NPZ_ALIASES", "NPZ_ROLES",
    "TABLE_UNITS", "TIME_COLS", "axes_matrix", "format_of", "parse_columns",
    "CSV_COLUMNS", "CSV_HEADER", "ImuData", "load_csv", "load_npz", "save_csv", "save_npz",
    "PROBE", "LogReader", "check_log", "read_log", "split_blocks",
    "LogWriter", "write_log",
]
