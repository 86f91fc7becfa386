"""A run's page and figures: the plots and report.html of a run directory (``pyins report RUNDIR``).

Reads only what `pyins.runs.execute` wrote (summary.json, the variants'
timeseries.npz), so a report can be re-rendered, or rendered for a partial
run, without running anything. Units follow the papers (`pyins.metrics`):
position errors in m or nmi (whichever reads better), level errors in
arc-seconds, heading errors in arc-minutes.

`render`:
1. the figures: navigation errors, the alignment's convergence, the
   turntable and the flexible scheme's sums, the scheme comparison (each
   when the run has something to show);
2. the results table (a column per metric a paper figure may name), the
   group metrics and the paper's figures beside ours;
3. report.html, with the scenario as run.
"""
import html
import json
import os

import numpy as np

from pyins import metrics, records, runs
from pyins.metrics import FIGURE_METRICS, display
from pyins.report.plotting import pyplot, time_axis
from pyins.units import ARCMIN_TO_RAD, ARCSEC_TO_RAD, NMI_TO_M

__all__ = ["render", "load", "plot_errors", "plot_alignment", "plot_table", "plot_comparison"]


def load(run_dir):
    """summary.json and the variants' series. A partial run (Ctrl-C, a kill,
    or one being written) is read as far as its records go: each unfinished
    variant's records on disk beside the truth of the scenario the run was
    written from, its metrics computed here (summary.json is left as it is);
    ``summary["stopped"]`` says how it stands."""
    summary = runs.read_summary(run_dir)
    if summary is None:
        raise FileNotFoundError(f"{run_dir}: not a run directory (no readable {runs.SUMMARY})")
    unfinished = [v for v in summary["variants"] if not v.get("complete")]
    scn = runs.scenario_of(run_dir, summary) if unfinished else None
    specs = {spec.label: spec for spec in scn.runs()} if scn is not None else {}
    series = {}
    for v in summary["variants"]:
        path = os.path.join(run_dir, v["dir"], "timeseries.npz")
        spec = specs.get(v["label"])
        if not v.get("complete") and spec is not None:
            res = runs.load_written(run_dir, spec)
            if res is not None:
                series[v["label"]] = records.timeseries(res)
                v["ticks_done"] = int(res.outputs["tick"][-1])
                v["metrics"] = metrics.run_metrics(spec, res)
        elif os.path.exists(path):
            with np.load(path, allow_pickle=False) as z:
                series[v["label"]] = {k: z[k] for k in z.files}
    if unfinished:
        holder = records.is_locked(run_dir)
        if holder is not None:
            summary["stopped"] = f"being written by pid {holder.get('pid', '?')} on {holder.get('host', '?')}"
        elif summary.get("state") == "interrupted":
            summary["stopped"] = "interrupted (Ctrl-C)"
        elif summary.get("state") == "running":
            summary["stopped"] = "stopped while running (killed or crashed)"
        else:
            summary["stopped"] = "interrupted"
        if scn is None:
            summary["stopped"] += "; the scenario could not be rebuilt, so only the finished variants are shown"
        summary["group_metrics"] = metrics.group_metrics(summary["variants"])
    return summary, series


def plot_errors(summary, series, path):
    plt = pyplot()
    big = max((s["horizontal_m"].max() for s in series.values() if len(s["horizontal_m"])), default=0)
    pos_scale, pos_unit = (NMI_TO_M, "nmi") if big > 0.5 * NMI_TO_M else (1.0, "m")
    fig, ax = plt.subplots(4, 1, figsize=(9, 11), sharex=True)
    for label, s in series.items():
        t, tl = time_axis(s["time_s"])
        ax[0].plot(t, s["horizontal_m"] / pos_scale, label=label)
        ax[1].plot(t, np.abs(s["att_err_n_rad"][:, :2]).max(axis=1) / ARCSEC_TO_RAD, label=label)
        ax[2].plot(t, s["att_err_n_rad"][:, 2] / ARCMIN_TO_RAD, label=label)
        ax[3].plot(t, np.hypot(s["vel_err_n_mps"][:, 0], s["vel_err_n_mps"][:, 1]), label=label)
        ax[3].set_xlabel(tl)
    for a, yl in zip(ax, [f"horizontal position error [{pos_unit}]", "max |level error| [arcsec]",
                          "heading error phi_U [arcmin]", "horizontal velocity error [m/s]"]):
        a.set_ylabel(yl)
        a.grid(alpha=0.3)
        if len(series) > 1:
            a.legend(fontsize=8)
    fig.suptitle(summary["title"], fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def plot_alignment(summary, series, path):
    """Attitude errors and the filter's sigma over the alignment (if any)."""
    plt = pyplot()
    aligning = {k: s for k, s in series.items() if (s["outputs"]["mode"] != 3).any()}
    if not aligning:
        return False
    fig, ax = plt.subplots(3, 1, figsize=(9, 9), sharex=True)
    names = ["phi_E [arcsec]", "phi_N [arcsec]", "phi_U [arcmin]"]
    scale = [ARCSEC_TO_RAD, ARCSEC_TO_RAD, ARCMIN_TO_RAD]
    for label, s in aligning.items():
        t, tl = time_axis(s["time_s"])
        for i in range(3):
            # |error| on a log axis: the first seconds are degrees, the end arc-seconds
            ax[i].semilogy(t, np.abs(s["att_err_n_rad"][:, i]) / scale[i], label=label, lw=0.9)
            sig = s["outputs"]["kf_sigma"][:, i]
            if np.any(sig > 0):
                ax[i].semilogy(t, 3 * sig / scale[i], "k:", lw=0.8)
        ax[2].set_xlabel(tl)
    for a, n in zip(ax, names):
        a.set_ylabel(f"|{n.split(' ')[0]}| {n.split(' ')[1]}")
        a.grid(alpha=0.3, which="both")
    ax[0].legend(fontsize=8)
    ax[0].set_title("alignment convergence: |attitude error| (dotted: 3 sigma of the fine-alignment "
                    "filter)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return True


def plot_table(summary, series, path):
    """Table angle, IMU heading and A_c/A_s of the rotating variants."""
    plt = pyplot()
    turning = {k: s for k, s in series.items()
               if np.any(s["outputs"]["index_state"] != 0) or np.any(s["outputs"]["table_angle_rad"] != 0)}
    if not turning:
        return False
    fig, ax = plt.subplots(3, 1, figsize=(9, 9), sharex=True)
    for label, s in turning.items():
        o = s["outputs"]
        t, tl = time_axis(s["time_s"])
        ax[0].plot(t, np.degrees(o["table_angle_rad"]), label=label, lw=0.8)
        ax[1].plot(t, np.degrees(o["yaw_p_rad"]), label=label, lw=0.5)
        ax[2].plot(t, o["index_a_c"], label=f"{label}: A_c", lw=0.8)
        ax[2].plot(t, o["index_a_s"], "--", label=f"{label}: A_s", lw=0.8)
        ax[2].set_xlabel(tl)
    for a, yl in zip(ax, ["table angle (encoder) [deg]", "IMU yaw psi_p [deg]",
                          "A_c, A_s [samples]"]):
        a.set_ylabel(yl)
        a.grid(alpha=0.3)
        a.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return True


def plot_comparison(summary, path):
    """Final and maximum horizontal errors per variant, the paper's beside."""
    plt = pyplot()
    vs = [v for v in summary["variants"] if "horizontal_error_max" in v["metrics"]]
    if len(vs) < 2:
        return False
    big = max(v["metrics"]["horizontal_error_max"] for v in vs)
    sc, un = (NMI_TO_M, "nmi") if big > 0.5 * NMI_TO_M else (1.0, "m")
    x = np.arange(len(vs))
    fig, ax = plt.subplots(figsize=(9, 4.5))
    ax.bar(x - 0.25, [v["metrics"]["horizontal_error_final"] / sc for v in vs], 0.25, label="ours, final")
    ax.bar(x, [v["metrics"]["horizontal_error_max"] / sc for v in vs], 0.25, label="ours, max")
    paper = {}
    for f in (summary.get("paper") or {}).get("figures", []):
        if f["metric"].startswith("horizontal_error") and f.get("variant"):
            paper[f["variant"]] = f["value_si"] / sc
    if paper:
        ax.bar(x + 0.25, [paper.get(v["label"], 0.0) for v in vs], 0.25, label="paper")
    ax.set_xticks(x, [v["label"] for v in vs], fontsize=8, rotation=10)
    ax.set_ylabel(f"horizontal position error [{un}]")
    ax.grid(alpha=0.3, axis="y")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return True


def _fmt(v, unit_scale):
    unit, scale = unit_scale
    return f"{v / scale:.4g} {unit}"


def _ours(row):
    return "" if row["ours"] is None else f"{row['ours']:.4g} {row['unit']}"


def render(run_dir, loaded=None):
    """Write the plots and report.html into ``run_dir``; returns the path.
    ``loaded``: what `load` returned for it (else it is read here)."""
    summary, series = loaded if loaded is not None else load(run_dir)
    # 1. the figures
    figs = []
    if series:
        plot_errors(summary, series, os.path.join(run_dir, "errors.png"))
        figs.append(("errors.png", "Navigation errors against the truth"))
        if plot_alignment(summary, series, os.path.join(run_dir, "alignment.png")):
            figs.append(("alignment.png", "Alignment convergence"))
        if plot_table(summary, series, os.path.join(run_dir, "table.png")):
            figs.append(("table.png", "Turntable angle, IMU heading and the flexible scheme's sums"))
    if plot_comparison(summary, os.path.join(run_dir, "comparison.png")):
        figs.append(("comparison.png", "Scheme comparison"))
    # 2. the results, the group metrics, the paper's figures
    esc = html.escape
    metric_names = [k for k in FIGURE_METRICS if any(k in v["metrics"] for v in summary["variants"])]
    head = "".join(f"<th>{esc(k)}</th>" for k in metric_names)
    body = []
    for v in summary["variants"]:
        cells = "".join(f"<td>{_fmt(v['metrics'][k], display(k)) if k in v['metrics'] else ''}</td>"
                        for k in metric_names)
        done = "" if v["complete"] else f" (partial: {v['ticks_done']} of {v['ticks']} ticks)"
        body.append(f"<tr><td>{esc(v['label'])}{esc(done)}</td>{cells}</tr>")
    group = "".join(f"<li>{esc(k)}: {_fmt(val, display(k))}</li>"
                    for k, val in summary.get("group_metrics", {}).items())
    paper = summary.get("paper") or {}
    prow = "".join(
        f"<tr><td>{esc(r['metric'])}</td><td>{esc(r['variant'] or '')}</td>"
        f"<td>{esc(r['relation'])} {r['paper']:g} {esc(r['unit'])}</td>"
        f"<td>{esc(_ours(r))}</td><td>{esc(r['verdict'])}</td><td>{esc(r['note'])}</td></tr>"
        for r in runs.paper_rows(summary))
    paper_html = ""
    if paper.get("figures") or paper.get("citation"):
        paper_html = (f"<h2>Beside the paper</h2><p>{esc(paper.get('citation', ''))}</p>"
                      f"<p class='note'>{esc(paper.get('note', ''))}</p>"
                      "<table><tr><th>metric</th><th>variant</th><th>paper</th><th>ours</th>"
                      f"<th>verdict</th><th>note</th></tr>{prow}</table>")
    # 3. the page
    scen_text = ""
    scen_path = os.path.join(run_dir, "scenario.toml")
    if os.path.exists(scen_path):
        with open(scen_path) as f:
            scen_text = f.read()
    status = "complete" if summary["complete"] else (
        f"PARTIAL ({summary.get('stopped', 'interrupted')}): figures cover the ticks done")
    imgs = "".join(f"<figure><img src='{esc(p)}' alt='{esc(c)}'><figcaption>{esc(c)}</figcaption></figure>"
                   for p, c in figs)
    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{esc(summary['title'])}</title>
<style>
body {{ font-family: sans-serif; max-width: 1100px; margin: 2em auto; color: #222; }}
table {{ border-collapse: collapse; margin: 1em 0; font-size: 0.9em; }}
td, th {{ border: 1px solid #bbb; padding: 0.25em 0.6em; text-align: right; }}
td:first-child, th:first-child {{ text-align: left; }}
figure {{ margin: 1em 0; }} img {{ max-width: 100%; }}
.note {{ color: #555; white-space: pre-wrap; }} pre {{ background: #f4f4f4; padding: 1em; overflow-x: auto; }}
</style></head><body>
<h1>{esc(summary['title'])}</h1>
<p>Scenario <code>{esc(summary['scenario'])}</code>, digest <code>{esc(summary['digest'][:16])}</code>,
core {esc(summary['core_version'])}. Status: {esc(status)}.</p>
<h2>Results</h2>
<table><tr><th>variant</th>{head}</tr>{''.join(body)}</table>
{f'<ul>{group}</ul>' if group else ''}
{paper_html}
<h2>Figures</h2>
{imgs}
<h2>Scenario</h2>
<pre>{esc(scen_text)}</pre>
</body></html>
"""
    path = os.path.join(run_dir, "report.html")
    records.write_atomic(path, page, sync=False)
    return path
