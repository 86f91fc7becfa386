"""A campaign's page and figures: aggregate.md and plots/ (``pyins campaign``).

Reads only what `pyins.campaign.aggregate` computed (the campaign.json dict
and the rows of every run's metrics) and the campaign's groups, so it writes
nothing but text and images. Units follow the papers (`pyins.metrics.display`):
position errors in m or nmi, level errors in arc-seconds, heading errors in
arc-minutes; aggregate.csv holds the same in SI.

aggregate.md (`markdown`):
1. the campaign: base scenario, grid, seeds, groups, fixed overrides;
2. the spread over the runs of each group (the group metrics);
3. beside the paper: the base scenario's [paper] figures and ours;
4. per metric: with two or more group keys the mean of each group by the
   first key and the others (`pivot_lines`), then the statistics per group.

plots/ (`plots`): per metric the mean +- std and box plots per group; the
group metrics with the paper's figures; with two or more group keys, each
metric against each of the first two keys (`_by_key_plots`).
"""
import os

import numpy as np

from pyins import scenario as scenario_mod
from pyins.metrics import GROUP_METRICS, display, si_name
from pyins.report.plotting import margins, pyplot

__all__ = ["markdown", "pivot_lines", "plots"]


def _g(x, scale):
    """A value shown in a unit (``scale``: its size in SI), 4 digits; "" for None."""
    return "" if x is None else f"{x / scale:.4g}"


def markdown(camp, result, rows):
    """aggregate.md: the campaign, the spread over each group, the paper's
    figures beside ours, and per metric the statistics of each group."""
    stats = result["stats"]
    # 1. the campaign
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
        lines += ["Set on every run: "
                  + ", ".join(f"`{k} = {camp.show(v)}`" for k, v in camp.overrides.items()) + ".", ""]
    if result["missing_points"]:
        lines += [f"**Incomplete**: {len(result['missing_points'])} point(s) have no complete run "
                  f"yet; the figures below cover the others.", ""]
    # 2. the spread over the runs of each group
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
                str(cnt), _g(lv and lv["value"], display("level_error_std", [])[1]),
                _g(hd and hd["value"], display("heading_error_std", [])[1])]) + " |")
        lines.append("")
    # 3. beside the paper
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
    # 4. per metric
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
        unit, scale = display(m, [r[2].get(m) for r in rows])
        lines += [f"### {m} [{unit}]", "", info["meaning"] + ".", ""]
        lines += pivot_lines(camp, sel, scale)
        heads = ["group"] + (["variant"] if vcol else []) + list(stats)
        lines += ["| " + " | ".join(heads) + " |", "|" + "---|" * len(heads)]
        for a in sel:
            lines.append("| " + " | ".join([camp.groups[a["group"]]["label"]] + (
                [a["variant"]] if vcol else []) + [str(a["count"])] + [_g(a[s], scale) for s in stats[1:]])
                + " |")
        lines.append("")
    return "\n".join(lines)


def pivot_lines(camp, sel, scale):
    """With two or more group keys: the mean of each group in a table whose
    rows are the first key's values and whose columns are the others' (per
    [compare] variant)."""
    if len(camp.group_by) < 2:
        return []
    rows, cols = camp.by_key(camp.group_by[0])
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
        unit, scale = display(m, vals_all)
        fig, axes = plt.subplots(1, 2, figsize=(12.0, 5.2), sharey=True)
        for ax, key in zip(axes, keys):
            xlabels, lines = camp.by_key(key)
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


def plots(camp, out_dir, result, rows):
    """plots/<metric>.png per metric (mean +- std and box plots per group),
    plots/group_std.png (the group metrics, the paper's figures beside) and,
    with two or more group keys, plots/<metric>_by_keys.png; returns the paths."""
    plt = pyplot()
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
        unit, scale = display(m, vals_all)
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
        margins(fig, labels, rot)
        path = os.path.join(pdir, f"{m}.png")
        fig.savefig(path, dpi=90)
        plt.close(fig)
        written.append(path)
    gm = result["group_metrics"]
    if gm:
        fig, ax = plt.subplots(1, 2, figsize=(fig_w, 5.2))
        for j, m in enumerate(GROUP_METRICS):
            unit, scale = display(m, [])
            for k, v in enumerate(vlabels):
                off = (k - (nv - 1) / 2) * width
                d = {a["group"]: a["value"] for a in gm if a["metric"] == si_name(m) and a["variant"] == v}
                gx = [gi for gi in range(len(labels)) if d.get(gi) is not None]
                bars = ax[j].bar(x[gx] + off, [d[gi] / scale for gi in gx], width,
                                 label=v or "std (ddof=1) over the group's runs")
                ax[j].bar_label(bars, labels=[f"{d[gi] / scale:.3g}" for gi in gx], fontsize=7)
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
        margins(fig, labels, rot, wspace=0.25)
        path = os.path.join(pdir, "group_std.png")
        fig.savefig(path, dpi=90)
        plt.close(fig)
        written.append(path)
    written += _by_key_plots(camp, pdir, result, rows, plt)
    return written
