"""Reading one value of a scenario file against its `Key`: the type, the
unit (`pyins.units.parse_quantity`), the range, whole ticks, the shape (one
value or three, a 3x3 matrix with a zero diagonal); unknown keys with the
closest known key suggested. Every mistake raises `ScenarioError` naming the
key path.
"""
import difflib

from pyins.scenario.schema import _SUFFIX
from pyins.units import DT, TICK_HZ, ScenarioError, parse_quantity


def _join(path, name):
    return f"{path}.{name}" if path else name


#: Words people write for a key -> the key.
_SYNONYMS = {"latitude": "lat", "longitude": "lon", "altitude": "height", "alt": "height",
             "elevation": "height", "time": "duration", "length": "duration",
             "every": "record_every", "noise_seed": "seed"}


def _suggest(name, allowed):
    if _SYNONYMS.get(name) in allowed:
        return _SYNONYMS[name]
    close = difflib.get_close_matches(name, list(allowed), n=1, cutoff=0.5)
    return close[0] if close else None


def _check_keys(table, path, allowed, what=""):
    for name in table:
        if name not in allowed:
            close = _suggest(name, allowed)
            hint = (f"did you mean {close!r}?" if close
                    else f"known keys{what}: {', '.join(allowed)}")
            raise ScenarioError(f"unknown key; {hint}", _join(path, name))


def _need_table(value, where):
    if not isinstance(value, dict):
        raise ScenarioError(f"must be a table ([{where}] or {{ ... }}), got "
                            f"{_type_name(value)} {value!r}", where)
    return value


def _type_name(value):
    return {bool: "boolean", int: "integer", float: "float", str: "string", list: "array",
            dict: "table"}.get(type(value), type(value).__name__)


def _limit(limit, dimension):
    return parse_quantity(limit, dimension) if isinstance(limit, str) else float(limit)


def _range_text(key):
    parts = []
    if key.lo is not None:
        parts.append(f"{'>' if key.lo_open else '>='} {key.lo}")
    if key.hi is not None:
        parts.append(f"{'<' if key.hi_open else '<='} {key.hi}")
    return " and ".join(parts)


def _check_range(value, key, where, raw):
    dim = key.kind if key.kind != "int" else "dimensionless"
    bad = False
    if key.lo is not None:
        lo = _limit(key.lo, dim)
        bad |= value <= lo if key.lo_open else value < lo
    if key.hi is not None:
        hi = _limit(key.hi, dim)
        bad |= value >= hi if key.hi_open else value > hi
    if bad:
        raise ScenarioError(f"out of range: {raw!r} must be {_range_text(key)}", where)


def _whole_ticks(seconds, where, raw):
    ticks = seconds * TICK_HZ
    n = round(ticks)
    if abs(ticks - n) > 1e-9 * max(1.0, abs(ticks)):
        raise ScenarioError(f"{raw!r} is not a whole number of {DT:g} s ticks", where)
    return n


def _scalar(raw, key, where):
    value = parse_quantity(raw, key.kind, where=where, tick_hz=TICK_HZ)
    _check_range(value, key, where, raw)
    if key.ticks:
        value = _whole_ticks(value, where, raw) / TICK_HZ
    return value


def _convert(raw, key, where):
    """A raw TOML value checked against ``key``; quantities in SI."""
    kind = key.kind
    if kind == "text":
        if not isinstance(raw, str):
            raise ScenarioError(f"must be a string, got {_type_name(raw)} {raw!r}", where)
        return raw
    if kind == "bool":
        if not isinstance(raw, bool):
            raise ScenarioError(f"must be true or false, got {_type_name(raw)} {raw!r}", where)
        return raw
    if kind == "int":
        if isinstance(raw, bool) or not isinstance(raw, int):
            raise ScenarioError(f"must be an integer, got {_type_name(raw)} {raw!r}", where)
        if key.choices and raw not in key.choices:
            raise ScenarioError(f"must be one of {', '.join(map(str, key.choices))}, got {raw}", where)
        _check_range(raw, key, where, raw)
        return raw
    if kind == "choice":
        if not isinstance(raw, str):
            raise ScenarioError(f"must be one of {', '.join(map(repr, key.choices))}, got "
                                f"{_type_name(raw)} {raw!r}", where)
        if raw not in key.choices:
            close = difflib.get_close_matches(raw, key.choices, n=1, cutoff=0.6)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise ScenarioError(f"unknown value {raw!r}{hint} (choose one of "
                                f"{', '.join(key.choices)})", where)
        return raw
    if kind == "list":
        if not isinstance(raw, list) or not raw:
            raise ScenarioError(f"must be a non-empty array, got {_type_name(raw)} {raw!r}", where)
        return raw
    if key.shape is None:
        return _scalar(raw, key, where)
    if key.shape == 3:
        if isinstance(raw, list):
            if len(raw) != 3:
                # a lever arm is a vector: one value for all three axes is refused where it is resolved
                forms = ("a list of 3 lengths [x starboard, y bow, z up]" if key.kind == "length"
                         else "one value for all three axes or a list of 3")
                raise ScenarioError(f"must be {forms}, got {len(raw)} values", where)
            return [_scalar(v, key, f"{where}[{i}]") for i, v in enumerate(raw)]
        return [_scalar(raw, key, where)] * 3
    # a 3x3 matrix with a zero diagonal
    if not isinstance(raw, list):
        v = _scalar(raw, key, where)
        return [[0.0 if i == j else v for j in range(3)] for i in range(3)]
    if len(raw) != 3 or not all(isinstance(row, list) and len(row) == 3 for row in raw):
        raise ScenarioError("must be one value for all six off-diagonal terms or a 3x3 array "
                            "[[..., ..., ...], [...], [...]]", where)
    m = [[_scalar(v, key, f"{where}[{i}][{j}]") for j, v in enumerate(row)] for i, row in enumerate(raw)]
    for i in range(3):
        if m[i][i] != 0.0:
            raise ScenarioError(f"the diagonal [{i}][{i}] must be 0 (scale-factor errors go in "
                                f"*_scale)", where)
    return m


def _read(table, path, keys, what=""):
    """Every key of ``keys`` from ``table``: {name: SI value or None}."""
    _check_keys(table, path, keys, what)
    out = {}
    for name, key in keys.items():
        where = _join(path, name)
        if name in table:
            raw = table[name]
        elif key.required:
            raise ScenarioError(f"missing (required: {key.doc})", where)
        else:
            raw = key.default
        if raw is None or key.kind in ("tables", "table", "quantity"):
            out[name] = raw
        else:
            out[name] = _convert(raw, key, where)
    return out


def _si(values, keys):
    """{name: value} -> {name + SI-unit suffix: value} (the resolved form)."""
    return {name + _SUFFIX.get(keys[name].kind, ""): v for name, v in values.items()}


def _array_of_tables(raw, where, lo, hi):
    if not isinstance(raw, list) or not all(isinstance(t, dict) for t in raw):
        raise ScenarioError(f"must be an array of tables ([[{where}]] or [{{...}}, ...]), got "
                            f"{_type_name(raw)}", where)
    if not lo <= len(raw) <= hi:
        raise ScenarioError(f"must have {lo} to {hi} entries, got {len(raw)}", where)
    return raw

