"""A campaign's results: the statistics over its runs, in data form, and the files.

Aggregation reads the runs' summary.json files in point order (never the
order they finished in), so the aggregates of a campaign are the same bit
for bit whether it ran locally, on Dask, or in several interrupted pieces.
Per group and metric (and per [compare] variant when the base keeps its
[compare]): count, mean, std (ddof=1), min, p5, p50, p95, max (`STATS`);
per group also the group metrics of `pyins.metrics` (seed 000's level and
heading error std over the runs).

`aggregate`:
1. every run's summary.json, in point order (what is missing is listed);
2. per group (and variant): the statistics of each metric, and the group
   metrics;
3. the metrics present, with their dimension, meaning and display unit
   (`pyins.metrics`);
4. written: campaign.json (SI, units in the metric names), aggregate.csv
   (SI), runs.csv (every run's metrics, SI), and, by `pyins.report.campaign`,
   aggregate.md and plots/ (the papers' units: arcsec, arcmin, m or nmi).
"""
import csv
import io
import json
import math
import os

import numpy as np

from pyins.campaign.grid import show
from pyins.metrics import GROUP_METRICS, NAMES, describe, dimension, display, group_metrics, si_name
from pyins.records import write_atomic
from pyins.report import campaign as campaign_report

__all__ = ["aggregate", "plan", "metric_order", "read_summary", "write_json", "STATS",
           "SCHEMA_VERSION"]

SCHEMA_VERSION = 1                                  #: of campaign.json
STATS = ("count", "mean", "std", "min", "p5", "p50", "p95", "max")


def read_summary(run_dir):
    """The summary.json of a run directory, or None (none yet, or unreadable)."""
    try:
        with open(os.path.join(run_dir, "summary.json")) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def write_json(path, obj):
    """``obj`` as JSON into ``path``, atomically (a kill leaves the old file or the new)."""
    write_atomic(path, json.dumps(obj, indent=2, allow_nan=False) + "\n", sync=False)


def plan(camp):
    """What campaign.json holds before any run: the campaign, its groups and points."""
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


def metric_order(names):
    """``names`` in the order of `pyins.metrics.TABLE` (unknown ones last, by name)."""
    return sorted(names, key=lambda m: (NAMES.index(m) if m in NAMES else len(NAMES), m))


def aggregate(camp, out_dir, plots=True):
    """Read every run's summary.json in point order and write campaign.json,
    aggregate.csv, aggregate.md, runs.csv and plots/ (what is missing is
    left out and listed); returns the campaign.json dict (without
    ``execution``, which run_campaign adds)."""
    # 1. every run's summary.json, in point order
    out = plan(camp)
    variants = camp.variants
    rows = []                   # (point, variant label or None, {metric: value})
    missing, versions = [], set()
    summaries = {}
    for p, pj in zip(camp.points, out["points"]):
        s = summaries.get(p.digest)
        if s is None:
            s = read_summary(os.path.join(out_dir, p.dir))
            summaries[p.digest] = s
        if s is None or s.get("digest") != p.digest or s.get("complete") is not True:
            missing.append(p.index)
            pj["metrics"] = None
            continue
        versions.add(s.get("core_version"))
        pj["metrics"] = {}
        for v in s["variants"]:
            label = v["label"] if variants else None
            m = {k: v["metrics"][k] for k in metric_order(v["metrics"])}
            pj["metrics"][label or ""] = {si_name(k): x for k, x in m.items()}
            rows.append((p, label, m, v))
    # 2. per group (and [compare] variant): the statistics of each metric, and the group metrics
    vlabels = variants or [None]
    aggregates, group_rows = [], []
    for gi in range(len(camp.groups)):
        for label in vlabels:
            sel = [r for r in rows if r[0].group == gi and r[1] == label]
            names = metric_order({k for r in sel for k in r[2]})
            for metric in names:
                vals = [r[2][metric] for r in sel if metric in r[2]]
                aggregates.append({"group": gi, "variant": label, "metric": si_name(metric),
                                   **_stats(vals)})
            gm = group_metrics([r[3] for r in sel])
            for metric in GROUP_METRICS:
                if metric in gm:
                    group_rows.append({"group": gi, "variant": label, "metric": si_name(metric),
                                          "count": len(sel), "value": _num(gm[metric])})
    # 3. the metrics present, with their dimension, meaning and display unit
    present = metric_order({k for r in rows for k in r[2]}
                           | {m for m in GROUP_METRICS if any(g["metric"] == si_name(m) for g in group_rows)})
    metrics = {}
    for m in present:
        dim, meaning = dimension(m), describe(m)
        unit, _ = display(m, [r[2].get(m, 0.0) for r in rows])
        metrics[si_name(m)] = {"metric": m, "dimension": dim, "meaning": meaning, "shown_in": unit}
    result = dict(out)
    result.update(complete=not missing, missing_points=missing, stats=list(STATS),
                  metrics=metrics, aggregates=aggregates, group_metrics=group_rows,
                  paper=camp.base.paper, core_versions=sorted(v for v in versions if v))
    # 4. written: campaign.json, the CSVs, the Markdown and the plots
    write_json(os.path.join(out_dir, "campaign.json"), result)
    _write_csv(camp, out_dir, result)
    _write_runs_csv(camp, out_dir, result)
    write_atomic(os.path.join(out_dir, "aggregate.md"), campaign_report.markdown(camp, result, rows), sync=False)
    if plots:
        campaign_report.plots(camp, out_dir, result, rows)
    return result


def _fmt(x):
    return "" if x is None else repr(float(x))


def _write_csv(camp, out_dir, result):
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["group", *camp.group_by, "variant", "metric", *STATS, "value"])
    for a in result["aggregates"]:
        g = camp.groups[a["group"]]["values"]
        w.writerow([a["group"], *(show(g[k]) for k in camp.group_by), a["variant"] or "", a["metric"],
                    a["count"], *(_fmt(a[s]) for s in STATS[1:]), ""])
    for a in result["group_metrics"]:
        g = camp.groups[a["group"]]["values"]
        w.writerow([a["group"], *(show(g[k]) for k in camp.group_by), a["variant"] or "", a["metric"],
                    a["count"], *([""] * (len(STATS) - 1)), _fmt(a["value"])])
    write_atomic(os.path.join(out_dir, "aggregate.csv"), buf.getvalue(), sync=False)


def _write_runs_csv(camp, out_dir, result):
    names = [si for si, info in result["metrics"].items() if info["metric"] not in GROUP_METRICS]
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["point", *camp.grid, "run", "seed", "group", "variant", "digest", *names])
    for p in result["points"]:
        for label, m in (p["metrics"] or {}).items():
            w.writerow([p["index"], *(show(p["values"][k]) for k in camp.grid),
                        "" if p["run"] is None else p["run"], "" if p["seed"] is None else p["seed"],
                        p["group"], label, p["digest"][:16], *(_fmt(m.get(n)) for n in names)])
    write_atomic(os.path.join(out_dir, "runs.csv"), buf.getvalue(), sync=False)

