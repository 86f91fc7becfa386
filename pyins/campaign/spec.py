"""Campaigns: grids and Monte-Carlo sets of scenario runs, aggregated per group.

A campaign is a base scenario (a built-in name or a TOML path), a grid of
overrides (dotted scenario keys -> lists of values, as
`pyins.scenario.Scenario.with_overrides` takes them), optional fixed
overrides applied to every run, noise seeds (a count or a list, optionally
turned into the scenario's ``seed`` by a formula) and the keys to group the
runs by. Every combination of grid values times every seed is one *point*;
each point is one scenario, validated when the campaign is built, and run
with `pyins.runs.execute` into ``OUT/runs/<digest[:16]>`` where ``digest``
is `Scenario.digest` of the overridden scenario: runs are content
addressed, so a campaign that is run again (after a kill, a Ctrl-C, or with
more seeds) runs only what has no complete summary.json of that digest.

    >>> camp = load_campaign("seed000_static")       # a built-in, or a campaign .toml
    >>> camp = from_args("seed000_static", ["motion.heading=0 deg,60 deg"], 5)
    >>> result = run_campaign(camp, "runs/campaigns/x")   # doctest: +SKIP
    >>> run_campaign(camp, "runs/campaigns/x", scheduler="tcp://10.0.0.5:8786")  # doctest: +SKIP

Execution: a local process pool using every core (``workers``), or a Dask
distributed cluster (``scheduler``: its address, or a ``distributed.Client``)
whose workers see ``out_dir`` at the same path (one machine, or a shared
file system) and have the same pyins installed; dask is imported only then.
Each run writes only its own directory, its summary.json last and
atomically, so a kill loses at most the runs in flight.

Aggregation reads the runs' summary.json files in point order (never the
order they finished in), so the aggregates of a campaign are the same bit
for bit whether it ran locally, on Dask, or in several interrupted pieces.
Per group and metric (and per [compare] variant when the base keeps its
[compare]): count, mean, std (ddof=1), min, p5, p50, p95, max; per group
also seed 000's level/heading error std over the runs (`METRICS`
``level_error_std``, ``heading_error_std``). Written: campaign.json (SI,
units in the metric names), aggregate.csv (SI), aggregate.md and plots/
(the papers' units: arcsec, arcmin, m or nmi), runs.csv (every run's
metrics, SI). docs/campaigns.md is the guide.

The base scenario's [compare] (e.g. seed000_static compares five seeds):
``compare = "drop"`` removes it (and the base's [paper], whose figures may
name its variants: campaign.json keeps it), so each point is one run;
``"keep"`` runs every variant at every point and aggregates each variant
separately (keyed by its label); ``"auto"`` (default) drops it when the
campaign itself sets the compared key (a grid key, a fixed override, or
``seed`` when it has seeds), and keeps it otherwise.
"""
import ast
import copy
import csv
import difflib
import hashlib
import io
import itertools
import json
import math
import os
import re
import time
from dataclasses import dataclass, field
from pathlib import Path

try:
    import tomllib
except ImportError:            # Python 3.10
    import tomli as tomllib

import numpy as np

from pyins import scenario as scenario_mod
from pyins.units import ScenarioError, split_quantity

__all__ = ["Campaign", "Point", "CampaignError", "ScenarioError", "load_campaign", "loads_campaign",
           "from_args", "parse_grid", "parse_value", "run_campaign", "aggregate", "pending",
           "list_builtin", "builtin_path", "default_out_dir", "STATS"]

SCHEMA_VERSION = 1
BUILTIN_DIR = Path(__file__).resolve().parent / "campaigns"
DASK_CONNECT_TIMEOUT = "20s"   #: how long to wait for a Dask scheduler
STATS = ("count", "mean", "std", "min", "p5", "p50", "p95", "max")
CAMPAIGN_KEYS = ("name", "title", "description", "scenario", "seeds", "seed_formula", "group_by",
                 "compare", "grid", "set", "labels")
_SI_SUFFIX = {"length": "_m", "angle": "_rad", "velocity": "_mps", "angular_rate": "_rad_s"}
#: per-run metrics pyins.runs.metrics gives beyond scenario.METRICS
_EXTRA_METRICS = {"phi_e_final": ("angle", "phi_E (east attitude error) at the end of the run"),
                  "phi_n_final": ("angle", "phi_N (north attitude error) at the end of the run"),
                  "phi_u_final": ("angle", "phi_U (up attitude error, heading) at the end of the run")}
GROUP_METRICS = ("level_error_std", "heading_error_std")


class CampaignError(RuntimeError):
    """A campaign that cannot run (no dask, no scheduler) or whose runs
    failed (``result``: the campaign.json written with what did finish)."""

    def __init__(self, message, result=None):
        super().__init__(message)
        self.result = result


def _metric_info(metric):
    return scenario_mod.METRICS.get(metric) or _EXTRA_METRICS.get(metric) or ("dimensionless", "")


def si_name(metric):
    """``level_error_final`` -> ``level_error_final_rad`` (the SI unit in the name)."""
    return metric + _SI_SUFFIX.get(_metric_info(metric)[0], "")


def _canonical(value):
    return json.dumps(value, sort_keys=True, separators=(",", ":"), allow_nan=False)


def _show(value):
    """A grid value as text: strings as written, anything else as JSON."""
    return value if isinstance(value, str) else json.dumps(value)


def _value_label(labels, key, value, keys=()):
    """A grid value as text: its label ([campaign.labels]), else "heading = 60 deg"
    (the key's last part; the whole key if another of ``keys`` ends alike)."""
    names = (labels or {}).get(key)
    if names:
        return names[1][names[0].index(_canonical(value))]
    short = key.split(".")[-1]
    if sum(k.split(".")[-1] == short for k in keys) > 1:
        short = key
    return f"{short} = {_show(value)}"


def _qkey(table, key):
    """``campaign.grid."motion.heading"``: a key path as a TOML file writes it."""
    return f'campaign.{table}."{key}"' if "." in key else f"campaign.{table}.{key}"


# ---------------------------------------------------------------------------
# Grid strings (the command line) and seed formulas
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
            raise ScenarioError("given twice", _qkey("grid", key), "command line")
        vals = [parse_value(v) for v in _split_top(values)]
        if any(v == "" for v in vals):
            raise ScenarioError(f"an empty value in {values!r}", _qkey("grid", key), "command line")
        grid[key] = vals
    return grid


def _parse_overrides(items):
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


def _parse_seeds(seeds, where, source):
    """None, a count N (0..N-1), a list, or text ("5", "0,3,7", "2..6")."""
    if seeds is None:
        return None
    if isinstance(seeds, str):
        s = seeds.strip()
        if ".." in s:
            a, _, b = s.partition("..")
            try:
                seeds = list(range(int(a), int(b) + 1))
            except ValueError:
                raise ScenarioError(f"{seeds!r}: write a count, a list or FIRST..LAST", where,
                                    source) from None
        elif "," in s:
            seeds = [parse_value(v) for v in s.split(",")]
        else:
            seeds = parse_value(s)
    if isinstance(seeds, bool):
        raise ScenarioError(f"must be a count or a list of seeds, got {seeds!r}", where, source)
    if isinstance(seeds, int):
        if seeds < 1:
            raise ScenarioError(f"out of range: a count of seeds must be >= 1, got {seeds}", where, source)
        return list(range(seeds))
    if not isinstance(seeds, (list, tuple)) or not seeds:
        raise ScenarioError(f"must be a count or a non-empty list of seeds, got {seeds!r}", where, source)
    for s in seeds:
        if isinstance(s, bool) or not isinstance(s, int) or s < 0:
            raise ScenarioError(f"seeds must be integers >= 0, got {s!r}", where, source)
    if len(set(seeds)) != len(seeds):
        raise ScenarioError("a seed is given twice", where, source)
    return list(seeds)


_ALLOWED_NODES = (ast.Expression, ast.BinOp, ast.UnaryOp, ast.Constant, ast.Name, ast.Load,
                  ast.Add, ast.Sub, ast.Mult, ast.FloorDiv, ast.Mod, ast.USub, ast.UAdd)


def _compile_formula(text, names, where, source):
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


def _eval(node, env):
    if isinstance(node, ast.Expression):
        return _eval(node.body, env)
    if isinstance(node, ast.Constant):
        return node.value
    if isinstance(node, ast.Name):
        value = env[node.id]
        if isinstance(value, str):
            raise ValueError(value)
        return value
    if isinstance(node, ast.UnaryOp):
        v = _eval(node.operand, env)
        return -v if isinstance(node.op, ast.USub) else v
    a, b = _eval(node.left, env), _eval(node.right, env)
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


def _number_as_written(value):
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


def _formula_names(grid_keys):
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


# ---------------------------------------------------------------------------
# The campaign
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class Point:
    """One run of a campaign."""
    index: int                  #: position in the campaign (grid order, then seeds)
    values: dict                #: grid key -> value as written
    run: object                 #: the `seeds` entry (None: no seeds)
    seed: object                #: the scenario seed set (None: the base's own)
    group: int                  #: index of its group
    overrides: dict             #: everything passed to Scenario.with_overrides
    digest: str                 #: Scenario.digest() of the overridden scenario

    @property
    def dir(self):
        """Its run directory, relative to the campaign's out_dir."""
        return f"runs/{self.digest[:16]}"

    def label(self, labels=None):
        """"motion.heading = 60 deg, run 3 (seed 60003)" (``labels``: Campaign.labels)."""
        parts = [_value_label(labels, k, v, self.values) for k, v in self.values.items()]
        if self.run is not None:
            parts.append(f"run {self.run}" + (f" (seed {self.seed})" if self.seed != self.run else ""))
        return ", ".join(parts) or "base"


@dataclass
class Campaign:
    """A validated campaign; build it with `load_campaign` or `from_args`."""
    name: str
    title: str
    description: str
    base: object                      #: the base pyins.scenario.Scenario
    scenario_ref: str                 #: the base as written (built-in name or path)
    grid: dict                        #: grid key -> [values]
    seeds: object                     #: [int] or None
    seed_formula: object              #: str or None
    group_by: list
    overrides: dict                   #: fixed overrides (every run)
    compare: str                      #: "keep" or "drop" (what "auto" became)
    labels: dict                      #: grid key -> ([canonical values], [labels])
    source: str
    points: list = field(default_factory=list)
    groups: list = field(default_factory=list)   #: [{values: {key: value}, label: str}]

    def __repr__(self):
        return (f"Campaign({self.name!r}, {len(self.points)} runs in {len(self.groups)} group(s), "
                f"base {self.base.name!r})")

    @property
    def variants(self):
        """The [compare] labels of the base each point runs (None: one run per point)."""
        return self.base.labels if self.compare == "keep" and len(self.base.labels) > 1 else None

    def digest(self):
        """SHA-256 of the campaign's content: its points (digests) and grouping."""
        body = {"points": [[p.digest, p.group, _canonical(p.values), p.run] for p in self.points],
                "group_by": self.group_by, "compare": self.compare}
        return hashlib.sha256(_canonical(body).encode()).hexdigest()

    def describe(self):
        """The campaign's definition as a plain dict (for campaign.json)."""
        return {"name": self.name, "title": self.title, "description": self.description,
                "source": self.source, "scenario": self.scenario_ref,
                "base": {"name": self.base.name, "title": self.base.title, "source": self.base.source,
                         "digest": self.base.digest(), "labels": self.base.labels},
                "grid": self.grid, "labels": {k: v[1] for k, v in self.labels.items()},
                "seeds": self.seeds, "seed_formula": self.seed_formula, "group_by": self.group_by,
                "set": self.overrides, "compare": self.compare, "variants": self.variants,
                "digest": self.digest()}


def _base_overrides(base, compare, fixed):
    out = {}
    if compare == "drop":
        out.update({"compare": None, "paper": None})
    out.update(fixed)
    return out


def _rewrap(exc, key, source, prefix=""):
    """A ScenarioError of a point, as one line about the campaign file."""
    inner = f"{exc.key}: {exc.reason}" if exc.key else exc.reason
    return ScenarioError(prefix + inner, key, source)


def _build(base, scenario_ref, grid, seeds, group_by, *, overrides=None, seed_formula=None,
           compare="auto", labels=None, name=None, title=None, description="", source="command line"):
    """Validate everything and expand the points (ScenarioError: one line)."""
    grid = dict(grid or {})
    fixed = dict(overrides or {})
    # grid and fixed keys: scenario keys, not the campaign's own business
    for table, keys in (("set", fixed), ("grid", grid)):
        for key in keys:
            where = _qkey(table, key)
            if key == "seed" and table == "grid":
                raise ScenarioError("the seeds of a campaign go in campaign.seeds (a count or a list), "
                                    "not in the grid", where, source)
            try:
                scenario_mod._check_key_path(key, where)
            except ScenarioError as exc:
                raise ScenarioError(exc.reason.replace(f"{key!r} ", "", 1) if exc.reason.startswith(
                    f"{key!r} ") else exc.reason, where, source) from None
            if key.split(".")[0] in ("compare", "paper", "name"):
                raise ScenarioError(f"{key!r} cannot be set by a campaign (use campaign.compare to "
                                    f"keep or drop the base's [compare])", where, source)
    for key, values in grid.items():
        where = _qkey("grid", key)
        if key in fixed:
            raise ScenarioError("set both in campaign.set and in campaign.grid", where, source)
        if not isinstance(values, list) or not values:
            raise ScenarioError(f"must be a non-empty array of values, got {values!r}", where, source)
        canon = [_canonical(v) for v in values]
        if len(set(canon)) != len(canon):
            dup = next(v for i, v in enumerate(values) if canon.index(canon[i]) != i)
            raise ScenarioError(f"the value {dup!r} is given twice", where, source)
    # labels of grid values
    lab = {}
    for key, names in (labels or {}).items():
        where = _qkey("labels", key)
        if key not in grid:
            raise ScenarioError(f"{key!r} is not a grid key (grid: {', '.join(grid) or 'none'})",
                                where, source)
        if not isinstance(names, list) or not all(isinstance(s, str) for s in names):
            raise ScenarioError("must be an array of strings, one per grid value", where, source)
        if len(names) != len(grid[key]):
            raise ScenarioError(f"{len(names)} labels for {len(grid[key])} values", where, source)
        if len(set(names)) != len(names):
            raise ScenarioError("labels must differ from each other", where, source)
        lab[key] = ([_canonical(v) for v in grid[key]], list(names))
    # seeds and their formula
    seeds = _parse_seeds(seeds, "campaign.seeds", source)
    formula = None
    names = _formula_names(grid)
    if seed_formula is not None:
        if not isinstance(seed_formula, str) or not seed_formula.strip():
            raise ScenarioError(f"must be a formula as a string (e.g. '1000 * heading + run'), got "
                                f"{seed_formula!r}", "campaign.seed_formula", source)
        formula = _compile_formula(seed_formula, set(names) | {"run", "point"},
                                   "campaign.seed_formula", source)
        if seeds is None:
            seeds = [0]
    # what becomes of the base's [compare]
    if compare not in ("auto", "keep", "drop"):
        raise ScenarioError(f"unknown value {compare!r} (choose one of auto, keep, drop)",
                            "campaign.compare", source)
    ckey = (base.resolved().get("compare") or {}).get("key")
    if "seed" in fixed and seeds is not None:
        raise ScenarioError("the seed is set both here and by campaign.seeds", _qkey("set", "seed"),
                            source)
    set_by_campaign = set(grid) | set(fixed) | ({"seed"} if seeds is not None else set())
    set_by_campaign |= {scenario_mod._ALTERNATIVES[k] for k in set_by_campaign
                        if k in scenario_mod._ALTERNATIVES}          # yaw <-> heading
    if ckey is None:
        compare = "drop" if compare == "auto" else compare
        if compare == "keep":
            compare = "drop"              # nothing to keep: one run per point either way
    elif compare == "auto":
        compare = "drop" if ckey in set_by_campaign else "keep"
    elif compare == "keep" and ckey in set_by_campaign:
        raise ScenarioError(f"the base scenario's [compare] varies {ckey!r}, which the campaign sets "
                            f"too: use compare = 'drop'", "campaign.compare", source)
    # group_by
    if group_by is None:
        group_by = list(grid)
    elif isinstance(group_by, str):
        group_by = [s.strip() for s in group_by.split(",") if s.strip()]
    if not isinstance(group_by, (list, tuple)) or not all(isinstance(s, str) for s in group_by):
        raise ScenarioError(f"must be an array of grid keys, got {group_by!r}", "campaign.group_by", source)
    allowed = list(grid) + (["seed"] if seeds is not None else [])
    for key in group_by:
        if key not in allowed:
            close = difflib.get_close_matches(key, allowed, n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise ScenarioError(f"{key!r} is not a grid key{hint} (group by any of: "
                                f"{', '.join(allowed) or 'nothing: the campaign has no grid'})",
                                "campaign.group_by", source)
    if len(set(group_by)) != len(group_by):
        raise ScenarioError("a key is given twice", "campaign.group_by", source)
    group_by = list(group_by)

    common = _base_overrides(base, compare, fixed)
    try:
        base.with_overrides(common)
    except ScenarioError as exc:
        if exc.key in fixed:
            raise ScenarioError(exc.reason, _qkey("set", exc.key), source) from None
        raise _rewrap(exc, "campaign.set", source) from None
    # every grid value alone, for a message naming the value
    for key, values in grid.items():
        for i, v in enumerate(values):
            try:
                base.with_overrides({**common, key: v})
            except ScenarioError as exc:
                inner = exc.reason if exc.key == key else f"{exc.key}: {exc.reason}" if exc.key else exc.reason
                raise ScenarioError(inner, f"{_qkey('grid', key)}[{i}]", source) from None

    points, groups, group_index = [], [], {}
    keys = list(grid)
    combos = list(itertools.product(*(range(len(grid[k])) for k in keys)))
    for ci, combo in enumerate(combos):
        values = {k: grid[k][i] for k, i in zip(keys, combo)}
        for run in (seeds if seeds is not None else [None]):
            ov = dict(common)
            ov.update(values)
            seed = run
            if formula is not None:
                env = {"run": run, "point": ci}
                for nm, (k, what) in names.items():
                    if what == "index":
                        env[nm] = combo[keys.index(k)]
                    else:
                        num = _number_as_written(values[k])
                        env[nm] = num if num is not None else (
                            f"{nm} is {_show(values[k])!r}, not a number: use {nm}_index")
                try:
                    seed = _eval(formula, env)
                except ValueError as exc:
                    raise ScenarioError(f"{seed_formula!r}: {exc}", "campaign.seed_formula",
                                        source) from None
                except (ZeroDivisionError, OverflowError) as exc:
                    raise ScenarioError(f"{seed_formula!r}: {exc}", "campaign.seed_formula",
                                        source) from None
                if isinstance(seed, float) and seed.is_integer():
                    seed = int(seed)
                if not isinstance(seed, int) or seed < 0:
                    raise ScenarioError(f"{seed_formula!r} gives {seed!r} for "
                                        f"{', '.join(f'{k} = {_show(v)}' for k, v in values.items())}"
                                        f"{', ' if values else ''}run {run}: a seed must be an "
                                        f"integer >= 0", "campaign.seed_formula", source)
            if seed is not None:
                ov["seed"] = seed
            try:
                scn = base.with_overrides(ov)
            except ScenarioError as exc:
                at = ", ".join(f"{k} = {_show(v)}" for k, v in values.items())
                at += (", " if at else "") + (f"seed {seed}" if seed is not None else "")
                raise _rewrap(exc, "campaign.grid", source, f"with {at}: ") from None
            gkey = tuple(_canonical(values[k]) if k != "seed" else str(run) for k in group_by)
            if gkey not in group_index:
                group_index[gkey] = len(groups)
                gvals = {k: (values[k] if k != "seed" else run) for k in group_by}
                glabel = ", ".join(
                    _value_label(lab, k, v, grid) if k != "seed" else f"run {v}"
                    for k, v in gvals.items()) or "all runs"
                groups.append({"values": gvals, "label": glabel})
            points.append(Point(index=len(points), values=values, run=run, seed=seed,
                                group=group_index[gkey], overrides=ov, digest=scn.digest()))
    if not isinstance(name, str) or not name:
        name = f"{base.name}_campaign"
    if not re.fullmatch(r"[A-Za-z0-9_.-]+", name):
        raise ScenarioError(f"{name!r} may hold only letters, digits, '_', '.' and '-'", "campaign.name",
                            source)
    return Campaign(name=name, title=title or name, description=description or "", base=base,
                    scenario_ref=scenario_ref, grid=grid, seeds=seeds, seed_formula=seed_formula,
                    group_by=group_by, overrides=fixed, compare=compare, labels=lab, source=source,
                    points=points, groups=groups)


def _flatten(table, where, source):
    """{"motion.heading": [...]} or {"motion": {"heading": [...]}} (unquoted
    dotted TOML keys) -> {"motion.heading": [...]}."""
    if not isinstance(table, dict):
        raise ScenarioError(f"must be a table, got {table!r}", where, source)
    out = {}
    for key, value in table.items():
        if isinstance(value, dict) and key in scenario_mod.TABLES:
            for sub, v in value.items():
                out[f"{key}.{sub}"] = v
        else:
            out[key] = value
    return out


def _load_base(ref, source, relative_to=None):
    """The base scenario: a path (relative to the campaign file first) or a built-in."""
    if not isinstance(ref, str) or not ref:
        raise ScenarioError(f"must be a built-in scenario name or a path, got {ref!r}",
                            "campaign.scenario", source)
    path = ref
    if relative_to is not None and not os.path.isabs(ref):
        cand = Path(relative_to).parent / ref
        if cand.is_file():
            path = str(cand)
    try:
        return scenario_mod.load(path)
    except ScenarioError as exc:
        if exc.source == path and not exc.key:          # no such file or built-in
            raise ScenarioError(f"{ref!r}: {exc.reason}", "campaign.scenario", source) from None
        raise ScenarioError(f"the base scenario {ref!r} is invalid: {exc}", "campaign.scenario",
                            source) from None


def loads_campaign(text, source="<string>", name=None, relative_to=None):
    """A Campaign from the TOML text of a campaign file."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"malformed TOML: {exc}", "", source) from None
    if "campaign" not in data:
        if "motion" in data:
            raise ScenarioError("this is a scenario file, not a campaign: a campaign file has a "
                                "[campaign] table whose 'scenario' names the base scenario", "", source)
        raise ScenarioError("missing table [campaign] (required: scenario = '...', [campaign.grid], "
                            "seeds, group_by)", "campaign", source)
    for key in data:
        if key != "campaign":
            close = difflib.get_close_matches(key, ["campaign"], n=1)
            hint = f"; did you mean {close[0]!r}?" if close else " (a campaign file holds only [campaign])"
            raise ScenarioError(f"unknown key{hint}", key, source)
    c = data["campaign"]
    if not isinstance(c, dict):
        raise ScenarioError("must be a table", "campaign", source)
    for key in c:
        if key not in CAMPAIGN_KEYS:
            close = difflib.get_close_matches(key, CAMPAIGN_KEYS, n=1, cutoff=0.5)
            hint = f"did you mean {close[0]!r}?" if close else f"known keys: {', '.join(CAMPAIGN_KEYS)}"
            raise ScenarioError(f"unknown key; {hint}", f"campaign.{key}", source)
    if "scenario" not in c:
        raise ScenarioError("missing (required: the base scenario, a built-in name or a path)",
                            "campaign.scenario", source)
    for key in ("name", "title", "description", "compare"):
        if key in c and not isinstance(c[key], str):
            raise ScenarioError(f"must be a string, got {c[key]!r}", f"campaign.{key}", source)
    if "seeds" in c and isinstance(c["seeds"], str):
        raise ScenarioError(f"must be a count or an array of seeds, got the string {c['seeds']!r}",
                            "campaign.seeds", source)
    base = _load_base(c["scenario"], source, relative_to)
    grid = _flatten(c.get("grid", {}), "campaign.grid", source)
    fixed = _flatten(c.get("set", {}), "campaign.set", source)
    labels = _flatten(c.get("labels", {}), "campaign.labels", source)
    if not grid and "seeds" not in c:
        raise ScenarioError("a campaign needs a grid ([campaign.grid]) or seeds", "campaign", source)
    return _build(base, c["scenario"], grid, c.get("seeds"), c.get("group_by"), overrides=fixed,
                  seed_formula=c.get("seed_formula"), compare=c.get("compare", "auto"), labels=labels,
                  name=c.get("name", name), title=c.get("title"), description=c.get("description", ""),
                  source=source)


def builtin_path(name):
    """The path of built-in campaign ``name`` (to copy and edit)."""
    return scenario_mod.find_builtin(BUILTIN_DIR, name, "campaign", [n for n, _ in list_builtin()])


def load_campaign(path_or_name):
    """A Campaign from a campaign .toml file, or the built-in of that name."""
    text, path = scenario_mod.read_toml_source(path_or_name, builtin_path)
    return loads_campaign(text, source=str(path), name=path.stem, relative_to=path)


def list_builtin():
    """[(name, title)] of the built-in campaigns, sorted by name."""
    out = []
    for path in sorted(BUILTIN_DIR.glob("*.toml")):
        data = tomllib.loads(path.read_text(encoding="utf-8"))
        out.append((path.stem, data.get("campaign", {}).get("title", path.stem)))
    return out


def from_args(scenario, grid_strings=(), seeds=None, group_by=None, *, overrides=None,
              seed_formula=None, compare="auto", name=None, title=None):
    """A Campaign from command-line style arguments.

    ``scenario``: a built-in name, a path or a Scenario; ``grid_strings``:
    ["motion.heading=0 deg,60 deg,120 deg", ...] (or a dict key -> list);
    ``seeds``: None (the base's seed), a count N (0..N-1), a list, or text
    ("5", "0,3,7", "2..6"); ``group_by``: grid keys (list or "a,b"; None:
    every grid key); ``overrides``: ["duration=30 s", ...] or a dict, set on
    every run; ``seed_formula``: e.g. "1000 * heading + run"; ``compare``:
    "auto", "keep" or "drop" (the base's [compare]).
    """
    source = "command line"
    if isinstance(scenario, scenario_mod.Scenario):
        base, ref = scenario, scenario.name
    else:
        base, ref = _load_base(str(scenario), source), str(scenario)
    grid = dict(grid_strings) if isinstance(grid_strings, dict) else parse_grid(grid_strings)
    if not grid and seeds is None:
        raise ScenarioError("a campaign needs a grid (KEY=V1,V2,...) or seeds", "", source)
    return _build(base, ref, grid, seeds, group_by, overrides=_parse_overrides(overrides),
                  seed_formula=seed_formula, compare=compare, name=name, title=title, source=source)


def default_out_dir(camp):
    """runs/campaigns/<name>: where the CLI puts a campaign by default."""
    return os.path.join("runs", "campaigns", camp.name)


# ---------------------------------------------------------------------------
# Running
# ---------------------------------------------------------------------------
def _read_summary(run_dir):
    try:
        with open(os.path.join(run_dir, "summary.json")) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def _is_done(run_dir, digest):
    s = _read_summary(run_dir)
    return s is not None and s.get("complete") is True and s.get("digest") == digest


def _write_json(path, obj):
    tmp = f"{path}.tmp{os.getpid()}"
    with open(tmp, "w") as f:
        json.dump(obj, f, indent=2, allow_nan=False)
        f.write("\n")
    os.replace(tmp, path)


def _run_point(task):
    """Run one point into its run directory (in a pool process or on a Dask
    worker): rebuild the scenario from the base's data and the overrides,
    check its digest, `pyins.runs.execute` it (resume=True: an earlier
    killed attempt continues from its checkpoint). Returns
    {"digest", "wall_s", "summary"}."""
    from pyins import runs
    t0 = time.perf_counter()
    base = scenario_mod.Scenario(task["text"], copy.deepcopy(task["data"]), task["source"], task["stem"])
    scn = base.with_overrides(task["overrides"])
    digest = scn.digest()
    if digest != task["digest"]:
        raise CampaignError(f"this worker's pyins resolves the scenario differently (digest "
                            f"{digest[:16]}, not {task['digest'][:16]}): install the same pyins on "
                            f"every worker")
    run_dir = task["run_dir"]
    os.makedirs(run_dir, exist_ok=True)
    point_json = os.path.join(run_dir, "point.json")
    if os.path.exists(point_json):
        with open(point_json) as f:
            old = json.load(f)
        if old.get("digest") != digest:
            raise CampaignError(f"{run_dir} belongs to another scenario (digest {old.get('digest')})")
    else:
        _write_json(point_json, {"digest": digest, "base": base.name, "base_source": str(task["source"]),
                                 "overrides": task["overrides"]})
    try:
        summary = runs.execute(scn, run_dir, resume=True)
    except ValueError as exc:
        if "checkpoint belongs to another run" not in str(exc):
            raise
        summary = runs.execute(scn, run_dir, resume=False)   # a checkpoint of an older pyins
    return {"digest": digest, "wall_s": time.perf_counter() - t0, "summary": summary}


def pending(camp, out_dir):
    """The digests (in point order, each once) of the runs of ``camp`` that
    have no complete summary.json in ``out_dir``, and how many runs it has."""
    seen, todo = set(), []
    for p in camp.points:
        if p.digest in seen:
            continue
        seen.add(p.digest)
        if not _is_done(os.path.join(out_dir, p.dir), p.digest):
            todo.append(p.digest)
    return todo, len(seen)


def _tasks(camp, out_dir, digests):
    by_digest = {}
    for p in camp.points:
        by_digest.setdefault(p.digest, p)
    data = camp.base.data
    out = []
    for d in digests:
        p = by_digest[d]
        out.append({"text": camp.base.text, "data": data, "source": camp.base.source,
                    "stem": getattr(camp.base, "_stem", camp.base.name), "overrides": p.overrides,
                    "digest": d, "run_dir": os.path.abspath(os.path.join(out_dir, p.dir)),
                    "label": p.label(camp.labels)})
    return out


def _first_line(exc):
    text = f"{type(exc).__name__}: {exc}"
    return text.splitlines()[0] if text else type(exc).__name__


def _run_local(tasks, workers, on_done):
    from concurrent.futures import ProcessPoolExecutor, as_completed
    if workers == 1:
        for t in tasks:
            try:
                on_done(t, _run_point(t), None)
            except KeyboardInterrupt:
                raise
            except Exception as exc:             # noqa: BLE001 - recorded, the others go on
                on_done(t, None, exc)
        return "local, in process"
    ex = ProcessPoolExecutor(max_workers=workers)
    futs = {}
    try:
        futs = {ex.submit(_run_point, t): t for t in tasks}
        for f in as_completed(futs):
            exc = f.exception()
            on_done(futs[f], None if exc else f.result(), exc)
    except BaseException:
        for f in futs:
            f.cancel()
        ex.shutdown(wait=False, cancel_futures=True)
        raise
    ex.shutdown(wait=True)
    return f"local process pool, {workers} worker(s)"


def _run_dask(tasks, scheduler, on_done):
    try:
        import distributed
    except ImportError:
        raise CampaignError("running on a Dask cluster needs dask.distributed: "
                            "pip install 'pyins[campaign]' (or \"dask[distributed]\")") from None
    own = not isinstance(scheduler, distributed.Client)
    if own:
        try:
            client = distributed.Client(scheduler, timeout=DASK_CONNECT_TIMEOUT)
        except (OSError, TimeoutError) as exc:
            raise CampaignError(f"cannot connect to the Dask scheduler {scheduler}: "
                                f"{_first_line(exc)}") from None
    else:
        client = scheduler
    try:
        address = client.scheduler.address
        futs = client.map(_run_point, tasks, pure=False)
        index = {f.key: t for f, t in zip(futs, tasks)}
        try:
            for f in distributed.as_completed(futs):
                if f.status == "error":
                    on_done(index[f.key], None, f.exception())
                else:
                    on_done(index[f.key], f.result(), None)
                f.release()
        except BaseException:
            client.cancel(futs)
            raise
    finally:
        if own:
            client.close()
    return f"dask {address}"


def run_campaign(camp, out_dir, workers=None, scheduler=None, progress=None, log=None, plots=True):
    """Run the campaign's missing runs into ``out_dir`` and aggregate.

    ``workers``: processes of the local pool (default os.cpu_count(); 1 runs
    in this process); ``scheduler``: a Dask scheduler address
    ("tcp://host:8786") or a ``distributed.Client``, instead of the local
    pool. ``progress(done, total, skipped)`` is called once before running
    (done = skipped: the runs found complete) and after every run;
    ``log(line)`` gets a line per finished or failed run. Returns the
    campaign.json dict (its ``execution`` entry says what was computed,
    skipped or failed, and the wall time: everything else is the same
    whichever way and in however many pieces the campaign ran). If runs
    failed, every result is still written and CampaignError is raised
    (``.result``: that dict).
    """
    t0 = time.perf_counter()
    out_dir = str(out_dir)
    os.makedirs(os.path.join(out_dir, "runs"), exist_ok=True)
    todo, total = pending(camp, out_dir)
    skipped = total - len(todo)
    _write_json(os.path.join(out_dir, "campaign.json"),
                dict(_plan(camp), complete=False, note="running: aggregates are written at the end"))
    if progress:
        progress(skipped, total, skipped)
    state = {"done": skipped, "computed": 0, "failed": []}
    tasks = _tasks(camp, out_dir, todo)

    def on_done(task, result, exc):
        state["done"] += 1
        if exc is not None:
            state["failed"].append({"digest": task["digest"], "label": task["label"],
                                    "error": _first_line(exc)})
            if log:
                log(f"  FAILED {task['label']}: {_first_line(exc)}")
        else:
            state["computed"] += 1
            if not os.path.exists(os.path.join(task["run_dir"], "summary.json")):
                # a Dask worker without the shared file system: keep its summary here
                os.makedirs(task["run_dir"], exist_ok=True)
                _write_json(os.path.join(task["run_dir"], "summary.json"), result["summary"])
            if log:
                log(f"  {task['label']}: {result['wall_s']:.2f} s")
        if progress:
            progress(state["done"], total, skipped)

    how = "nothing to run"
    if tasks:
        if scheduler is not None:
            how = _run_dask(tasks, scheduler, on_done)
        else:
            n = workers or os.cpu_count() or 1
            how = _run_local(tasks, max(1, min(n, len(tasks))), on_done)
    result = aggregate(camp, out_dir, plots=plots)
    result["execution"] = {"scheduler": how, "runs": total, "computed": state["computed"],
                           "skipped": skipped, "failed": state["failed"],
                           "wall_s": time.perf_counter() - t0}
    _write_json(os.path.join(out_dir, "campaign.json"), result)
    if state["failed"]:
        f = state["failed"][0]
        raise CampaignError(f"{len(state['failed'])} of {total} runs failed (first: {f['label']}: "
                            f"{f['error']}); the results cover the others. Run the campaign again "
                            f"to retry them.", result)
    return result


# ---------------------------------------------------------------------------
# Aggregation
# ---------------------------------------------------------------------------
def _plan(camp):
    return {"schema": SCHEMA_VERSION, "campaign": camp.describe(),
            "groups": [{"index": i, "label": g["label"], "values": g["values"],
                        "points": [p.index for p in camp.points if p.group == i]}
                       for i, g in enumerate(camp.groups)],
            "points": [{"index": p.index, "values": p.values, "run": p.run, "seed": p.seed,
                        "group": p.group, "digest": p.digest, "dir": p.dir} for p in camp.points]}


def _num(x):
    x = float(x)
    return x if math.isfinite(x) else None


def _stats(values):
    a = np.asarray(values, dtype=float)
    p5, p50, p95 = np.percentile(a, [5.0, 50.0, 95.0])
    return {"count": int(a.size), "mean": _num(a.mean()),
            "std": _num(a.std(ddof=1)) if a.size > 1 else None,
            "min": _num(a.min()), "p5": _num(p5), "p50": _num(p50), "p95": _num(p95),
            "max": _num(a.max())}


def _metric_order(names):
    known = list(scenario_mod.METRICS) + list(_EXTRA_METRICS)
    return sorted(names, key=lambda m: (known.index(m) if m in known else len(known), m))


def aggregate(camp, out_dir, plots=True):
    """Read every run's summary.json in point order and write campaign.json,
    aggregate.csv, aggregate.md, runs.csv and plots/ (what is missing is
    left out and listed); returns the campaign.json dict (without
    ``execution``, which run_campaign adds)."""
    from pyins import runs
    plan = _plan(camp)
    variants = camp.variants
    rows = []                   # (point, variant label or None, {metric: value})
    missing, versions = [], set()
    summaries = {}
    for p, pj in zip(camp.points, plan["points"]):
        s = summaries.get(p.digest)
        if s is None:
            s = _read_summary(os.path.join(out_dir, p.dir))
            summaries[p.digest] = s
        if s is None or s.get("digest") != p.digest or s.get("complete") is not True:
            missing.append(p.index)
            pj["metrics"] = None
            continue
        versions.add(s.get("core_version"))
        pj["metrics"] = {}
        for v in s["variants"]:
            label = v["label"] if variants else None
            m = {k: v["metrics"][k] for k in _metric_order(v["metrics"])}
            pj["metrics"][label or ""] = {si_name(k): x for k, x in m.items()}
            rows.append((p, label, m, v))
    vlabels = variants or [None]
    aggregates, group_metrics = [], []
    for gi in range(len(camp.groups)):
        for label in vlabels:
            sel = [r for r in rows if r[0].group == gi and r[1] == label]
            names = _metric_order({k for r in sel for k in r[2]})
            for metric in names:
                vals = [r[2][metric] for r in sel if metric in r[2]]
                aggregates.append({"group": gi, "variant": label, "metric": si_name(metric),
                                   **_stats(vals)})
            gm = runs.group_metrics([r[3] for r in sel])
            for metric in GROUP_METRICS:
                if metric in gm:
                    group_metrics.append({"group": gi, "variant": label, "metric": si_name(metric),
                                          "count": len(sel), "value": _num(gm[metric])})
    present = _metric_order({k for r in rows for k in r[2]}
                            | {m for m in GROUP_METRICS if any(g["metric"] == si_name(m) for g in group_metrics)})
    metrics = {}
    for m in present:
        dim, meaning = _metric_info(m)
        unit, _ = _display_unit(m, [r[2].get(m, 0.0) for r in rows])
        metrics[si_name(m)] = {"metric": m, "dimension": dim, "meaning": meaning, "shown_in": unit}
    result = dict(plan)
    result.update(complete=not missing, missing_points=missing, stats=list(STATS),
                  metrics=metrics, aggregates=aggregates, group_metrics=group_metrics,
                  paper=camp.base.paper, core_versions=sorted(v for v in versions if v))
    _write_json(os.path.join(out_dir, "campaign.json"), result)
    _write_csv(camp, out_dir, result)
    _write_runs_csv(camp, out_dir, result)
    with open(os.path.join(out_dir, "aggregate.md"), "w") as f:
        f.write(_markdown(camp, result, rows))
    if plots:
        _plots(camp, out_dir, result, rows)
    return result


def _display_unit(metric, values_si):
    """(unit, factor) of the papers for a metric: arcsec level, arcmin heading,
    m or nmi position (nmi when the values reach half a mile)."""
    from pyins import report
    if metric.startswith("horizontal_error"):
        big = max((abs(v) for v in values_si if v is not None), default=0.0)
        return ("nmi", report.NMI) if big > 0.5 * report.NMI else ("m", 1.0)
    if metric in report.UNIT_OF:
        return report.UNIT_OF[metric]
    if metric in ("phi_e_final", "phi_n_final"):
        return ("arcsec", report.ARCSEC)
    if metric == "phi_u_final":
        return ("arcmin", report.ARCMIN)
    dim = _metric_info(metric)[0]
    return {"length": ("m", 1.0), "velocity": ("m/s", 1.0), "angle": ("rad", 1.0),
            "angular_rate": ("rad/s", 1.0)}.get(dim, ("", 1.0))


def _fmt(x):
    return "" if x is None else repr(float(x))


def _write_csv(camp, out_dir, result):
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["group", *camp.group_by, "variant", "metric", *STATS, "value"])
    for a in result["aggregates"]:
        g = camp.groups[a["group"]]["values"]
        w.writerow([a["group"], *(_show(g[k]) for k in camp.group_by), a["variant"] or "", a["metric"],
                    a["count"], *(_fmt(a[s]) for s in STATS[1:]), ""])
    for a in result["group_metrics"]:
        g = camp.groups[a["group"]]["values"]
        w.writerow([a["group"], *(_show(g[k]) for k in camp.group_by), a["variant"] or "", a["metric"],
                    a["count"], *([""] * (len(STATS) - 1)), _fmt(a["value"])])
    with open(os.path.join(out_dir, "aggregate.csv"), "w") as f:
        f.write(buf.getvalue())


def _write_runs_csv(camp, out_dir, result):
    names = [si for si, info in result["metrics"].items() if info["metric"] not in GROUP_METRICS]
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["point", *camp.grid, "run", "seed", "group", "variant", "digest", *names])
    for p in result["points"]:
        for label, m in (p["metrics"] or {}).items():
            w.writerow([p["index"], *(_show(p["values"][k]) for k in camp.grid),
                        "" if p["run"] is None else p["run"], "" if p["seed"] is None else p["seed"],
                        p["group"], label, p["digest"][:16], *(_fmt(m.get(n)) for n in names)])
    with open(os.path.join(out_dir, "runs.csv"), "w") as f:
        f.write(buf.getvalue())


def _g(x, scale):
    return "" if x is None else f"{x / scale:.4g}"


def _markdown(camp, result, rows):
    lines = [f"# {camp.title}", ""]
    if camp.description.strip():
        lines += [camp.description.strip(), ""]
    n_runs = len({p.digest for p in camp.points})
    seeds = "" if camp.seeds is None else f" x {len(camp.seeds)} seed(s)"
    if camp.seed_formula:
        seeds += f" (scenario seed = {camp.seed_formula})"
    grid = " x ".join(f"{len(v)} {k}" for k, v in camp.grid.items()) or "no grid"
    lines += [f"Base scenario `{camp.base.name}` ({camp.base.title}); {grid}{seeds}: "
              f"{len(camp.points)} points, {n_runs} runs"
              + (f", each running the base's [compare] variants ({', '.join(camp.variants)})"
                 if camp.variants else "") + f"; grouped by {', '.join(camp.group_by) or 'nothing'} "
              f"({len(camp.groups)} group(s)).", ""]
    if camp.overrides:
        lines += ["Set on every run: " + ", ".join(f"`{k} = {_show(v)}`" for k, v in camp.overrides.items())
                  + ".", ""]
    if result["missing_points"]:
        lines += [f"**Incomplete**: {len(result['missing_points'])} point(s) have no complete run "
                  f"yet; the figures below cover the others.", ""]
    gm = result["group_metrics"]
    vcol = bool(camp.variants)
    if gm:
        lines += ["## Spread over the runs of each group", "",
                  "Std (ddof=1) of the final attitude errors over the runs of a group: level = the "
                  "larger of phi_E and phi_N (seed 000's Table 1).", ""]
        heads = ["group"] + (["variant"] if vcol else []) + ["runs", "level error std [arcsec]",
                                                            "heading error std [arcmin]"]
        lines += ["| " + " | ".join(heads) + " |", "|" + "---|" * len(heads)]
        keyed = {}
        for a in gm:
            keyed.setdefault((a["group"], a["variant"]), {})[a["metric"]] = a
        for (gi, v), d in keyed.items():
            lv = d.get(si_name("level_error_std"))
            hd = d.get(si_name("heading_error_std"))
            cnt = (lv or hd)["count"]
            lines.append("| " + " | ".join([camp.groups[gi]["label"]] + ([v] if vcol else []) + [
                str(cnt), _g(lv and lv["value"], _display_unit("level_error_std", [])[1]),
                _g(hd and hd["value"], _display_unit("heading_error_std", [])[1])]) + " |")
        lines.append("")
    paper = result.get("paper") or {}
    figs = [f for f in paper.get("figures", []) if not f.get("variant") or camp.variants]
    if figs:
        lines += ["## Beside the paper", "", paper.get("citation", ""), ""]
        if paper.get("note"):
            lines += [" ".join(paper["note"].split()), ""]
        if camp.grid or camp.overrides:
            lines += ["These are the base scenario's figures: they compare only with the groups that "
                      "run what the paper ran (the campaign changes "
                      + ", ".join(list(camp.overrides) + list(camp.grid)) + ").", ""]
        heads = ["metric", "paper"] + ["group"] + (["variant"] if vcol else []) + ["ours"]
        lines += ["| " + " | ".join(heads) + " |", "|" + "---|" * len(heads)]
        for f in figs:
            m = f["metric"]
            unit_scale = scenario_mod.in_figure_unit(1.0, f)
            unit_scale = 1.0 / unit_scale if unit_scale else 1.0
            for gi in range(len(camp.groups)):
                for v in (camp.variants or [None]):
                    if f.get("variant") not in (None, v):
                        continue
                    if m in GROUP_METRICS:
                        a = next((a for a in gm if a["group"] == gi and a["variant"] == v
                                  and a["metric"] == si_name(m)), None)
                        ours = None if a is None else f"{_g(a['value'], unit_scale)} {f['unit']}"
                    else:
                        a = next((a for a in result["aggregates"] if a["group"] == gi
                                  and a["variant"] == v and a["metric"] == si_name(m)), None)
                        ours = None if a is None else (f"max {_g(a['max'], unit_scale)}, p95 "
                                                       f"{_g(a['p95'], unit_scale)} {f['unit']}")
                    if ours is not None:
                        lines.append("| " + " | ".join([m, f"{f['relation']} {f['value']:g} {f['unit']}",
                                                        camp.groups[gi]["label"]] + ([v] if vcol else [])
                                                       + [ours]) + " |")
        lines.append("")
    lines += ["## Per metric", "", "Over the runs of each group: count, mean, std (ddof=1), min, "
              "percentiles 5/50/95, max. aggregate.csv holds the same in SI units.", ""]
    zero = [info["metric"] for si, info in result["metrics"].items()
            if info["metric"] not in GROUP_METRICS and not any(r[2].get(info["metric"]) for r in rows)]
    if zero:
        lines += ["Zero in every run (not shown): " + ", ".join(zero) + ".", ""]
    for si, info in result["metrics"].items():
        m = info["metric"]
        if m in GROUP_METRICS or m in zero:
            continue
        sel = [a for a in result["aggregates"] if a["metric"] == si]
        if not sel:
            continue
        unit, scale = _display_unit(m, [r[2].get(m) for r in rows])
        lines += [f"### {m} [{unit}]", "", info["meaning"] + ".", ""]
        lines += _pivot_lines(camp, sel, scale)
        heads = ["group"] + (["variant"] if vcol else []) + list(STATS)
        lines += ["| " + " | ".join(heads) + " |", "|" + "---|" * len(heads)]
        for a in sel:
            lines.append("| " + " | ".join([camp.groups[a["group"]]["label"]] + (
                [a["variant"]] if vcol else []) + [str(a["count"])] + [_g(a[s], scale) for s in STATS[1:]])
                + " |")
        lines.append("")
    return "\n".join(lines)


def _group_value_label(camp, key, value):
    """A group's value of ``key`` as text ("heave 0.5 m", "run 2")."""
    return f"run {value}" if key == "seed" else _value_label(camp.labels, key, value, camp.grid)


def _by_key(camp, key):
    """The groups arranged against one group key: (x labels, lines) with
    lines = [(label of the other keys' values, {x index: group index})], both
    in the order the groups come (grid order)."""
    others = [k for k in camp.group_by if k != key]
    xs, lines = {}, {}
    for gi, g in enumerate(camp.groups):
        vals = g["values"]
        x = xs.setdefault(_canonical(vals[key]), (len(xs), _group_value_label(camp, key, vals[key])))[0]
        line = tuple(_canonical(vals[k]) for k in others)
        if line not in lines:
            lines[line] = (", ".join(_group_value_label(camp, k, vals[k]) for k in others), {})
        lines[line][1][x] = gi
    return [label for _, label in sorted(xs.values())], list(lines.values())


def _pivot_lines(camp, sel, scale):
    """With two or more group keys: the mean of each group in a table whose
    rows are the first key's values and whose columns are the others' (per
    [compare] variant)."""
    if len(camp.group_by) < 2:
        return []
    rows, cols = _by_key(camp, camp.group_by[0])
    out = []
    for v in camp.variants or [None]:
        mean = {a["group"]: a["mean"] for a in sel if a["variant"] == v}
        out += [f"Mean over the runs of each group, by {camp.group_by[0]} (rows) and "
                f"{', '.join(camp.group_by[1:])} (columns)" + (f", {v}" if v else "") + ":", "",
                "| " + " | ".join([""] + [label for label, _ in cols]) + " |",
                "|" + "---|" * (len(cols) + 1)]
        for xi, row in enumerate(rows):
            out.append("| " + " | ".join([row] + [_g(mean.get(groups.get(xi)), scale)
                                                 for _, groups in cols]) + " |")
        out.append("")
    return out


def _by_key_plots(camp, pdir, result, rows, plt):
    """With two or more group keys: per metric, plots/<metric>_by_keys.png,
    the mean +- std of each group against the first group key (left) and the
    second (right), one line per value of the other keys."""
    written = []
    if len(camp.group_by) < 2:
        return written
    keys = camp.group_by[:2]
    vlabels = camp.variants or [None]
    for si, info in result["metrics"].items():
        m = info["metric"]
        vals_all = [r[2][m] for r in rows if m in r[2]]
        if m in GROUP_METRICS or not vals_all or not any(vals_all):
            continue
        unit, scale = _display_unit(m, vals_all)
        fig, axes = plt.subplots(1, 2, figsize=(12.0, 5.2), sharey=True)
        for ax, key in zip(axes, keys):
            xlabels, lines = _by_key(camp, key)
            n = len(lines) * len(vlabels)
            step = 0.3 / max(n - 1, 1)            # the lines side by side, each error bar visible
            k = 0
            for line_label, groups in lines:
                for v in vlabels:
                    agg = {a["group"]: a for a in result["aggregates"]
                           if a["metric"] == si and a["variant"] == v}
                    xs = [x for x in sorted(groups) if groups[x] in agg]
                    off = (k - (n - 1) / 2) * step if n > 1 else 0.0
                    ax.errorbar(np.array(xs, dtype=float) + off,
                                [agg[groups[x]]["mean"] / scale for x in xs],
                                yerr=[(agg[groups[x]]["std"] or 0.0) / scale for x in xs],
                                fmt="o-", ms=4, lw=1, capsize=3,
                                label=line_label + (f" [{v}]" if v else ""))
                    k += 1
            ax.set_xticks(np.arange(len(xlabels)), xlabels, fontsize=8)
            ax.set_xlabel(key, fontsize=9)
            ax.grid(alpha=0.3)
            ax.set_title(f"against {key}; a line per {', '.join(o for o in camp.group_by if o != key)}",
                         fontsize=9)
            if n > 1:
                ax.legend(fontsize=7, ncol=2 if n > 6 else 1)
        axes[0].set_ylabel(f"{m} [{unit}]")
        fig.suptitle(f"{camp.title}\n{info['meaning']}: mean +- std (ddof=1) per group", fontsize=9)
        fig.subplots_adjust(left=0.07, right=0.985, top=0.86, bottom=0.12, wspace=0.06)
        path = os.path.join(pdir, f"{m}_by_keys.png")
        fig.savefig(path, dpi=90)
        plt.close(fig)
        written.append(path)
    return written


def _margins(fig, labels, rot, wspace=0.06):
    """Margins from the length of the tick labels (tight_layout costs as much
    as drawing the figure twice): 8-pt text is about 6 px a character at 90 dpi."""
    w_px, h_px = fig.get_size_inches() * 90
    n = max((len(s) for s in labels), default=0) * 6.0
    bottom = (n * math.sin(math.radians(rot)) + 12 if rot else 14) + 30
    left = max(60.0, n * math.cos(math.radians(rot)) - 0.5 * (w_px / 2) / max(len(labels), 1)
               if rot else 60.0)
    fig.subplots_adjust(left=min(left / w_px, 0.3), right=0.985, top=0.86,
                        bottom=min(bottom / h_px, 0.5), wspace=wspace)


def _plots(camp, out_dir, result, rows):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    pdir = os.path.join(out_dir, "plots")
    os.makedirs(pdir, exist_ok=True)
    labels = [g["label"] for g in camp.groups]
    vlabels = camp.variants or [None]
    nv = len(vlabels)
    x = np.arange(len(labels))
    width = 0.8 / nv
    written = []
    rot = 30 if len(labels) > 4 or max((len(s) for s in labels), default=0) > 20 else 0
    fig_w = max(12.0, 3.0 + 0.9 * len(labels) * max(nv, 1) ** 0.5)
    for si, info in result["metrics"].items():
        m = info["metric"]
        if m in GROUP_METRICS:
            continue
        vals_all = [r[2][m] for r in rows if m in r[2]]
        if not vals_all or not any(vals_all):
            continue                                      # identically zero: nothing to show
        unit, scale = _display_unit(m, vals_all)
        fig, ax = plt.subplots(1, 2, figsize=(fig_w, 5.2), sharey=True)
        for k, v in enumerate(vlabels):
            off = (k - (nv - 1) / 2) * width
            agg = {a["group"]: a for a in result["aggregates"] if a["metric"] == si and a["variant"] == v}
            gx = [gi for gi in range(len(labels)) if gi in agg]
            mean = [agg[gi]["mean"] / scale for gi in gx]
            std = [(agg[gi]["std"] or 0.0) / scale for gi in gx]
            ax[0].errorbar(x[gx] + off, mean, yerr=std, fmt="o", capsize=4, label=v)
            data = [[r[2][m] / scale for r in rows if r[0].group == gi and r[1] == v and m in r[2]]
                    for gi in gx]
            color = f"C{k}"
            bp = ax[1].boxplot(data, positions=x[gx] + off, widths=width * 0.8, whis=(5, 95),
                               patch_artist=True, manage_ticks=False,
                               medianprops={"color": color if nv > 1 else "C1"})
            for patch in bp["boxes"]:
                patch.set_facecolor(color)
                patch.set_alpha(0.4)
        for a, t in zip(ax, ["mean +- std (ddof=1) per group",
                             "median, quartiles (box), 5th-95th percentiles (whiskers)"]):
            a.set_xticks(x, labels, rotation=rot, ha="right" if rot else "center", fontsize=8,
                         rotation_mode="anchor")
            a.set_title(t, fontsize=9)
            a.grid(alpha=0.3, axis="y")
        ax[0].set_ylabel(f"{m} [{unit}]")
        if nv > 1:
            ax[0].legend(fontsize=8)
        fig.suptitle(f"{camp.title}\n{info['meaning']}", fontsize=9)
        _margins(fig, labels, rot)
        path = os.path.join(pdir, f"{m}.png")
        fig.savefig(path, dpi=90)
        plt.close(fig)
        written.append(path)
    gm = result["group_metrics"]
    if gm:
        fig, ax = plt.subplots(1, 2, figsize=(fig_w, 5.2))
        for j, m in enumerate(GROUP_METRICS):
            unit, scale = _display_unit(m, [])
            for k, v in enumerate(vlabels):
                off = (k - (nv - 1) / 2) * width
                d = {a["group"]: a["value"] for a in gm if a["metric"] == si_name(m) and a["variant"] == v}
                gx = [gi for gi in range(len(labels)) if d.get(gi) is not None]
                ax[j].bar(x[gx] + off, [d[gi] / scale for gi in gx], width, label=v)
            for f in (result.get("paper") or {}).get("figures", []):
                if f["metric"] == m:
                    ax[j].axhline(f["value_si"] / scale, color="k", ls="--", lw=1,
                                  label=f"paper {f['relation']} {f['value']:g} {f['unit']}")
            ax[j].set_xticks(x, labels, rotation=rot, ha="right" if rot else "center", fontsize=8,
                             rotation_mode="anchor")
            ax[j].set_ylabel(f"{m} [{unit}]")
            ax[j].grid(alpha=0.3, axis="y")
            if ax[j].get_legend_handles_labels()[1]:
                ax[j].legend(fontsize=8)
        fig.suptitle(f"{camp.title}\nstd over the runs of each group", fontsize=9)
        _margins(fig, labels, rot, wspace=0.25)
        path = os.path.join(pdir, "group_std.png")
        fig.savefig(path, dpi=90)
        plt.close(fig)
        written.append(path)
    written += _by_key_plots(camp, pdir, result, rows, plt)
    return written
