"""The parsers of the log formats, one section each: whitespace text,
headerless binary records, CSV with a header naming the columns, an npz of
other tools' arrays, PSINS's .imu (the formats themselves: `pyins.logs`'s
docstring and docs/log-formats.md). `_PARSERS` maps a format to its parser;
the project's own csv and npz are told apart here and read by
`pyins.logs.project`."""
import io as _io
import os

import zipfile

import numpy as np

from pyins.logs.files import _full, _lines, _opener, _read_bytes, _read_exact
from pyins.logs.issues import LogError, _plural
from pyins.logs.options import CSV_ALIASES, CSV_ROLES, NPZ_ALIASES, _columns
from pyins.logs.project import _npz_why, CSV_HEADER, _NPZ_KEYS
from pyins.units import ARCSEC_TO_RAD


# ---------------------------------------------------------------------------
# Parsing: each parser yields (values (m, ncol) float array, line numbers or
# None) chunks of at most `size` rows (size None: one chunk of all rows)
# ---------------------------------------------------------------------------
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
    ``lay.project`` set, for the project's own header (pyins.logs.project reads it)."""
    lines = _lines(path, name, size)
    header = None
    for lineno, line in lines:
        if line.strip() and line.lstrip()[0] not in "#%":
            header = line
            break
    if header is None:
        raise LogError(f"{name}: no header line (only blank or comment lines)")
    header_line = lineno
    if lineno == 1 and header.strip() == CSV_HEADER:
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
                       f"'PSINS' and 'SIMU'), got {first.strip()[:60]!r}; to read it as another "
                       f"layout, pass fmt='text', fmt='csv' or fmt='binary'")
    head, rows, numbers, ncol = [], [], [], None
    state = dict(k=0, dither=0.0, checked=False)

    def chunk(rows, numbers):
        if not state["checked"]:       # the header's interval and g, before the first counts are used
            ts_ms, g = lay.header["ts_ms"], lay.header["g_mps2"]
            if not (np.isfinite(ts_ms / 1000.0) and ts_ms / 1000.0 > 0 and np.isfinite(g) and g > 0):
                raise LogError(f"{name}: header line 2: sampling interval {ts_ms!r} ms and g "
                               f"{g!r} m/s^2 must be positive")
            # a header that lost a line reads the next line in its place (the first data
            # line as the scale factors: the counts of one sample): refused, never run
            lines_ = "; ".join(f"{i + 1}: {' '.join(k)}" for i, k in enumerate(PSINS_HEADER))
            if not G_RANGE[0] <= g <= G_RANGE[1]:
                raise LogError(f"{name}: PSINS header line 2 gives g = {g:g} m/s^2, not the Earth's "
                               f"gravity ({G_RANGE[0]:g} to {G_RANGE[1]:g}): a header line is missing "
                               f"or damaged (the 3 header lines are {lines_})")
            scales = np.array(head[2][0:6], dtype=float)
            if not np.all(np.isfinite(scales) & (scales > 0)):
                raise LogError(f"{name}: PSINS header line 3 (the scale factors gf_x gf_y gf_z "
                               f"[arcsec], af_x af_y af_z [ug*s]) holds "
                               f"{' '.join(f'{v:g}' for v in scales)}: a scale factor must be "
                               f"positive; the scale-factor line is missing (a data line read as "
                               f"it?) or damaged")
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


def _comma_hint(tokens):
    if any("," in tok or ";" in tok for tok in tokens):
        return " (this reader splits on whitespace; a CSV with a header line is fmt='csv')"
    return ""


def _csv_name(field):
    """A header field compared by name: lower case, no spaces, no unit suffix
    in brackets ("gyro_x [rad]" -> "gyro_x")."""
    field = field.strip().strip('"').lower()
    for opening in "[(":
        if opening in field:
            field = field[:field.index(opening)]
    return field.strip().replace(" ", "_")


def _parse_npz(path, name, opt):
    """An npz of other arrays than the project's, found by name (`NPZ_ALIASES`
    or ``columns=``): (values, where, has_table) in the text layout "first"
    (or "none"); None for the project's own file (its arrays, no mapping)."""
    raw = _read_bytes(path, name)
    try:
        npz = np.load(_io.BytesIO(raw), allow_pickle=False)
        files = list(npz.files)
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:
        raise LogError(f"{name}: not a readable .npz file ({_npz_why(exc)}): cut, damaged or not an npz") from None
    if opt.columns is None and all(k in files for k in _NPZ_KEYS):
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
#: g [m/s^2] a PSINS header may give: the Earth's normal gravity spans 9.78 (equator) to
#: 9.83 (poles), a little less at altitude; anything outside is not a g
G_RANGE = (9.7, 9.9)
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
