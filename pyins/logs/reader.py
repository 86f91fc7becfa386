"""Reading a log: `LogReader` (in blocks, every check, bounded memory),
`read_log` (the same read whole), `check_log` (every finding listed), and
`split_blocks` (an ImuData in blocks)."""
import io as _io
import os

import numpy as np

from pyins.logs.checks import DEFAULT_DT, MAX_LISTED, _Scan, _check_magnitudes
from pyins.logs.files import _decode, _read_bytes, compression_of
from pyins.logs.formats import _PARSERS
from pyins.logs.issues import LogError, LogIssue, _plural
from pyins.logs.options import (ACCEL_UNITS, DEFAULT_BLOCK, GYRO_UNITS, TABLE_UNITS, _options,
                                _perm_sign)
from pyins.logs.project import CSV_HEADER, ImuData, load_csv, load_npz
from pyins.logs.where import _Layout, _Where

# ---------------------------------------------------------------------------
# Reading
# ---------------------------------------------------------------------------
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
    project's own npz/csv, read by `pyins.logs.project`); about 64 bytes a sample.
    """

    def __init__(self, path, fmt=None, *, block=DEFAULT_BLOCK, probe=PROBE, dt=None,
                 kind="increments", gyro_unit=None, accel_unit=None, axes="rfu", time_col=None,
                 table=None, table_unit="rad", table_angle=None, strict=True, plausibility=True,
                 gyro_scale=1.0, accel_scale=1.0, columns=None,
                 strict_hint="read_log(..., strict=False) accepts it", name=None, _collect=False):
        for label, value in (("block", block), ("probe", probe)):
            if value is not None and not (isinstance(value, (int, np.integer)) and value >= 1):
                raise ValueError(f"{label} must be a positive number of samples or None, got "
                                 f"{value!r}")
        # ``name``: what the messages call the file (a pipe's copy is named as the user gave it)
        self.path, self.name = path, os.fspath(path) if name is None else name
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
        if lay.project:                  # the project's own csv/npz: logs.project reads them whole
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
                intervals = np.concatenate(([dt_nom], np.diff(t) / np.maximum(steps, 1)))
            else:
                ticks = np.cumsum(steps) + np.int64(state["tick"])
                intervals = np.diff(t) / np.maximum(steps, 1)
                t = t[1:]
            # a rate is held over its own tick: after a gap (a step of several
            # ticks) the sample is one tick's increment, the time it spans
            # divided by the ticks in it; the missing ticks are the bridge's
            # (rate x the whole gap made the first sample after a 0.1 s gap
            # 11 ticks' worth, and the bridge ramped towards it)
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


def _load_project(path, name, opt, plausibility, table_angle, text=None):
    if table_angle is not None:
        raise ValueError(f"{name}: table_angle does not apply: {opt.fmt} files hold the angle")
    if opt.fmt in ("csv", "npz"):
        default = (opt.kind == "increments" and opt.gyro_unit == "rad" and opt.accel_unit == "m/s"
                   and opt.gyro_scale == 1.0 and opt.accel_scale == 1.0 and opt.columns is None
                   and opt.table is None and np.array_equal(opt.axes, np.eye(3)))
        if not default:
            what = f"csv header ({CSV_HEADER})" if opt.fmt == "csv" else "npz file"
            raise ValueError(f"{name}: the project's {what} holds rad, m/s and the p axes; unit, "
                             f"axis, scale and column options do not apply")
    try:
        if opt.fmt == "npz":
            packed = compression_of(path) is not None
            data = load_npz(path, file=_io.BytesIO(_read_bytes(path, name)) if packed else None)
        else:
            data = load_csv(path, dt=opt.dt, file=_io.StringIO(text, newline=""))
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
        Check the magnitudes for unit mix-ups (see `pyins.logs`, Validation).
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
