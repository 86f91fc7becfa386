"""A campaign's values as written: grid strings, values, seeds and seed formulas.

What a campaign file or the command line writes, read into Python values,
and a value shown back as text:

1. values: `parse_value` reads ``3``, ``0.5``, ``true``, ``["1 deg", 0, 0]``
   as TOML would, anything else (``60 deg``) as the string;
2. grids and fixed overrides: `parse_grid` ("KEY=V1,V2,...", commas inside
   brackets or quotes do not split), `parse_overrides` ("KEY=VALUE");
3. seeds: `parse_seeds` (a count N for 0..N-1, a list, "0,3,7", "2..6");
4. seed formulas: `compile_formula` checks one (numbers, names, + - * // %
   and parentheses only), `formula_names` lists the names a grid gives it
   (each key's value as written and its index), `eval_formula` evaluates it;
5. text: `canonical` (the JSON that keys a value), `show`, `value_label`
   ("heading = 60 deg" or its [campaign.labels] label), `qkey` (a key path
   as a TOML file writes it, for messages).
"""
import ast
import difflib
import json

try:
    import tomllib
except ImportError:            # Python 3.10
    import tomli as tomllib

from pyins.units import ScenarioError, split_quantity

__all__ = ["parse_value", "parse_grid", "parse_overrides", "parse_seeds", "compile_formula",
           "eval_formula", "number_as_written", "formula_names", "canonical", "show", "value_label",
           "qkey"]


# ---------------------------------------------------------------------------
# 5. Text (first: the parsers' messages use it)
# ---------------------------------------------------------------------------
def canonical(value):
    """The JSON text that keys a value (sorted keys, no spaces)."""
    return json.dumps(value, sort_keys=True, separators=(",", ":"), allow_nan=False)


def show(value):
    """A grid value as text: strings as written, anything else as JSON."""
    return value if isinstance(value, str) else json.dumps(value)


def value_label(labels, key, value, keys=()):
    """A grid value as text: its label ([campaign.labels]), else "heading = 60 deg"
    (the key's last part; the whole key if another of ``keys`` ends alike)."""
    names = (labels or {}).get(key)
    if names:
        return names[1][names[0].index(canonical(value))]
    short = key.split(".")[-1]
    if sum(k.split(".")[-1] == short for k in keys) > 1:
        short = key
    return f"{short} = {show(value)}"


def qkey(table, key):
    """``campaign.grid."motion.heading"``: a key path as a TOML file writes it."""
    return f'campaign.{table}."{key}"' if "." in key else f"campaign.{table}.{key}"


# ---------------------------------------------------------------------------
# 1-3. Values, grid strings (the command line) and seeds
# ---------------------------------------------------------------------------
def _split_top(text, sep=","):
    """``text`` split at ``sep`` outside brackets, braces and quotes."""
    parts, depth, quote, cur = [], 0, None, []
    for ch in text:
        if quote:
            if ch == quote:
                quote = None
        elif ch in "\"'":
            quote = ch
        elif ch in "[{":
            depth += 1
        elif ch in "]}":
            depth -= 1
        elif ch == sep and depth == 0:
            parts.append("".join(cur))
            cur = []
            continue
        cur.append(ch)
    parts.append("".join(cur))
    return parts


def parse_value(text):
    """A value written on the command line, as a TOML file would hold it:
    ``3`` -> 3, ``0.5`` -> 0.5, ``true`` -> True, ``["1 deg", 0, 0]`` -> a
    list, ``"x"`` -> "x"; anything TOML does not read (``60 deg``,
    ``flexible``) is that string."""
    text = text.strip()
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def parse_grid(strings):
    """``["motion.heading=0 deg,60 deg", "seed=1,2"]`` -> {key: [values]}
    (values read by `parse_value`; commas inside brackets or quotes do not
    split). A key given twice is an error."""
    grid = {}
    for s in strings or ():
        key, eq, values = s.partition("=")
        key = key.strip()
        if not eq or not key:
            raise ScenarioError(f"{s!r} must be KEY=VALUE[,VALUE...] (e.g. 'motion.heading=0 deg,60 deg')",
                                "", "command line")
        if key in grid:
            raise ScenarioError("given twice", qkey("grid", key), "command line")
        vals = [parse_value(v) for v in _split_top(values)]
        if any(v == "" for v in vals):
            raise ScenarioError(f"an empty value in {values!r}", qkey("grid", key), "command line")
        grid[key] = vals
    return grid


def parse_overrides(items):
    """["duration=30 s", ...] or a dict -> {key: value}."""
    if items is None:
        return {}
    if isinstance(items, dict):
        return dict(items)
    out = {}
    for s in items:
        key, eq, value = s.partition("=")
        if not eq or not key.strip():
            raise ScenarioError(f"{s!r} must be KEY=VALUE (e.g. 'duration=30 s')", "", "command line")
        out[key.strip()] = parse_value(value)
    return out


#: The most seeds a campaign takes (each is at least one run; more is a typo, not a plan)
MAX_SEEDS = 100_000


def parse_seeds(seeds, where, source):
    """None, a count N (0..N-1), a list, or text ("5", "0,3,7", "2..6")."""
    if seeds is None:
        return None
    if isinstance(seeds, str):
        s = seeds.strip()
        if ".." in s:
            a, _, b = s.partition("..")
            try:
                first, last = int(a), int(b)
            except ValueError:
                raise ScenarioError(f"{seeds!r}: write a count, a list or FIRST..LAST", where,
                                    source) from None
            if last - first + 1 > MAX_SEEDS:
                raise ScenarioError(f"out of range: {seeds!r} is {last - first + 1} seeds, more than "
                                    f"{MAX_SEEDS} runs", where, source)
            seeds = list(range(first, last + 1))
        elif "," in s:
            seeds = [parse_value(v) for v in s.split(",")]
        else:
            seeds = parse_value(s)
    if isinstance(seeds, bool):
        raise ScenarioError(f"must be a count or a list of seeds, got {seeds!r}", where, source)
    if isinstance(seeds, int):
        if seeds < 1:
            raise ScenarioError(f"out of range: a count of seeds must be >= 1, got {seeds}", where, source)
        if seeds > MAX_SEEDS:
            raise ScenarioError(f"out of range: {seeds} seeds is more than {MAX_SEEDS} runs", where, source)
        return list(range(seeds))
    if not isinstance(seeds, (list, tuple)) or not seeds:
        raise ScenarioError(f"must be a count or a non-empty list of seeds, got {seeds!r}", where, source)
    for s in seeds:
        if isinstance(s, bool) or not isinstance(s, int) or s < 0:
            raise ScenarioError(f"seeds must be integers >= 0, got {s!r}", where, source)
    if len(set(seeds)) != len(seeds):
        raise ScenarioError("a seed is given twice", where, source)
    return list(seeds)


# ---------------------------------------------------------------------------
# 4. Seed formulas
# ---------------------------------------------------------------------------
_ALLOWED_NODES = (ast.Expression, ast.BinOp, ast.UnaryOp, ast.Constant, ast.Name, ast.Load,
                  ast.Add, ast.Sub, ast.Mult, ast.FloorDiv, ast.Mod, ast.USub, ast.UAdd)


def compile_formula(text, names, where, source):
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError as exc:
        raise ScenarioError(f"cannot read {text!r}: {exc.msg}", where, source) from None
    for node in ast.walk(tree):
        if not isinstance(node, _ALLOWED_NODES):
            raise ScenarioError(f"{text!r}: only numbers, names, + - * // % and parentheses are "
                                f"allowed", where, source)
        if isinstance(node, ast.Constant) and (isinstance(node.value, bool)
                                               or not isinstance(node.value, (int, float))):
            raise ScenarioError(f"{text!r}: {node.value!r} is not a number", where, source)
        if isinstance(node, ast.Name) and node.id not in names:
            close = difflib.get_close_matches(node.id, names, n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise ScenarioError(f"{text!r}: unknown name {node.id!r}{hint} (names: "
                                f"{', '.join(sorted(names))})", where, source)
    return tree


def eval_formula(node, env):
    if isinstance(node, ast.Expression):
        return eval_formula(node.body, env)
    if isinstance(node, ast.Constant):
        return node.value
    if isinstance(node, ast.Name):
        value = env[node.id]
        if isinstance(value, str):
            raise ValueError(value)
        return value
    if isinstance(node, ast.UnaryOp):
        v = eval_formula(node.operand, env)
        return -v if isinstance(node.op, ast.USub) else v
    a, b = eval_formula(node.left, env), eval_formula(node.right, env)
    op = type(node.op)
    if op is ast.Add:
        return a + b
    if op is ast.Sub:
        return a - b
    if op is ast.Mult:
        return a * b
    if op is ast.FloorDiv:
        return a // b
    return a % b


def number_as_written(value):
    """60 for "60 deg", 3 for 3; None when the value is not a number."""
    if isinstance(value, bool):
        return None
    if isinstance(value, (int, float)):
        return value
    if isinstance(value, str):
        try:
            x = split_quantity(value)[0]
        except ValueError:
            return None
        return int(x) if x.is_integer() else x
    return None


def formula_names(grid_keys):
    """name -> (grid key, "value" | "index") for a seed formula."""
    names = {}
    short = {}
    for key in grid_keys:
        full = key.replace(".", "_")
        names[full] = (key, "value")
        names[f"{full}_index"] = (key, "index")
        short.setdefault(key.split(".")[-1], []).append(key)
    for s, keys in short.items():
        if len(keys) == 1 and s not in names:
            names[s] = (keys[0], "value")
            names[f"{s}_index"] = (keys[0], "index")
    return names
