"""A run's page and figures: the plots and report.html of a run directory (``pyins report RUNDIR``).

Reads only what `pyins.run_scenario.execute` wrote (summary.json, the variants'
timeseries.npz), so a report can be re-rendered, or rendered for a partial
run, without running anything. Units follow the papers (`pyins.metrics`):
position errors in m or nmi (whichever reads better), level errors in
arc-seconds, heading errors in arc-minutes, latitude and longitude errors
in arc-seconds or, with errors beyond a minute, arc-minutes (1' of
latitude is 1 nmi).

`render`:
1. the figures, each only where it means something: the errors (position:
   horizontal, north, east, latitude, longitude; velocity, when a variant
   navigates: an alignment holds the site; level, heading);
   the alignment's convergence (runs that align); the turntable (rotating
   variants), with a zoom on a few cycles beside each panel when the run has
   many, and the flexible sums A_c, A_s (only schemes that steer by them);
   the scheme comparison (two variants or more). Every curve is a min/max
   envelope of at most `pyins.report.plotting.MAX_POINTS` points: a 72 h run
   draws in seconds and its peaks stay;
2. the results table, a row per metric and a column per variant (at most
   `VARIANTS_PER_TABLE` a table: the page reads at 1200 px whatever the
   number of metrics), the position error split north/east and
   latitude/longitude, the group metrics, the paper's figures beside ours
   (`pyins.report.paper.paper_rows`: a stopped run, or one run for another length
   than the scenario gives it, is labelled and not judged);
3. report.html, with the scenario as run.

``render(..., progress=pyins.progress.Phases())`` writes a line per phase
(reading the records, the figures) on stderr.
"""
import html
import json
import os
import zipfile

import numpy as np

from pyins import contract, metrics, records, rundir
from pyins.metrics import FIGURE_METRICS, display
from pyins.progress import phase
from pyins.reference import abi, earth
from pyins.reference.config import DEFAULT_NAV_GATE
from pyins.report.paper import not_judged, paper_rows, span
from pyins.report.plotting import cycle_window, line, pyplot, time_axis
from pyins.units import ARCMIN_TO_RAD, ARCSEC_TO_RAD, NMI_TO_M

__all__ = ["render", "load", "plot_errors", "plot_alignment", "plot_table", "plot_comparison",
           "latlon_errors", "navigates", "VARIANTS_PER_TABLE"]

#: variant columns of one results table (more variants: more tables, one under the other)
VARIANTS_PER_TABLE = 5
_DPI = 90


def _fill_facts(run_dir, summary, scn):
    """Duration as run and as written, and the use of the flexible sums, for
    the variants of a summary written before `pyins.run_scenario` recorded them."""
    if all("duration_s" in v and "uses_index_sums" in v for v in summary["variants"]):
        return
    scn = scn if scn is not None else rundir.scenario_of(run_dir, summary)
    if scn is None:
        return
    written = rundir.written_durations(scn)
    facts = {spec.label: rundir.variant_facts(spec, written) for spec in scn.runs()}
    for v in summary["variants"]:
        for k, val in facts.get(v["label"], {}).items():
            v.setdefault(k, val)


#: What a variant's timeseries.npz must hold for the figures
_SERIES_KEYS = ("time_s", "north_m", "east_m", "horizontal_m", "vel_err_n_mps", "att_err_n_rad", "outputs")
#: The fields of a variant's firmware records the figures and tables read; only these are
#: loaded (a 72 h run with 1-s records: 200 B a record instead of 696, and the plant's
#: records not at all), so a report of long runs holds about a third of their records.
_REPORT_FIELDS = ("lat_rad", "height_m", "mode", "kf_sigma", "index_state", "index_step", "index_a_c",
                  "index_a_s", "n_ref_used", "nav_mode", "nav_nis", "nav_sigma_pos_m", "ref_in_use",
                  "table_angle_rad", "yaw_p_rad")
#: Records read at a time from timeseries.npz's firmware records (3.5 MB).
_READ_RECORDS = 5_000


def load_series(path):
    """A variant's timeseries.npz as the report holds it: the error arrays,
    and its firmware records with only the fields the report reads
    (`_REPORT_FIELDS`), read 5,000 records at a time (never the whole
    records at once)."""
    s = {}
    with zipfile.ZipFile(path) as zf:
        for name in zf.namelist():
            key = name[:-4] if name.endswith(".npy") else name
            if key == "plant":
                continue
            with zf.open(name) as f:
                if key != "outputs":
                    s[key] = np.lib.format.read_array(f, allow_pickle=False)
                    continue
                version = np.lib.format.read_magic(f)
                if version not in ((1, 0), (2, 0)):      # a newer layout: read whole, then keep the fields
                    with zf.open(name) as g:
                        s[key] = _kept_fields(np.lib.format.read_array(g, allow_pickle=False))
                    continue
                read_header = (np.lib.format.read_array_header_1_0 if version == (1, 0)
                               else np.lib.format.read_array_header_2_0)
                shape, fortran, dtype = read_header(f)
                if fortran or len(shape) != 1 or dtype.names is None:
                    raise ValueError(f"{name}: not a 1-d array of records")
                kept = _kept_dtype(dtype)
                out = np.empty(shape, dtype=kept)
                for i in range(0, shape[0], _READ_RECORDS):
                    m = min(_READ_RECORDS, shape[0] - i)
                    buf = f.read(m * dtype.itemsize)
                    if len(buf) != m * dtype.itemsize:
                        raise ValueError(f"{name}: shorter than its header says")
                    chunk = np.frombuffer(buf, dtype=dtype)
                    for n in kept.names:
                        out[n][i:i + m] = chunk[n]
                s[key] = out
    return s


def _kept_dtype(dtype):
    """The packed record type of `_REPORT_FIELDS` that ``dtype`` has."""
    return np.dtype([(n, dtype.fields[n][0]) for n in _REPORT_FIELDS if n in dtype.names])


def _kept_fields(records):
    """``records`` with only the fields of `_REPORT_FIELDS` it has, packed."""
    kept = _kept_dtype(records.dtype)
    out = np.empty(records.shape, dtype=kept)
    for n in kept.names:
        out[n] = records[n]
    return out


def load(run_dir):
    """summary.json and the variants' series. A partial run (Ctrl-C, a kill,
    or one being written) is read as far as its records go: each unfinished
    variant's records on disk beside the truth of the scenario the run was
    written from, its metrics computed here (summary.json is left as it is);
    ``summary["stopped"]`` says how it stands."""
    summary = rundir.summary_for_report(run_dir)
    problems = summary.setdefault("report_warnings", [])
    unfinished = [v for v in summary["variants"] if not v.get("complete")]
    scn = rundir.scenario_of(run_dir, summary) if unfinished else None
    specs = {spec.label: spec for spec in scn.runs()} if scn is not None else {}
    _fill_facts(run_dir, summary, scn)
    series, lost = {}, []
    for v in summary["variants"]:
        rel = os.path.join(v["dir"], "timeseries.npz")
        path = os.path.join(run_dir, rel)
        spec = specs.get(v["label"])
        if not v.get("complete") and spec is not None:
            try:
                res = rundir.load_written(run_dir, spec)
            except (OSError, ValueError, KeyError, TypeError, IndexError) as exc:
                problems.append(f"{os.path.join(v['dir'], 'records')}: unreadable ({type(exc).__name__}: "
                                f"{exc}); variant {v['label']!r} is left out of the figures")
                res = None
            if res is not None:
                series[v["label"]] = records.timeseries(res)
                v["ticks_done"] = int(res.outputs["tick"][-1])
                v["metrics"] = metrics.run_metrics(spec, res)
        elif os.path.exists(path):
            try:
                s = load_series(path)
                missing = [k for k in _SERIES_KEYS if k not in s]
                if missing:
                    raise ValueError(f"no {', '.join(missing)}")
                series[v["label"]] = s
            except Exception as exc:    # noqa: BLE001 - any damage: a zip, a pickle, a short array
                lost.append((v, rel, f"damaged ({type(exc).__name__}: "
                             f"{str(exc).splitlines()[0] if str(exc) else ''})"))
        elif v.get("complete"):
            lost.append((v, rel, "missing"))
    if lost:        # a finished variant's series: rebuilt from its records when they and the scenario are there
        scn = scn if scn is not None else rundir.scenario_of(run_dir, summary)
        specs = {spec.label: spec for spec in scn.runs()} if scn is not None else {}
        for v, rel, what in lost:
            res = None
            if v["label"] in specs:
                try:
                    res = rundir.load_written(run_dir, specs[v["label"]])
                except (OSError, ValueError, KeyError, TypeError, IndexError):
                    res = None
            if res is not None and len(res.outputs):
                series[v["label"]] = records.timeseries(res)
                problems.append(f"{rel}: {what}; variant {v['label']!r} is drawn from its records instead")
            else:
                problems.append(f"{rel}: {what}, and its records cannot be read back; variant "
                                f"{v['label']!r} is left out of the figures (its figures in the tables are "
                                "summary.json's)")
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


# ---------------------------------------------------------------------------
# 1. The figures
# ---------------------------------------------------------------------------
def latlon_errors(s):
    """(latitude error, longitude error) [rad] of one variant's series: its
    north and east errors over the radii of curvature at the computed
    position (to 1e-4 of the value, what a figure or a table shows)."""
    o = s["outputs"]
    rm, rn = earth.principal_radii(np.sin(o["lat_rad"]))
    h = o["height_m"]
    return s["north_m"] / (rm + h), s["east_m"] / ((rn + h) * np.cos(o["lat_rad"]))


def _pos_unit(values_m):
    return display("horizontal_error_max", [float(np.max(np.abs(v), initial=0.0)) for v in values_m])


def _angle_unit(values_rad):
    big = max((float(np.max(np.abs(v), initial=0.0)) for v in values_rad), default=0.0)
    return ("arcmin", ARCMIN_TO_RAD) if big > ARCMIN_TO_RAD else ("arcsec", ARCSEC_TO_RAD)


def _clock(series):
    """(seconds per unit, axis label) of one time axis for every variant of a
    figure: the unit `time_axis` picks for the longest of them (a stopped
    variant is drawn on the same axis as the finished ones)."""
    longest = max((float(s["time_s"][-1]) for s in series.values() if len(s["time_s"])), default=0.0)
    shown, label = time_axis(np.array([longest]))
    return (longest / shown[0] if longest > 0 else 1.0), label


def _colours(summary):
    """label -> colour: one per variant, the same in every figure."""
    return {v["label"]: f"C{i % 10}" for i, v in enumerate(summary["variants"])}


def _save(fig, path, plt):
    fig.savefig(path, dpi=_DPI)
    plt.close(fig)


def navigates(s):
    """True when a variant's series holds navigation (more than the last
    record in PYINS_MODE_NAVIGATE): during an alignment the firmware holds
    the site and zero velocity, so position and velocity errors mean
    nothing."""
    return int(np.count_nonzero(s["outputs"]["mode"] == abi.PYINS_MODE_NAVIGATE)) > 1


def plot_errors(summary, series, path):
    """Horizontal, north and east position errors, latitude and longitude
    errors, horizontal velocity (when a variant navigates), level and heading
    errors of every variant."""
    plt = pyplot()
    nav = any(navigates(s) for s in series.values())
    rows = 4 if nav else 1
    fig, ax = plt.subplots(rows, 2, figsize=(12.4, 11 if nav else 3.6), sharex=True, squeeze=False)
    ts, tl = _clock(series)
    colour = _colours(summary)
    if nav:
        pos_unit, pos_scale = _pos_unit([s[k] for s in series.values() for k in ("north_m", "east_m",
                                                                                "horizontal_m")])
        ll = {label: latlon_errors(s) for label, s in series.items()}
        ang_unit, ang_scale = _angle_unit([a for pair in ll.values() for a in pair])
    for label, s in series.items():
        t = s["time_s"] / ts
        kw = dict(label=label, lw=0.9, color=colour[label])
        if nav:
            dlat, dlon = ll[label]
            line(ax[0, 0], t, s["horizontal_m"] / pos_scale, **kw)
            line(ax[0, 1], t, np.hypot(s["vel_err_n_mps"][:, 0], s["vel_err_n_mps"][:, 1]), **kw)
            line(ax[1, 0], t, s["north_m"] / pos_scale, **kw)
            line(ax[1, 1], t, s["east_m"] / pos_scale, **kw)
            line(ax[2, 0], t, dlat / ang_scale, **kw)
            line(ax[2, 1], t, dlon / ang_scale, **kw)
        # a variant that navigates: its attitude from the end of the alignment (the unaligned start,
        # degrees, would squash the navigation's arc-seconds flat; alignment.png shows it)
        k = s["outputs"]["mode"] == abi.PYINS_MODE_NAVIGATE if nav and navigates(s) else slice(None)
        line(ax[-1, 0], t[k], np.abs(s["att_err_n_rad"][k, :2]).max(axis=1) / ARCSEC_TO_RAD, **kw)
        line(ax[-1, 1], t[k], s["att_err_n_rad"][k, 2] / ARCMIN_TO_RAD, **kw)
    for a in ax[-1]:
        a.set_xlabel(tl)
    names = ([f"horizontal position error [{pos_unit}]", "horizontal velocity error [m/s]",
              f"north position error [{pos_unit}]", f"east position error [{pos_unit}]",
              f"latitude error [{ang_unit}]", f"longitude error [{ang_unit}]"] if nav else [])
    names += (["max |level error| [arcsec], from the end of the alignment",
               "heading error phi_U [arcmin], from the end of the alignment"] if nav else
              ["max |level error| [arcsec]", "heading error phi_U [arcmin]"])
    for a, yl in zip(ax.flat, names):
        a.set_ylabel(yl, fontsize=9)
        a.grid(alpha=0.3)
    if len(series) > 1:
        ax[0, 0].legend(fontsize=8)
    fig.suptitle(summary["title"] + ("" if nav else " (alignment only: the site and zero velocity are "
                                     "held, no position error to show)"), fontsize=10)
    fig.tight_layout()
    _save(fig, path, plt)


def aided(s):
    """True when a variant's records show external references used."""
    out = s["outputs"]
    return "n_ref_used" in out.dtype.names and int(np.sum(out["n_ref_used"][-1])) > 0


def _spans(t, on):
    """The (t0, t1) spans where ``on`` holds (records in order)."""
    d = np.diff(np.concatenate([[0], np.asarray(on, bool).astype(np.int8), [0]]))
    return [(t[a], t[b - 1]) for a, b in zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1))]


def plot_references(summary, series, path):
    """Navigation with external references, a column per variant that used
    them: the horizontal error with the filter's 3-sigma envelope (spans
    without GNSS position shaded), each kind's normalised innovation with
    the gate, and the mode and the references in use over time. False when
    no variant used references."""
    used = {label: s for label, s in series.items() if aided(s)}
    if not used:
        return False
    plt = pyplot()
    fig, ax = plt.subplots(3, len(used), figsize=(6.4 * len(used) + 1.0, 9), sharex="col", squeeze=False)
    ts, tl = _clock(series)
    gate = DEFAULT_NAV_GATE         # (no scenario key sets another)
    for j, (label, s) in enumerate(used.items()):
        out = s["outputs"]
        nav = out["mode"] == abi.PYINS_MODE_NAVIGATE
        t = s["time_s"][nav] / ts
        o = out[nav]
        hor = s["horizontal_m"][nav]
        no_fix = (o["ref_in_use"] & (1 << (abi.PYINS_REF_GNSS_POS - 1))) == 0
        for a, b in _spans(t, no_fix):
            for k in range(3):
                ax[k, j].axvspan(a, b, color="0.9", lw=0, zorder=0)
        line(ax[0, j], t, hor, lw=0.8, label="horizontal error")
        line(ax[0, j], t, 3.0 * o["nav_sigma_pos_m"], lw=0.8, color="C3", label="filter's 3 sigma")
        ax[0, j].set_yscale("log")       # centimetres aided, metres coasting, the prior's tens at the start
        ax[0, j].set_ylabel("horizontal [m]")
        ax[0, j].set_title(f"{label}: shaded, no GNSS position in use", fontsize=9)
        kinds = [k for k in range(o["nav_nis"].shape[1]) if int(o["n_ref_used"][-1, k]) > 0]
        names = {v - 1: name for name, v in contract.REF_KINDS.items()}
        for k in kinds:
            nis = o["nav_nis"][:, k]
            ok = nis > 0.0
            if ok.any():
                ax[1, j].semilogy(t[ok], nis[ok], ".", ms=1.5, label=f"{names[k]} NIS")
        ax[1, j].axhline(gate, color="r", lw=0.8, ls="--", label=f"gate {gate:.4g}")
        ax[1, j].set_ylabel("normalised innovation (last)")
        lanes = [("integrated", (o["nav_mode"] == abi.PYINS_NAV_INTEGRATED).astype(float)),
                 ("damped", (o["nav_mode"] == abi.PYINS_NAV_DAMPED).astype(float))]
        lanes += [(f"{names[k]} in use", ((o["ref_in_use"] >> k) & 1).astype(float)) for k in kinds]
        for i, (name, on) in enumerate(lanes):
            ax[2, j].step(t, on * 0.6 + i, where="post", lw=1.0, color="k" if i < 2 else f"C{i - 2}")
        ax[2, j].set_yticks([i + 0.3 for i in range(len(lanes))], [n for n, _ in lanes], fontsize=8)
        ax[2, j].set_ylim(-0.3, len(lanes))
        ax[2, j].set_xlabel(tl)
        for k in range(2):
            ax[k, j].legend(fontsize=8, loc="upper right")
        for k in range(3):
            ax[k, j].grid(alpha=0.3)
    fig.tight_layout()
    _save(fig, path, plt)
    return True


def plot_alignment(summary, series, path):
    """Attitude errors and the filter's sigma over the alignment (if any)."""
    aligning = {k: s for k, s in series.items() if (s["outputs"]["mode"] != 3).any()}
    if not aligning:
        return False
    plt = pyplot()
    fig, ax = plt.subplots(3, 1, figsize=(10, 9), sharex=True)
    names = ["phi_E [arcsec]", "phi_N [arcsec]", "phi_U [arcmin]"]
    scale = [ARCSEC_TO_RAD, ARCSEC_TO_RAD, ARCMIN_TO_RAD]
    ts, tl = _clock(aligning)
    colour = _colours(summary)
    for label, s in aligning.items():
        t = s["time_s"] / ts
        for i in range(3):
            # |error| on a log axis: the first seconds are degrees, the end arc-seconds
            line(ax[i], t, np.abs(s["att_err_n_rad"][:, i]) / scale[i], label=label, lw=0.9, log=True,
                  color=colour[label])
            sig = s["outputs"]["kf_sigma"][:, i]
            if np.any(sig > 0):
                line(ax[i], t, 3 * sig / scale[i], "k:", lw=0.8, log=True)
    ax[2].set_xlabel(tl)
    for a, n in zip(ax, names):
        a.set_ylabel(f"|{n.split(' ')[0]}| {n.split(' ')[1]}")
        a.grid(alpha=0.3, which="both")
    ax[0].legend(fontsize=8)
    ax[0].set_title("alignment convergence: |attitude error| (dotted: 3 sigma of the fine-alignment "
                    "filter)", fontsize=9)
    fig.tight_layout()
    _save(fig, path, plt)
    return True


def _zoom_axis(t0_s, t1_s):
    """Unit and label of a zoom panel's time axis: seconds up to 20 min, else minutes."""
    return (60.0, "time [min]") if t1_s - t0_s > 1200 else (1.0, "time [s]")


def plot_table(summary, series, path):
    """Table angle and IMU yaw of the rotating variants, and the flexible
    sums A_c, A_s of those whose scheme steers by them; beside each panel a
    zoom on a few cycles when the run holds many (a 24 h run at 120 s a
    cycle is otherwise a solid band). False when no variant rotates."""
    turning = {k: s for k, s in series.items()
               if np.any(s["outputs"]["index_state"] != 0) or np.any(s["outputs"]["table_angle_rad"] != 0)}
    if not turning:
        return False
    plt = pyplot()
    flexible = {v["label"] for v in summary["variants"] if v.get("uses_index_sums")}
    sums = {k: s for k, s in turning.items() if k in flexible}
    windows = {}
    for label, s in turning.items():
        w = cycle_window(s["outputs"]["index_step"], s["outputs"]["index_state"])
        if w is not None:
            windows[label] = (s["time_s"][w.start], s["time_s"][w.stop - 1])
    zoom = (min(a for a, _ in windows.values()), max(b for _, b in windows.values())) if windows else None
    rows = 3 if sums else 2
    fig = plt.figure(figsize=(12.4, 3.1 * rows))
    gs = fig.add_gridspec(rows, 2 if zoom else 1, width_ratios=[2.3, 1] if zoom else [1])
    main = [fig.add_subplot(gs[0, 0])]
    main += [fig.add_subplot(gs[i, 0], sharex=main[0]) for i in range(1, rows)]
    side = []
    if zoom:
        side = [fig.add_subplot(gs[0, 1])]
        side += [fig.add_subplot(gs[i, 1], sharex=side[0]) for i in range(1, rows)]
        zs, zl = _zoom_axis(*zoom)
    ts, tl = _clock(turning)
    colour = _colours(summary)
    for label, s in turning.items():
        o = s["outputs"]
        t = s["time_s"] / ts
        curves = [(0, np.degrees(o["table_angle_rad"]), "-", label), (1, np.degrees(o["yaw_p_rad"]), "-", label)]
        if label in sums:
            curves += [(2, o["index_a_c"], "-", f"{label}: A_c"), (2, o["index_a_s"], "--", f"{label}: A_s")]
        for row, y, style, name in curves:
            line(main[row], t, y, style, label=name, lw=0.7, color=colour[label])
            if zoom:
                k = (s["time_s"] >= zoom[0]) & (s["time_s"] <= zoom[1])
                line(side[row], s["time_s"][k] / zs, y[k], style, color=colour[label], lw=0.9)
    names = ["table angle (encoder) [deg]", "IMU yaw psi_p [deg]", "A_c, A_s [samples]"]
    for a, yl in zip(main, names):
        a.set_ylabel(yl, fontsize=9)
        a.grid(alpha=0.3)
        a.legend(fontsize=7, loc="upper right")
        if zoom:
            a.axvspan(zoom[0] / ts, zoom[1] / ts, color="0.8", lw=0, zorder=0)
    main[-1].set_xlabel(tl)
    main[0].set_title("the whole run" + (" (shaded: the zoom at the right)" if zoom else ""), fontsize=9)
    if sums and len(sums) < len(turning):
        main[2].set_title("A_c, A_s: only the schemes that steer by them", fontsize=9)
    for a in side:
        a.grid(alpha=0.3)
    if zoom:
        side[-1].set_xlabel(zl)
        side[0].set_title("zoom: a few cycles", fontsize=9)
    fig.tight_layout()
    _save(fig, path, plt)
    return True


def plot_comparison(summary, path):
    """Final and maximum horizontal errors per variant, the paper's beside."""
    vs = [v for v in summary["variants"] if "horizontal_error_max" in v["metrics"]]
    if len(vs) < 2:
        return False
    plt = pyplot()
    big = max(v["metrics"]["horizontal_error_max"] for v in vs)
    sc, un = (NMI_TO_M, "nmi") if big > 0.5 * NMI_TO_M else (1.0, "m")
    x = np.arange(len(vs))
    fig, ax = plt.subplots(figsize=(10, 4.5))
    ax.bar(x - 0.25, [v["metrics"]["horizontal_error_final"] / sc for v in vs], 0.25, label="ours, final")
    ax.bar(x, [v["metrics"]["horizontal_error_max"] / sc for v in vs], 0.25, label="ours, max")
    paper, bounds = {}, {}
    for f in (summary.get("paper") or {}).get("figures", []):
        if f["metric"].startswith("horizontal_error") and f.get("variant"):
            # a bound ("<", ">") is drawn as a bound (a line across the variant), a value as a bar
            (paper if f.get("relation") in (None, "", "=", "~") else bounds)[f["variant"]] = (
                f["value_si"] / sc, f.get("relation"))
    caveat = " (for the full-length run: not comparable)" if not_judged(
        [v for v in vs if v["label"] in paper or v["label"] in bounds]) else ""
    if paper:
        ax.bar(x + 0.25, [paper.get(v["label"], (0.0,))[0] for v in vs], 0.25, label="paper" + caveat)
    first = True
    for i, v in enumerate(vs):
        if v["label"] in bounds:
            b, rel = bounds[v["label"]]
            ax.plot([i - 0.4, i + 0.4], [b, b], "k--", lw=1.2,
                    label=f"paper's bound ({rel} the line){caveat}" if first else None)
            ax.plot([i + 0.25], [b], "kv" if rel == "<" else "k^", ms=7)
            first = False
    ax.set_xticks(x, [v["label"] for v in vs], fontsize=8, rotation=10)
    ax.set_ylabel(f"horizontal position error [{un}]")
    ax.grid(alpha=0.3, axis="y")
    ax.legend(fontsize=8)
    fig.tight_layout()
    _save(fig, path, plt)
    return True


# ---------------------------------------------------------------------------
# 2. The tables
# ---------------------------------------------------------------------------
esc = html.escape


def _ours(row):
    return "" if row["ours"] is None else f"{row['ours']:.4g} {row['unit']}"


def _status(v):
    dur = v.get("duration_s")
    if not v.get("complete"):
        done = (f"{span(dur * v.get('ticks_done', 0) / v['ticks'])} of {span(dur)}"
                if dur and v.get("ticks") else f"{v.get('ticks_done', 0)} of {v['ticks']} ticks")
        return f"partial: {done}"
    written = v.get("written_duration_s")
    if dur is not None and written is not None and not_judged([v]):
        return f"{span(dur)} (the scenario: {span(written)})"
    return f"complete, {span(dur)}" if dur else "complete"


def _component_rows(summary, series):
    """Rows (name, description, {label: cell}) of the position error split
    north/east and latitude/longitude: "final / largest |.|"."""
    have = [v["label"] for v in summary["variants"] if v["label"] in series and navigates(series[v["label"]])]
    if not have:
        return []
    ll = {k: latlon_errors(series[k]) for k in have}
    pu, ps = _pos_unit([series[k][c] for k in have for c in ("north_m", "east_m")])
    au, ascale = _angle_unit([a for k in have for a in ll[k]])

    def cell(y, scale, unit):
        return f"{y[-1] / scale:.4g} / {np.abs(y).max() / scale:.4g} {unit}" if len(y) else ""
    return [
        ("north error", "north position error: final / largest |value|",
         {k: cell(series[k]["north_m"], ps, pu) for k in have}),
        ("east error", "east position error: final / largest |value|",
         {k: cell(series[k]["east_m"], ps, pu) for k in have}),
        ("latitude error", "latitude error: final / largest |value| (1 arcmin of latitude = 1 nmi)",
         {k: cell(ll[k][0], ascale, au) for k in have}),
        ("longitude error", "longitude error: final / largest |value|",
         {k: cell(ll[k][1], ascale, au) for k in have}),
    ]


def _aligned_cell(al):
    sigma = al.get("heading_sigma_arcmin")
    return (f"{al['method']}; navigating at {al['time_s']:g} s"
            + (f", heading sigma {sigma:.3g}'" if sigma is not None else ", no heading sigma (no filter)"))


def _results_tables(summary, series):
    """The results: a row per metric, a column per variant, at most
    VARIANTS_PER_TABLE variants a table."""
    variants = summary["variants"]
    metric_names = [k for k in FIGURE_METRICS if any(k in v["metrics"] for v in variants)]
    rows = []
    for k in metric_names:
        unit = display(k, [v["metrics"].get(k) for v in variants])
        rows.append((k, metrics.describe(k),
                     {v["label"]: f"{v['metrics'][k] / unit[1]:.4g} {unit[0]}" for v in variants
                      if k in v["metrics"]}))
    rows += _component_rows(summary, series)
    aligned = {v["label"]: _aligned_cell(v["aligned"]) for v in variants if v.get("aligned")}
    if aligned:
        rows.append(("alignment", "which alignment ran, and the heading sigma it reported as navigation "
                     "began (the navigation filter's, else the fine filter's)", aligned))
    out = []
    for i in range(0, len(variants), VARIANTS_PER_TABLE):
        part = variants[i:i + VARIANTS_PER_TABLE]
        cols = f"<col class='name'>{'<col>' * len(part)}"
        head = "".join(f"<th>{esc(v['label'])}</th>" for v in part)
        status = "".join(f"<td>{esc(_status(v))}</td>" for v in part)
        body = "".join(f"<tr><td title='{esc(desc, quote=True)}'><code>{esc(name)}</code></td>"
                       + "".join(f"<td>{esc(cells.get(v['label'], ''))}</td>" for v in part) + "</tr>"
                       for name, desc, cells in rows)
        out.append(f"<table class='fit results'><colgroup>{cols}</colgroup>"
                   f"<tr><th>metric</th>{head}</tr><tr class='status'><td>run</td>{status}</tr>{body}</table>")
    return "\n".join(out)


def _caveats(summary):
    """Sentences on a run that is not the scenario as written: stopped, or
    run for another length (what the paper's figures then cannot be judged on)."""
    out = [f"Not read: {w}." for w in summary.get("report_warnings", [])]
    out += [f"Note: {n}." for n in summary.get("notes", [])]
    if not summary["complete"]:
        out.append(f"PARTIAL ({summary.get('stopped', 'interrupted')}): the figures and tables cover the "
                   "ticks done; the paper's figures are not judged on a stopped variant.")
    retimed = [v for v in summary["variants"] if v.get("complete") and not_judged([v])]
    if retimed:
        v = retimed[0]
        out.append(f"Run for {span(v['duration_s'])}; the scenario as written runs "
                   f"{span(v['written_duration_s'])}, the length its paper's figures are for: they are "
                   "shown beside ours and not judged.")
    return out


def _paper_html(summary):
    paper = summary.get("paper") or {}
    if not (paper.get("figures") or paper.get("citation")):
        return ""
    prow = "".join(
        f"<tr><td>{esc(r['metric'])}</td><td>{esc(r['variant'] or '')}</td>"
        f"<td>{esc(r['relation'])} {r['paper']:g} {esc(r['unit'])}</td>"
        f"<td>{esc(_ours(r))}</td><td class='{'verdict' if r['judged'] else 'unjudged'}'>{esc(r['verdict'])}</td>"
        f"<td class='note'>{esc(r['note'])}</td></tr>"
        for r in paper_rows(summary))
    cols = "".join(f"<col style='width: {w}%'>" for w in (15, 13, 9, 10, 15, 38))
    return (f"<h2>Beside the paper</h2><p>{esc(paper.get('citation', ''))}</p>"
            f"<p class='note'>{esc(paper.get('note', ''))}</p>"
            f"<table class='fit paper'><colgroup>{cols}</colgroup>"
            "<tr><th>metric</th><th>variant</th><th>paper</th><th>ours</th>"
            f"<th>verdict</th><th>note</th></tr>{prow}</table>")


#: the page's style: at most 1360 px wide, every table as wide as the page
#: with fixed columns whose text wraps, images scaled down: nothing scrolls
#: sideways at 1200-1400 px (tests/cli/test_report_layout.py)
STYLE = """
body { font-family: sans-serif; max-width: 1360px; margin: 1.5em auto; padding: 0 1em; color: #222; }
table.fit { width: 100%; table-layout: fixed; border-collapse: collapse; margin: 1em 0; font-size: 0.88em; }
table.results col.name { width: 16em; }
td, th { border: 1px solid #bbb; padding: 0.25em 0.5em; text-align: right; vertical-align: top;
         overflow-wrap: anywhere; }
td:first-child, th:first-child, table.paper td, table.paper th { text-align: left; }
table.paper td:nth-child(3), table.paper td:nth-child(4) { text-align: right; }
tr.status td { color: #555; font-size: 0.92em; }
td.unjudged { color: #8a5a00; }
.caveat { background: #fff4d6; border-left: 4px solid #e0a800; padding: 0.4em 0.8em; }
figure { margin: 1em 0; } img { max-width: 100%; height: auto; }
.note { color: #555; white-space: pre-wrap; }
pre { background: #f4f4f4; padding: 1em; white-space: pre-wrap; overflow-wrap: anywhere; }
"""


def render(run_dir, loaded=None, progress=None):
    """Write the plots and report.html into ``run_dir``; returns the path.
    ``loaded``: what `load` returned for it (else it is read here);
    ``progress``: a `pyins.progress.Phases` (a line per phase), or None."""
    if loaded is None:
        with phase(progress, "report: reading the records"):
            loaded = load(run_dir)
    summary, series = loaded
    # 1. the figures
    figs = []
    plots = [("errors.png", "Errors against the truth", lambda p: plot_errors(summary, series, p) or True),
             ("alignment.png", "Alignment convergence", lambda p: plot_alignment(summary, series, p)),
             ("table.png", "Turntable angle and IMU heading (zoom: a few cycles)"
              + (", the flexible scheme's sums A_c, A_s" if any(v.get("uses_index_sums") for v in summary["variants"])
                 else ""), lambda p: plot_table(summary, series, p))] if series else []
    if series:
        plots.append(("references.png", "Navigation with external references: the horizontal error and the "
                      "filter's 3-sigma envelope (shaded: no GNSS position in use), the normalised "
                      "innovations and the gate, the mode and the references in use",
                      lambda p: plot_references(summary, series, p)))
    plots.append(("comparison.png", "Scheme comparison", lambda p: plot_comparison(summary, p)))
    with phase(progress, "report: figures"):
        for name, caption, draw in plots:
            path = os.path.join(run_dir, name)
            if draw(path):
                figs.append((name, caption))
            elif os.path.exists(path):          # an older rendering's figure that no longer means anything
                os.remove(path)
    # 2. the results, the group metrics, the paper's figures
    group = "".join(f"<li>{esc(k)}: {val / display(k)[1]:.4g} {display(k)[0]}</li>"
                    for k, val in summary.get("group_metrics", {}).items())
    # 3. the page
    scen_text = ""
    scen_path = os.path.join(run_dir, "scenario.toml")
    if os.path.exists(scen_path):
        with open(scen_path) as f:
            scen_text = f.read()
    status = "complete" if summary["complete"] else f"PARTIAL ({summary.get('stopped', 'interrupted')})"
    caveats = "".join(f"<p class='caveat'>{esc(c)}</p>" for c in _caveats(summary))
    imgs = "".join(f"<figure><img src='{esc(p)}' alt='{esc(c)}'><figcaption>{esc(c)}</figcaption></figure>"
                   for p, c in figs)
    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><meta name="viewport" content="width=device-width, initial-scale=1">
<title>{esc(summary['title'])}</title>
<style>{STYLE}</style></head><body>
<h1>{esc(summary['title'])}</h1>
<p>Scenario <code>{esc(summary['scenario'])}</code>, digest <code>{esc(summary['digest'][:16])}</code>,
core {esc(summary['core_version'])}. Status: {esc(status)}.</p>
{caveats}
<h2>Results</h2>
{_results_tables(summary, series)}
{f'<ul>{group}</ul>' if group else ''}
{_paper_html(summary)}
<h2>Figures</h2>
{imgs}
<h2>Scenario</h2>
<pre>{esc(scen_text)}</pre>
</body></html>
"""
    path = os.path.join(run_dir, "report.html")
    records.write_atomic(path, page, sync=False)
    return path
