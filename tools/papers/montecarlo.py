#!/usr/bin/env python3
"""Monte Carlo over the papers' random constants (docs/campaigns.md, "Campaign
files": random constants): seeds 002 and 003.

    .venv/bin/python tools/papers/montecarlo.py [seed002] [seed003] [--draws 100] [--block 10]
        [--out runs/montecarlo] [--workers 2] [--scheduler tcp://HOST:8786] [--report docs/results]
    .venv/bin/python tools/papers/montecarlo.py --report-only        # the report from what is on disk
    .venv/bin/python tools/papers/montecarlo.py --dask-identity      # local pool vs Dask LocalCluster

The campaigns are the built-ins seed002_montecarlo (4 schemes x 2 heading
swings, 72 h) and seed003_montecarlo (no rotation vs single-position, 24 h):
each seeds entry d is one draw of every random constant of the paper's
sensor table, N(0, sigma^2) per term with sigma its stated 1-sigma value
(`pyins.sim.sensors.random_constant_overrides`), and the ARW/VRW noise
seed d. Every scheme runs with the same draw (paired).

The draws run in blocks (draws 0..9, then 0..19, ...), each block a
campaign on the engine (`pyins.campaign.run_campaign`, local pool or Dask):
the runs are content addressed, so an interrupted command continues where it
stopped when it is run again, and a stopped one leaves every scheme with the
same draws but the last block. ``OUT/<seed>/timing.json`` accumulates the
wall time and the runs computed by every invocation (runs/s).

The report (``--report DIR``, default docs/results): montecarlo.md's tables
(per scheme and experiment: median, 5-95 % interval, the paper's figure and
its percentile among the draws; P(flexible beats traditional), paired, with
its 90 % Clopper-Pearson interval), the histograms with the paper's figure
marked (montecarlo_seed002.png, montecarlo_seed003.png) and montecarlo.json.
"""
import argparse
import dataclasses
import json
import math
import os
import sys
import time

import numpy as np

from pyins import campaign, scenario
from pyins.units import NMI_TO_M

CAMPAIGNS = {"seed002": "seed002_montecarlo", "seed003": "seed003_montecarlo"}
#: seed 002's experiments: motion.period -> the scenario holding that experiment's [paper]
SEED002_EXPERIMENTS = {"120 s": ("exp. 1", "seed002_exp1"), "60 s": ("exp. 2", "seed002_exp2")}
#: the paired comparisons: (seed, better, worse) schemes
PAIRS = {"seed002": [("flexible", "two_position"), ("flexible_derived", "two_position"),
                     ("two_position", "none"), ("flexible", "none")],
         "seed003": [("single_position", "none")]}
#: the metrics reported, and the unit each is shown in
METRICS = {"seed002": [("horizontal_error_final", "nmi", NMI_TO_M), ("horizontal_error_max", "nmi", NMI_TO_M)],
           "seed003": [("horizontal_error_max", "nmi", NMI_TO_M),
                       ("level_error_max", "arcmin", math.pi / 180 / 60),
                       ("heading_error_max", "arcmin", math.pi / 180 / 60),
                       ("velocity_error_max", "m/s", 1.0)]}


# ---------------------------------------------------------------------------
# 1. The campaigns, in blocks of draws
# ---------------------------------------------------------------------------
def first_draws(camp, n, schemes=None):
    """``camp`` restricted to its first ``n`` draws (seeds entries) and to
    ``schemes`` (indexing.scheme values; None: all), the points renumbered.
    A point's digest does not depend on the others, so the runs are shared
    with the whole campaign."""
    keep = set(camp.seeds[:n])
    pts = [p for p in camp.points if p.run in keep
           and (schemes is None or p.values["indexing.scheme"] in schemes)]
    pts = [dataclasses.replace(p, index=i) for i, p in enumerate(pts)]
    return dataclasses.replace(camp, seeds=list(camp.seeds[:n]), points=pts)


def _timing_path(out):
    return os.path.join(out, "timing.json")


def read_timing(out):
    try:
        with open(_timing_path(out)) as f:
            return json.load(f)
    except (OSError, ValueError):
        return {"sessions": []}


def _add_session(out, session):
    t = read_timing(out)
    t["sessions"].append(session)
    t["computed"] = sum(s["computed"] for s in t["sessions"])
    t["wall_s"] = sum(s["wall_s"] for s in t["sessions"])
    t["run_s"] = sum(s["run_s"] for s in t["sessions"])
    with open(_timing_path(out) + ".tmp", "w") as f:
        json.dump(t, f, indent=2)
    os.replace(_timing_path(out) + ".tmp", _timing_path(out))


def run_seed(key, draws, block, out, workers=None, scheduler=None, quiet=False, schemes=None):
    """Run campaign ``key`` (seed002 / seed003) for its first ``draws`` draws in blocks."""
    camp = campaign.load_campaign(CAMPAIGNS[key])
    draws = min(draws, len(camp.seeds))
    os.makedirs(out, exist_ok=True)
    t0 = time.perf_counter()
    session = {"started": time.strftime("%Y-%m-%d %H:%M:%S"), "draws": draws, "computed": 0,
               "run_s": 0.0, "scheduler": scheduler or f"local pool, {workers or os.cpu_count()} workers"}
    run_times = []

    def log(line):
        # "  <label>: 5.23 s" per computed run (execute.py's format)
        if line.rstrip().endswith(" s") and "FAILED" not in line:
            try:
                run_times.append(float(line.rstrip()[:-2].rsplit(":", 1)[1]))
            except (ValueError, IndexError):
                pass
        if not quiet:
            print(line, flush=True)

    try:
        n = 0
        while n < draws:
            n = min(draws, n + block)
            sub = first_draws(camp, n, schemes)
            todo, total = campaign.pending(sub, out)
            if not todo:
                continue
            tb = time.perf_counter()
            res = campaign.run_campaign(sub, out, workers=workers, scheduler=scheduler, log=log,
                                        plots=False)
            ex = res["execution"]
            session["computed"] += ex["computed"]
            if not quiet:
                print(f"{key}: draws 0..{n - 1}: {ex['computed']} runs in {time.perf_counter() - tb:.0f} s "
                      f"({total} in all)", flush=True)
    finally:
        session["wall_s"] = time.perf_counter() - t0
        session["run_s"] = float(sum(run_times))
        session["runs_timed"] = len(run_times)
        _add_session(out, session)
    # the whole campaign's aggregates and plots over the draws run so far
    final = first_draws(camp, draws, schemes)
    return campaign.run_campaign(final, out, workers=workers, scheduler=scheduler, plots=True)


# ---------------------------------------------------------------------------
# 2. The statistics
# ---------------------------------------------------------------------------
def clopper_pearson(k, n, level=0.90):
    """Exact binomial interval of k successes in n at ``level``."""
    from scipy.stats import beta
    a = (1.0 - level) / 2.0
    lo = 0.0 if k == 0 else float(beta.ppf(a, k, n - k + 1))
    hi = 1.0 if k == n else float(beta.ppf(1.0 - a, k + 1, n - k))
    return lo, hi


def percentile_of(values, x):
    """Where ``x`` falls among ``values`` [%]: the share below it plus half the ties."""
    v = np.asarray(values, dtype=float)
    return 100.0 * (np.sum(v < x) + 0.5 * np.sum(v == x)) / v.size


def per_draw(result, metric):
    """{group values as (scheme, period or None): {draw: value in SI}} of complete draws."""
    out = {}
    for p in result["points"]:
        m = p.get("metrics")
        if not m:
            continue
        v = m[""].get(f"{metric}_{_si_suffix(metric)}")
        key = (p["values"]["indexing.scheme"], p["values"].get("motion.period"))
        out.setdefault(key, {})[p["run"]] = v
    return out


def _si_suffix(metric):
    from pyins.metrics import si_name
    return si_name(metric)[len(metric) + 1:]


def paper_figures(key):
    """{(scheme, period or None): {metric: figure}} of the papers' printed figures."""
    out = {}
    if key == "seed002":
        sources = [(period, name) for period, (_, name) in SEED002_EXPERIMENTS.items()]
    else:
        sources = [(None, "seed003")]
    for period, name in sources:
        sc = scenario.load(name)
        lab = dict(zip(sc.resolved()["compare"]["labels"], sc.resolved()["compare"]["values"]))
        for f in sc.paper.get("figures", []):
            out.setdefault((lab[f["variant"]], period), {})[f["metric"]] = f
    return out


def _figure(papers, scheme, period, metric):
    """The paper's figure for ``metric``; seed 002 prints one figure per scheme
    without saying whether it is the final or the maximum error: it is placed
    in both distributions."""
    figs = papers.get((scheme, period), {})
    if metric in figs:
        return figs[metric]
    if metric == "horizontal_error_max":
        return figs.get("horizontal_error_final")
    return None


def up_gyro_dph(key, draw):
    """The drawn up-gyro (z) drift of ``draw`` [deg/h]."""
    from pyins.sim import sensors
    return float(sensors.random_constant_values(key, draw)["gyro_bias"][0][2])


def statistics(key, result):
    """The tables of the report, in data form."""
    labels = {"indexing.scheme": dict(zip(*[result["campaign"]["grid"]["indexing.scheme"],
                                            result["campaign"]["labels"]["indexing.scheme"]]))}
    papers = paper_figures(key)
    rows, pairs = [], []
    complete_draws = None
    for metric, unit, scale in METRICS[key]:
        data = per_draw(result, metric)
        draws = set.intersection(*(set(d) for d in data.values())) if data else set()
        complete_draws = draws if complete_draws is None else complete_draws & draws
        for (scheme, period), d in data.items():
            mine = sorted(d)                 # every complete draw of this group
            v = np.array([d[r] for r in mine]) / scale
            if v.size == 0:
                continue
            fig = _figure(papers, scheme, period, metric)
            p5, p50, p95 = np.percentile(v, [5, 50, 95])
            row = {"scheme": scheme, "label": labels["indexing.scheme"][scheme], "period": period,
                   "experiment": SEED002_EXPERIMENTS[period][0] if period else "",
                   "metric": metric, "unit": unit, "n": int(v.size), "median": float(p50),
                   "p5": float(p5), "p95": float(p95), "min": float(v.min()), "max": float(v.max())}
            if fig is not None:
                x = fig["value_si"] / scale
                row.update(paper=float(x), relation=fig["relation"], paper_percentile=percentile_of(v, x))
                # the up-gyro drift of the draws below the paper's figure, against all draws'
                eps = np.abs([up_gyro_dph(key, r) for r in mine])
                row.update(eps_u_all_dph=float(np.median(eps)),
                           eps_u_below_dph=float(np.median(eps[v < x])) if np.any(v < x) else None)
            if v.size > 2:        # how much the up-gyro drift alone orders the draws
                from scipy.stats import spearmanr
                eps_all = np.abs([up_gyro_dph(key, r) for r in mine])
                row["spearman_abs_eps_u"] = float(spearmanr(eps_all, v)[0])
            rows.append(row)
        for better, worse in PAIRS[key]:
            for period in sorted({k[1] for k in data}, key=lambda p: (p is None, p)):
                a, b = data.get((better, period)), data.get((worse, period))
                if not a or not b:
                    continue
                common = sorted(set(a) & set(b))
                wins = sum(a[r] < b[r] for r in common)
                lo, hi = clopper_pearson(wins, len(common)) if common else (float("nan"),) * 2
                ratio = np.array([a[r] / b[r] for r in common])
                pairs.append({"metric": metric, "period": period,
                              "experiment": SEED002_EXPERIMENTS[period][0] if period else "",
                              "better": better, "worse": worse, "n": len(common), "wins": int(wins),
                              "p": wins / len(common) if common else float("nan"), "ci90": [lo, hi],
                              "median_ratio": float(np.median(ratio)) if common else float("nan")})
    return {"rows": rows, "pairs": pairs, "draws": len(complete_draws or ()),
            "draws_max": max((r["n"] for r in rows), default=0),
            "labels": labels["indexing.scheme"]}


# ---------------------------------------------------------------------------
# 3. The figures and the report
# ---------------------------------------------------------------------------
def histograms(key, result, stats, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    metric, unit, scale = METRICS[key][0]
    papers = paper_figures(key)
    data = per_draw(result, metric)
    periods = [p for p in (*SEED002_EXPERIMENTS, None) if any(k[1] == p for k in data)]   # exp. 1 on top
    schemes = [s for s in result["campaign"]["grid"]["indexing.scheme"] if any(k[0] == s for k in data)]
    fig, axes = plt.subplots(len(periods), len(schemes), figsize=(3.2 * len(schemes), 2.8 * len(periods)),
                             squeeze=False)
    for i, period in enumerate(periods):
        for j, scheme in enumerate(schemes):
            ax = axes[i, j]
            d = data.get((scheme, period), {})
            v = np.array(list(d.values())) / scale
            if v.size:
                ax.hist(v, bins=20, color="0.6", edgecolor="0.3")
                ax.axvline(np.median(v), color="k", lw=1, label=f"median {np.median(v):.2f}")
            f = _figure(papers, scheme, period, metric)
            if f is not None:
                x = f["value_si"] / scale
                pct = percentile_of(v, x) if v.size else float("nan")
                ax.axvline(x, color="r", lw=2, ls="--",
                           label=f"paper {f['relation'] if f['relation'] != '=' else ''}{x:g} ({pct:.0f}th pct)")
            title = stats["labels"][scheme]
            if period:
                title = f"{SEED002_EXPERIMENTS[period][0]}: {title}"
            ax.set_title(title, fontsize=9)
            ax.set_xlabel(f"{metric.replace('_', ' ')} [{unit}]", fontsize=8)
            ax.legend(fontsize=7)
    fig.suptitle(f"{key}: draws of the random constants (up to {stats['draws_max']} per scheme)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def _fmt_rows(rows, key):
    out = []
    if key == "seed002":
        out.append("| experiment | scheme | metric | draws | median | 5-95 % | paper | paper's percentile | "
                   "median abs(eps_U) below the paper's figure (deg/h) |")
        out.append("|---|---|---|---|---|---|---|---|---|")
    else:
        out.append("| scheme | metric | draws | median | 5-95 % | paper | paper's percentile | "
                   "median abs(eps_U) below the paper's figure (deg/h) |")
        out.append("|---|---|---|---|---|---|---|---|")
    for r in rows:
        paper = (f"{'' if r.get('relation') in (None, '=') else r['relation'] + ' '}{r['paper']:g}"
                 if "paper" in r else "")
        pct = f"{r['paper_percentile']:.0f}" if "paper" in r else ""
        cells = [r["label"], r["metric"].replace("_", " "), str(r["n"]),
                 f"{r['median']:.3g} {r['unit']}", f"{r['p5']:.3g} - {r['p95']:.3g}", paper, pct,
                 "" if r.get("eps_u_below_dph") is None else
                 f"{r['eps_u_below_dph']:.4f} (all draws {r['eps_u_all_dph']:.4f})"]
        if key == "seed002":
            cells.insert(0, r["experiment"])
        out.append("| " + " | ".join(cells) + " |")
    return out


def _fmt_pairs(pairs, labels):
    out = ["| experiment | metric | comparison | draws | P(first smaller) | 90 % interval | median ratio |",
           "|---|---|---|---|---|---|---|"]
    for p in pairs:
        out.append(f"| {p['experiment']} | {p['metric'].replace('_', ' ')} | {labels[p['better']]} < "
                   f"{labels[p['worse']]} | {p['n']} | {p['p']:.2f} ({p['wins']}/{p['n']}) | "
                   f"{p['ci90'][0]:.2f} - {p['ci90'][1]:.2f} | {p['median_ratio']:.2f} |")
    return out


def timing_line(key, out, runs_timing=None):
    if runs_timing and runs_timing["complete"]:
        r = runs_timing
        return (f"{key}: {r['complete']} runs complete; from the first run's start to the last run's end "
                f"{r['span_s'] / 60:.1f} min ({r['complete'] / r['span_s']:.3f} runs/s, pauses between "
                f"sessions included); {r['run_s'] / r['complete']:.2f} s per run in a worker")
    t = read_timing(out)
    if not t.get("computed"):
        return f"{key}: no runs computed yet"
    rps = t["computed"] / t["wall_s"] if t["wall_s"] else float("nan")
    per = t["run_s"] / t["computed"] if t["computed"] else float("nan")
    return (f"{key}: {t['computed']} runs computed in {t['wall_s'] / 60:.1f} min of wall time over "
            f"{len(t['sessions'])} session(s): {rps:.3f} runs/s; {per:.2f} s per run in a worker")


def collect(camp, out):
    """campaign.json's points (values, run, metrics in SI) read from the run
    directories of ``out`` directly: every complete run of the whole campaign,
    whatever block or session made it (campaign.json holds only the last block,
    and no metrics while a block runs)."""
    from pyins.campaign.aggregate import read_summary
    from pyins.metrics import si_name
    points, run_s, first, last = [], [], [], []
    for p in camp.points:
        s = read_summary(os.path.join(out, p.dir))
        ok = s is not None and s.get("complete") is True and s.get("digest") == p.digest
        metrics = {"": {si_name(k): x for k, x in s["variants"][0]["metrics"].items()}} if ok else None
        points.append({"index": p.index, "values": p.values, "run": p.run, "seed": p.seed,
                       "digest": p.digest, "metrics": metrics})
        if ok:
            run_s.append(s["variants"][0].get("wall_s") or 0.0)
            first.append(os.path.getmtime(os.path.join(out, p.dir, "point.json")))
            last.append(os.path.getmtime(os.path.join(out, p.dir, "summary.json")))
    span = (max(last) - min(first)) if last else 0.0
    return {"campaign": camp.describe(), "points": points,
            "runs_timing": {"complete": len(run_s), "run_s": float(sum(run_s)), "span_s": span}}


def report(keys, out_root, report_dir):
    """Write montecarlo.json and the histograms into ``report_dir``; returns the tables as Markdown."""
    os.makedirs(report_dir, exist_ok=True)
    blob, md = {}, []
    for key in keys:
        out = os.path.join(out_root, key)
        result = collect(campaign.load_campaign(CAMPAIGNS[key]), out)
        if not any(p["metrics"] for p in result["points"]):
            md.append(f"{key}: no complete run in {out}")
            continue
        stats = statistics(key, result)
        histograms(key, result, stats, os.path.join(report_dir, f"montecarlo_{key}.png"))
        blob[key] = dict(stats, timing=read_timing(out), runs_timing=result["runs_timing"],
                         campaign=CAMPAIGNS[key], campaign_digest=result["campaign"]["digest"])
        md += [f"### {key}: {stats['draws_max']} draws (every group: {stats['draws']})", "",
               *_fmt_rows(stats["rows"], key), "", *_fmt_pairs(stats["pairs"], stats["labels"]), "",
               timing_line(key, out, result["runs_timing"]), ""]
    with open(os.path.join(report_dir, "montecarlo.json"), "w") as f:
        json.dump(blob, f, indent=1, allow_nan=True)
    text = "\n".join(md)
    _fill_markdown(os.path.join(report_dir, "montecarlo.md"), keys, text)
    return text


def _fill_markdown(path, keys, text):
    """Put the tables between montecarlo.md's markers (its prose is written by hand)."""
    begin, end = "<!-- montecarlo tables: begin (tools/papers/montecarlo.py writes this part) -->", \
        "<!-- montecarlo tables: end -->"
    if sorted(keys) != sorted(CAMPAIGNS) or not os.path.exists(path):
        return
    with open(path, encoding="utf-8") as f:
        doc = f.read()
    if begin not in doc or end not in doc:
        return
    head, rest = doc.split(begin, 1)
    tail = rest.split(end, 1)[1]
    with open(path, "w", encoding="utf-8") as f:
        f.write(f"{head}{begin}\n\n{text}\n{end}{tail}")


# ---------------------------------------------------------------------------
# 4. Dask identity: the same small campaign locally and on a Dask LocalCluster
# ---------------------------------------------------------------------------
def small_campaign(draws=3, hours=1):
    """seed002_montecarlo cut to ``draws`` draws, 2 schemes, exp. 1, ``hours`` h."""
    return campaign.from_args("seed002_exp1", {"indexing.scheme": ["two_position", "flexible"]},
                              seeds=draws, compare="drop", random_constants="seed002",
                              overrides={"duration": f"{hours} h", "record_every": "60 s",
                                         "outputs.plots": False, "outputs.csv": False},
                              name="montecarlo_dask_identity")


def comparable(result):
    """campaign.json without what may differ between executions (``execution``)."""
    return {k: v for k, v in result.items() if k != "execution"}


def dask_identity(out, draws=3, hours=1, workers=2, processes=True, camp=None, local_runs=None):
    """Run `small_campaign` (or ``camp``) locally and on a LocalCluster; returns
    (same?, local, dask, seconds). ``local_runs``: an existing runs/ directory
    the local side reads (linked, so what is complete there is not rerun)."""
    from distributed import LocalCluster
    camp = camp or small_campaign(draws, hours)
    if local_runs:
        os.makedirs(os.path.join(out, "local"), exist_ok=True)
        link = os.path.join(out, "local", "runs")
        if not os.path.exists(link):
            os.symlink(os.path.abspath(local_runs), link)
    t0 = time.perf_counter()
    local = campaign.run_campaign(camp, os.path.join(out, "local"), workers=workers, plots=False)
    t1 = time.perf_counter()
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=processes,
                      dashboard_address=None) as cluster:
        dask = campaign.run_campaign(camp, os.path.join(out, "dask"), scheduler=cluster.scheduler_address,
                                     plots=False)
    t2 = time.perf_counter()
    same = json.dumps(comparable(local), sort_keys=True) == json.dumps(comparable(dask), sort_keys=True)
    return same, local, dask, (t1 - t0, t2 - t1)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("seeds", nargs="*", help="seed002, seed003 (default both)")
    ap.add_argument("--draws", type=int, default=100)
    ap.add_argument("--block", type=int, default=10, help="draws per block (default 10)")
    ap.add_argument("--out", default="runs/montecarlo")
    ap.add_argument("--workers", type=int, default=None)
    ap.add_argument("--scheduler", default=None, help="a Dask scheduler address instead of the local pool")
    ap.add_argument("--report", default="docs/results", help="where the report's figures and JSON go")
    ap.add_argument("--schemes", default=None,
                    help="only these indexing.scheme values, comma separated (default: the campaign's)")
    ap.add_argument("--report-only", action="store_true")
    ap.add_argument("--dask-identity", action="store_true",
                    help="3 draws x 2 schemes x 1 h locally and on a Dask LocalCluster; with --dask-draws N "
                         "the first N draws of seed003_montecarlo on Dask against the local runs in --out")
    ap.add_argument("--dask-draws", type=int, default=0)
    ap.add_argument("--quiet", action="store_true")
    a = ap.parse_args(argv)
    keys = a.seeds or list(CAMPAIGNS)
    for key in keys:
        if key not in CAMPAIGNS:
            ap.error(f"unknown {key!r}: choose from {', '.join(CAMPAIGNS)}")
    if a.dask_identity:
        if a.dask_draws:
            camp = first_draws(campaign.load_campaign(CAMPAIGNS["seed003"]), a.dask_draws)
            same, local, dask, (tl, td) = dask_identity(
                os.path.join(a.out, f"dask_identity_seed003_{a.dask_draws}"), camp=camp,
                local_runs=os.path.join(a.out, "seed003", "runs"))
        else:
            same, local, dask, (tl, td) = dask_identity(os.path.join(a.out, "dask_identity"))
        print(f"local pool {local['execution']['computed']} runs computed "
              f"({local['execution']['skipped']} found complete) in {tl:.1f} s "
              f"({local['execution']['scheduler']}); Dask {dask['execution']['computed']} runs in "
              f"{td:.1f} s ({dask['execution']['scheduler']})")
        print("campaign.json without 'execution':", "IDENTICAL" if same else "DIFFERENT")
        return 0 if same else 1
    if not a.report_only:
        for key in keys:
            camp_schemes = campaign.load_campaign(CAMPAIGNS[key]).grid["indexing.scheme"]
            schemes = [s for s in a.schemes.split(",") if s in camp_schemes] if a.schemes else None
            run_seed(key, a.draws, a.block, os.path.join(a.out, key), a.workers, a.scheduler, a.quiet,
                     schemes)
    print(report(keys, a.out, a.report))
    return 0


if __name__ == "__main__":
    sys.exit(main())
