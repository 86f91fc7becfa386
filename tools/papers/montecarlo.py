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

from pyins import campaign, records, scenario
from pyins.units import NMI_TO_M

CAMPAIGNS = {"seed002": "seed002_montecarlo", "seed003": "seed003_montecarlo"}
#: seed 002's Table 1 heading (15 deg) and heading error (1'), read two ways (docs/papers.md,
#: seed 002 §7; docs/results/seed002.md, "Table 1's heading: two readings"): "ccw" is PSINS's
#: yaw, positive north-west (yaw +15 deg, yaw error +1'), the reading the project adopts;
#: "clockwise" a marine heading (yaw -15 deg, yaw error -1'), the built-in scenarios' and the
#: reading of this report before 2026-12-06. name -> the campaign's extra fixed overrides.
CONVENTIONS = {"ccw": {"motion.yaw": "15 deg", "initial_errors.yaw": "60 arcsec"},
               "clockwise": {}}
#: the reading the seed 002 campaign runs under (--convention)
CONVENTION = {"name": "ccw"}
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
def load(key):
    """The campaign of ``key``; seed 002's with Table 1's heading read as CONVENTION says
    (its fixed overrides added to the built-in's [campaign.set])."""
    extra = CONVENTIONS[CONVENTION["name"]] if key == "seed002" else {}
    if not extra:
        return campaign.load_campaign(CAMPAIGNS[key])
    from pyins.campaign import spec as cspec
    path = cspec.builtin_path(CAMPAIGNS[key])
    text = path.read_text(encoding="utf-8")
    lines = "".join(f'"{k}" = "{v}"\n' for k, v in extra.items())
    assert text.count("[campaign.set]\n") == 1
    text = text.replace("[campaign.set]\n", "[campaign.set]\n" + lines)
    return cspec.loads_campaign(text, source=str(path), name=path.stem, relative_to=path)


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
    camp = load(key)
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


# ---------------------------------------------------------------------------
# 3b. Per draw: the error vectors, the draw nearest the paper, the scheme's own error
# ---------------------------------------------------------------------------
#: the paper's three schemes (its figures), in its order
PAPER_SCHEMES = ("none", "two_position", "flexible")


def draw_vectors(camp, out):
    """{draw: {"scheme|period": [north, east, max horizontal] (nmi)}} at the run's end, read
    from each complete run's timeseries.npz (the records every 60 s)."""
    import glob
    from pyins.campaign.aggregate import read_summary
    vec = {}
    for p in camp.points:
        s = read_summary(os.path.join(out, p.dir))
        if s is None or s.get("complete") is not True or s.get("digest") != p.digest:
            continue
        (f,) = glob.glob(os.path.join(out, p.dir, "*", "timeseries.npz"))
        z = np.load(f)
        vec.setdefault(int(p.run), {})[f"{p.values['indexing.scheme']}|{p.values['motion.period']}"] = [
            float(z["north_m"][-1] / NMI_TO_M), float(z["east_m"][-1] / NMI_TO_M),
            float(z["horizontal_m"].max() / NMI_TO_M)]
    return {d: vec[d] for d in sorted(vec)}


def up_gyro_response(convention):
    """The final (north, east) error [nmi] of +0.003 deg/h on the up gyro alone (no other
    error, no noise, no initial error; no rotation: a vertical-axis table does not change it,
    docs/results/seed002.md), per experiment period, under ``convention``. Two 72-h runs."""
    from pyins import metrics, run_scenario
    out = {}
    for period, (_, name) in SEED002_EXPERIMENTS.items():
        sc = scenario.load(name).with_overrides({**CONVENTIONS[convention], "compare": None, "paper": None,
                                                "indexing.scheme": "none", "initial_errors": None,
                                                "sensors": {"gyro_bias": [0, 0, "0.003 deg/h"]}})
        (spec,) = sc.runs()
        e = metrics.nav_errors(run_scenario.run(spec))
        out[period] = [float(e.north_m[-1] / NMI_TO_M), float(e.east_m[-1] / NMI_TO_M)]
    return out


def paper_set_finals(convention):
    """The paper's own set (the seed002 preset: every term +its value, as PSINS builds it),
    noise seed 1, Table 1's initial errors, 72 h: the final horizontal error [nmi] of the
    paper's three schemes in both experiments, in PAPER_SCHEMES order per experiment (the
    Table 2 rows of tools/papers/reproduce_seed002.py --conventions). Six 72-h runs."""
    from pyins import metrics, run_scenario
    out = []
    for period, (_, name) in SEED002_EXPERIMENTS.items():
        for scheme in PAPER_SCHEMES:
            sc = scenario.load(name).with_overrides({**CONVENTIONS[convention], "compare": None,
                                                    "paper": None, "indexing.scheme": scheme})
            (spec,) = sc.runs()
            out.append(float(metrics.nav_errors(run_scenario.run(spec)).horizontal_m[-1] / NMI_TO_M))
    return out


def joint(vec, papers, up_response, paper_set=None):
    """What the draws say about the paper's six figures at once and about the schemes
    beyond the floor they share (docs/results/montecarlo.md, "The paper's six figures at
    once" and "Beside the shared up-gyro floor")."""
    keys = [f"{s}|{p}" for p in SEED002_EXPERIMENTS for s in PAPER_SCHEMES]
    paper = np.array([papers[(s, p)]["horizontal_error_final"]["value_si"] / NMI_TO_M
                      for p in SEED002_EXPERIMENTS for s in PAPER_SCHEMES])
    full = [d for d in vec if all(k in vec[d] for k in keys)]
    fin = np.array([[math.hypot(*vec[d][k][:2]) for k in keys] for d in full])
    rms = np.sqrt(np.mean((fin - paper) ** 2, axis=1))
    i = int(np.argmin(rms))
    res = {"draws": len(full), "paper_final_nmi": paper.tolist(),
           "nearest": {"draw": int(full[i]), "rms_nmi": float(rms[i]),
                       "max_abs_nmi": float(np.max(np.abs(fin[i] - paper))), "final_nmi": fin[i].tolist()},
           "rms_nmi_median": float(np.median(rms))}
    if paper_set is not None:
        ps = np.array(paper_set)
        r = float(np.sqrt(np.mean((ps - paper) ** 2)))
        res["paper_set"] = {"final_nmi": ps.tolist(), "rms_nmi": r, "draws_nearer": int(np.sum(rms < r))}
    for tol in (0.25, 0.5):
        k = int(np.sum(np.all(np.abs(fin - paper) <= tol * paper, axis=1)))
        res[f"all_six_within_{int(tol * 100)}pct"] = {"count": k, "ci90": list(clopper_pearson(k, len(full)))}
    orders = {}
    for j, p in enumerate(SEED002_EXPERIMENTS):
        no, tr, fl = fin[:, 3 * j], fin[:, 3 * j + 1], fin[:, 3 * j + 2]
        orders[SEED002_EXPERIMENTS[p][0]] = (no > tr) & (tr > fl)
    both = orders["exp. 1"] & orders["exp. 2"]
    res["paper_order"] = {name: {"count": int(o.sum()), "ci90": list(clopper_pearson(int(o.sum()), len(full)))}
                          for name, o in [*orders.items(), ("both", both)]}
    # the schemes beyond the up-gyro floor they share: each draw's error vector minus what its
    # drawn eps_U alone gives (the same for every scheme), and the difference of two schemes'
    # vectors, from which that floor cancels
    pairs = []
    for better, worse in [("flexible", "two_position"), ("two_position", "none"), ("flexible", "none")]:
        for p in SEED002_EXPERIMENTS:
            a, b, wins, diff, own_a, own_b = f"{better}|{p}", f"{worse}|{p}", 0, [], [], []
            ds = [d for d in vec if a in vec[d] and b in vec[d]]
            for d in ds:
                u = np.array(up_response[p]) * up_gyro_dph("seed002", d) / 0.003
                ea, eb = np.array(vec[d][a][:2]), np.array(vec[d][b][:2])
                own_a.append(np.hypot(*(ea - u)))
                own_b.append(np.hypot(*(eb - u)))
                wins += own_a[-1] < own_b[-1]
                diff.append(np.hypot(*(ea - eb)))
            pairs.append({"experiment": SEED002_EXPERIMENTS[p][0], "better": better, "worse": worse,
                          "n": len(ds), "wins_beyond_floor": int(wins),
                          "p": wins / len(ds), "ci90": list(clopper_pearson(int(wins), len(ds))),
                          "median_own_better_nmi": float(np.median(own_a)),
                          "median_own_worse_nmi": float(np.median(own_b)),
                          "median_abs_difference_nmi": float(np.median(diff))})
    res["beyond_floor"] = pairs
    res["up_gyro_response_nmi_per_3e-3_dph"] = up_response
    return res


def _fmt_joint(j, labels):
    paper = j["paper_final_nmi"]
    n = j["nearest"]
    out = [f"Draws with all six Table 2 rows: {j['draws']}. The paper's six final errors (exp. 1 none / "
           f"traditional / flexible, exp. 2 the same): {' / '.join(f'{x:g}' for x in paper)} nmi.", "",
           f"- The draw nearest to all six at once (RMS of the six differences): draw {n['draw']}, "
           f"{' / '.join(f'{x:.2f}' for x in n['final_nmi'])} nmi, RMS {n['rms_nmi']:.2f} nmi, its largest "
           f"difference {n['max_abs_nmi']:.2f} nmi (the median draw's RMS: {j['rms_nmi_median']:.2f} nmi).",
           *([f"- The paper's own set (every term +its value, noise seed 1): "
              f"{' / '.join(f'{x:.2f}' for x in j['paper_set']['final_nmi'])} nmi, RMS "
              f"{j['paper_set']['rms_nmi']:.2f} nmi; {j['paper_set']['draws_nearer']} of {j['draws']} "
              f"drawn units come nearer."] if "paper_set" in j else []),
           *(f"- All six within {t} % of the paper's figure: {j[f'all_six_within_{t}pct']['count']} of "
             f"{j['draws']} draws (90 % interval {j[f'all_six_within_{t}pct']['ci90'][0]:.3f}-"
             f"{j[f'all_six_within_{t}pct']['ci90'][1]:.3f})." for t in (25, 50)),
           *(f"- The paper's order none > traditional > flexible in {name}: {o['count']} of {j['draws']} "
             f"draws (90 % interval {o['ci90'][0]:.2f}-{o['ci90'][1]:.2f})."
             for name, o in j["paper_order"].items()), "",
           "| experiment | comparison | draws | P(first's own error smaller) | 90 % interval | "
           "median own error, first / second (nmi) | median abs(difference of the error vectors) (nmi) |",
           "|---|---|---|---|---|---|---|"]
    for p in j["beyond_floor"]:
        out.append(f"| {p['experiment']} | {labels[p['better']]} < {labels[p['worse']]} | {p['n']} | "
                   f"{p['p']:.2f} ({p['wins_beyond_floor']}/{p['n']}) | {p['ci90'][0]:.2f} - {p['ci90'][1]:.2f} | "
                   f"{p['median_own_better_nmi']:.2f} / {p['median_own_worse_nmi']:.2f} | "
                   f"{p['median_abs_difference_nmi']:.2f} |")
    return out


def _cached(path, compute):
    """The JSON at ``path``, else ``compute()`` written there (the runs a report needs once)."""
    if os.path.exists(path):
        with open(path) as f:
            return json.load(f)
    value = compute()
    records.write_atomic(path, json.dumps(value))
    return value


def report(keys, out_root, report_dir):
    """Write montecarlo.json and the histograms into ``report_dir``; returns the tables as Markdown."""
    os.makedirs(report_dir, exist_ok=True)
    # one seed's report keeps the other's figures in montecarlo.json (and its
    # tables in montecarlo.md, which `_fill_markdown` rewrites only for both)
    blob, md = {}, []
    try:
        with open(os.path.join(report_dir, "montecarlo.json")) as f:
            blob = {k: v for k, v in json.load(f).items() if k in CAMPAIGNS and k not in keys}
    except (OSError, ValueError):
        pass
    for key in keys:
        out = os.path.join(out_root, key)
        result = collect(load(key), out)
        if not any(p["metrics"] for p in result["points"]):
            md.append(f"{key}: no complete run in {out}")
            continue
        stats = statistics(key, result)
        histograms(key, result, stats, os.path.join(report_dir, f"montecarlo_{key}.png"))
        blob[key] = dict(stats, timing=read_timing(out), runs_timing=result["runs_timing"],
                         campaign=CAMPAIGNS[key], campaign_digest=result["campaign"]["digest"])
        md += [f"### {key}: {stats['draws_max']} draws (every group: {stats['draws']})", "",
               *(["Table 1's heading read as " + ("yaw +15 deg (PSINS's counter-clockwise yaw; yaw "
                  "error +1')" if CONVENTION["name"] == "ccw" else "a clockwise heading (yaw -15 deg, "
                  "yaw error -1')") + f" (--convention {CONVENTION['name']}).", ""] if key == "seed002" else []),
               *_fmt_rows(stats["rows"], key), "", *_fmt_pairs(stats["pairs"], stats["labels"]), ""]
        if key == "seed002":
            vec = draw_vectors(load(key), out)
            up = _cached(os.path.join(out, f"up_gyro_response_{CONVENTION['name']}.json"),
                         lambda: up_gyro_response(CONVENTION["name"]))
            ps = _cached(os.path.join(out, f"paper_set_{CONVENTION['name']}.json"),
                         lambda: paper_set_finals(CONVENTION["name"]))
            j = joint(vec, paper_figures(key), up, ps)
            blob[key]["joint"] = j
            with open(os.path.join(report_dir, "montecarlo_draws.json"), "w") as f:
                json.dump({"convention": CONVENTION["name"], "unit": "nmi",
                           "fields": "north, east (final), max horizontal", "draws": vec}, f, indent=0)
            md += ["#### The paper's six figures at once, and the schemes beside the shared up-gyro floor", "",
                   *_fmt_joint(j, stats["labels"]), ""]
        md += [timing_line(key, out, result["runs_timing"]), ""]
    blob = {k: blob[k] for k in CAMPAIGNS if k in blob}
    records.write_atomic(os.path.join(report_dir, "montecarlo.json"), json.dumps(blob, indent=1, allow_nan=True))
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
    ap.add_argument("--convention", choices=sorted(CONVENTIONS), default="ccw",
                    help="seed 002's Table 1 heading: ccw = yaw +15 deg (PSINS, adopted; default), "
                         "clockwise = yaw -15 deg (the built-in scenarios)")
    a = ap.parse_args(argv)
    CONVENTION["name"] = a.convention
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
            camp_schemes = load(key).grid["indexing.scheme"]
            schemes = [s for s in a.schemes.split(",") if s in camp_schemes] if a.schemes else None
            run_seed(key, a.draws, a.block, os.path.join(a.out, key), a.workers, a.scheduler, a.quiet,
                     schemes)
    print(report(keys, a.out, a.report))
    return 0


if __name__ == "__main__":
    sys.exit(main())
