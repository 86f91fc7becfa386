"""Writing a log in one of the layouts `pyins.logs.read_log` reads:
`LogWriter` block by block, `write_log` whole or from an iterable of
blocks; the file appears under its name only when complete."""
import json
import os

import numpy as np

from pyins.logs.files import _Closing, _copy, _remove, _tmp_name
from pyins.logs.npz_rows import NpzWriter
from pyins.logs.options import (ACCEL_UNITS, COMPRESSIONS, GYRO_UNITS, TABLE_UNITS, _columns,
                                _options, _perm_sign, _split_compression, format_of)
from pyins.logs.project import CSV_HEADER


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
                self._file.write((CSV_HEADER + "\n").encode())
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
            # what the reader will use: a rate is held over its own tick, after a gap too
            if self._last_t is None:
                intervals = np.concatenate(([dt], np.diff(t) / np.maximum(np.diff(tick), 1)))
            else:
                intervals = (np.diff(np.concatenate(([self._last_t], t)))
                             / np.maximum(np.diff(np.concatenate(([self._last_tick], tick))), 1))
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
                    self._file.write((CSV_HEADER + "\n").encode())
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
