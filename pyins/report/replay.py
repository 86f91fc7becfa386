"""A replayed log's page and figures: what ``pyins replay`` writes beside
its records (report.html, attitude.png, alignment.png, errors.png).

Reads only the replay directory (summary.json, navigation.npz), so ``pyins
report DIR`` re-renders it. What a user replaying a field log needs to see:

1. the attitude over the log, the alignment phases shaded;
2. the alignment: the fine filter's sigmas (level in arc-seconds, heading in
   arc-minutes) and its drift estimates; the coarse solution's wander;
3. the errors against a reference when one was given (the scenario's truth,
   or ``--reference parked``: the site and zero velocity), north and east
   apart;
4. report.html: the aligned attitude, the sigmas and drift estimates at the
   end of the fine alignment, the integrity figures and fault bits, the
   warnings, the final state;
5. with external references (``--refs``, ``--zero-velocity``):
   references.png, the navigation mode and the references in use over
   time, each kind's normalised innovation against its gate, and the
   filter's position and heading sigmas; a row per kind on the page (given,
   used, rejected, repeats, before navigation).
"""
import html
import json
import os

import numpy as np

from pyins import contract, logs
from pyins.reference import abi
from pyins.reference.config import DEFAULT_NAV_GATE
from pyins.reference.fine_align import EPS, EPS_NU, PHI
from pyins.report.plotting import MAX_POINTS, envelope, line, pyplot, time_axis
from pyins.units import ARCMIN_TO_RAD, ARCSEC_TO_RAD, DPH_TO_RPS, UG_TO_MPS2

__all__ = ["render", "is_replay", "source_text"]

MODES = {abi.PYINS_MODE_IDLE: "idle", abi.PYINS_MODE_COARSE_ALIGN: "coarse alignment",
          abi.PYINS_MODE_FINE_ALIGN: "fine alignment", abi.PYINS_MODE_NAVIGATE: "navigation"}
_MODES = MODES


def is_replay(summary):
    """True for the summary.json of ``pyins replay`` (it names its log)."""
    return "log" in summary and "samples" in summary


def _shade_phases(ax, t, mode):
    for m, colour in ((abi.PYINS_MODE_COARSE_ALIGN, "0.85"), (abi.PYINS_MODE_FINE_ALIGN, "0.93")):
        on = np.flatnonzero(mode == m)
        if len(on):
            for a in ax:
                a.axvspan(t[on[0]], t[on[-1]], color=colour, lw=0, zorder=0)


def plot_attitude(rec, hz, path):
    plt = pyplot()
    t, tl = time_axis(rec["tick"] / hz)
    fig, ax = plt.subplots(3, 1, figsize=(9, 8), sharex=True)
    _shade_phases(ax, t, rec["mode"])
    line(ax[0], t, np.degrees(rec["euler_b_rad"][:, 0]), lw=0.8)
    line(ax[1], t, np.degrees(rec["euler_b_rad"][:, 1]), lw=0.8)
    line(ax[2], t, np.degrees(rec["heading_b_rad"]), lw=0.8)
    for a, yl in zip(ax, ("pitch [deg]", "roll [deg]", "heading [deg]")):
        a.set_ylabel(yl)
        a.grid(alpha=0.3)
    ax[2].set_xlabel(tl)
    ax[0].set_title("attitude over the log (dark: coarse alignment, light: fine alignment)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def plot_alignment(rec, hz, path):
    """The fine filter's attitude sigmas over the fine alignment; False when
    there was none."""
    fine = rec[rec["mode"] == abi.PYINS_MODE_FINE_ALIGN]
    if not len(fine):
        return False
    plt = pyplot()
    t, tl = time_axis(fine["tick"] / hz)
    sig = fine["kf_sigma"][:, PHI]
    fig, ax = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    line(ax[0], t, sig[:, 0] / ARCSEC_TO_RAD, label="phi_E", log=True)
    line(ax[0], t, sig[:, 1] / ARCSEC_TO_RAD, label="phi_N", log=True)
    ax[0].set_ylabel("level sigma [arcsec]")
    ax[0].legend(fontsize=8)
    line(ax[1], t, sig[:, 2] / ARCMIN_TO_RAD, label="phi_U", log=True)
    ax[1].axhline(10.0, color="k", ls=":", lw=0.8)      # ATT_VALID needs the heading sigma within 10'
    ax[1].set_ylabel("heading sigma [arcmin]")
    ax[1].set_xlabel(tl)
    for a in ax:
        a.grid(alpha=0.3, which="both")
    ax[0].set_title("fine alignment: the filter's attitude sigmas (dotted: 10', where the attitude "
                    "becomes valid)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return True


def plot_errors(err, path):
    """North and east errors against the reference, and the velocity errors
    (a scenario's truth, parked) or the heading error (a truth track)."""
    plt = pyplot()
    t, tl = time_axis(np.asarray(err["time_s"]))
    fig, ax = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    line(ax[0], t, np.asarray(err["north_m"]), label="north")
    line(ax[0], t, np.asarray(err["east_m"]), label="east")
    ax[0].set_ylabel("position error [m]")
    if "vel_n_mps" in err:
        vel = np.asarray(err["vel_n_mps"])
        line(ax[1], t, vel[:, 1], label="north")
        line(ax[1], t, vel[:, 0], label="east")
        ax[1].set_ylabel("velocity error [m/s]")
    elif "heading_rad" in err:         # a truth track with headings
        line(ax[1], t, np.asarray(err["heading_rad"]) / ARCMIN_TO_RAD, label="heading")
        ax[1].set_ylabel("heading error [arcmin]")
    else:                              # a track of positions only
        line(ax[1], t, np.hypot(np.asarray(err["north_m"]), np.asarray(err["east_m"])),
              label="horizontal")
        ax[1].set_ylabel("horizontal error [m]")
    ax[1].set_xlabel(tl)
    for a in ax:
        a.grid(alpha=0.3)
        a.legend(fontsize=8)
    ax[0].set_title(f"errors against {err['reference']}", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def alignment_figures(rec, end=None):
    """The fine alignment's result at its last record (``end``: the record
    that holds its final state, the first of navigation, when there is one):
    attitude sigmas and the drift and bias estimates (in the units of seed
    001's figures)."""
    fine = rec[rec["mode"] == abi.PYINS_MODE_FINE_ALIGN]
    if not len(fine):
        return None
    last = fine[-1] if end is None or not end["kf_states"] else end
    out = dict(states=int(last["kf_states"]), time_s=None,
               sigma_level_arcsec=[float(s / ARCSEC_TO_RAD) for s in last["kf_sigma"][PHI][:2]],
               sigma_heading_arcmin=float(last["kf_sigma"][PHI][2] / ARCMIN_TO_RAD),
               nis=float(last["align_nis"]))
    if last["kf_states"] in (5, 8):
        # the noise density R is built from, and what the coarse phase measured
        # (0: nothing measured; docs/core.md, "Measurement noise of the fine alignment")
        out["r_vrw_ug_sqrt_hz"] = float(last["fine_vrw"] / UG_TO_MPS2)
        out["measured_vrw_ug_sqrt_hz"] = float(last["coarse_vrw"] / UG_TO_MPS2)
    if last["kf_states"] == 5:
        # the reduced filter's eps_N^, eps_U^ (seed 001 eq. 21)
        out["drift_nu_dph"] = [float(x / DPH_TO_RPS) for x in last["kf_x"][EPS_NU][:2]]
    else:
        out["drift_enu_dph"] = [float(x / DPH_TO_RPS) for x in last["kf_x"][EPS]]
    return out


def _row(name, value):
    return f"<tr><th>{html.escape(name)}</th><td>{html.escape(str(value))}</td></tr>"


def source_text(src):
    """What one reference file gave (an entry of the summary's
    ``references.sources``), in one line: the terminal's and the page's."""
    head = f"{src.get('option', '')} {src.get('file', '')}".strip()
    if src.get("format") != "NMEA 0183":
        return f"{head}: " + ", ".join(f"{n} {k}" for k, n in src.get("references", {}).items())
    got = []
    for k, n in src.get("references", {}).items():
        sig = ", ".join(f"{m} {w}" for w, m in src.get("sigmas", {}).get(k, {}).items() if m)
        got.append(f"{n} {k} from {src.get('sentences_used', {}).get(k, '?')}" + (f" (sigma: {sig})" if sig else ""))
    span = src.get("utc_span") or ["?", "?"]
    return f"{head} (NMEA 0183, UTC {span[0]} .. {span[1]}): {', '.join(got) or 'no reference in the log'}"


#: records read at a time (3.5 MB at 432 B): small against the process, so a
#: 6 h and a 72 h page peak alike (a 65,536-record block is 28 MB: the 24 h page
#: peaked 35 % above the 6 h one)
_RECORD_BLOCK = 8192


def _kept(rows, budget):
    """The rows of a block that hold each attitude curve's envelope (pitch,
    roll, heading: `envelope` on each, ``budget`` points a curve) and the
    rows where the mode changes (the phases' shading)."""
    i = np.arange(len(rows))
    curves = (rows["euler_b_rad"][:, 0], rows["euler_b_rad"][:, 1], rows["heading_b_rad"])
    idx = [envelope(i, c, budget)[0] for c in curves]
    change = np.flatnonzero(np.diff(rows["mode"]) != 0)
    idx += [change, change + 1]
    return rows[np.unique(np.concatenate(idx))]


#: the fields references.png draws
_NAV_FIELDS = ("tick", "mode", "nav_mode", "ref_in_use", "nav_nis", "nav_sigma_pos_m", "nav_sigma_heading_rad")


def _nav_kept(rows, budget):
    """Of a block's navigation records, those that hold the envelope of each
    kind's NIS and of the sigmas, and every change of mode or references in
    use, in the fields references.png draws."""
    rows = rows[rows["mode"] == abi.PYINS_MODE_NAVIGATE]
    if not len(rows):
        return np.zeros(0, dtype=[(f, rows.dtype[f]) for f in _NAV_FIELDS])
    i = np.arange(len(rows))
    curves = [rows["nav_nis"][:, k] for k in range(rows["nav_nis"].shape[1])]
    curves += [rows["nav_sigma_pos_m"], rows["nav_sigma_heading_rad"]]
    idx = [envelope(i, c, budget)[0] for c in curves]
    change = np.flatnonzero((np.diff(rows["nav_mode"]) != 0) | (np.diff(rows["ref_in_use"]) != 0))
    idx += [change, change + 1, [0, len(rows) - 1]]
    keep = rows[np.unique(np.concatenate(idx).astype(np.int64))]
    out = np.zeros(len(keep), dtype=[(f, rows.dtype[f]) for f in _NAV_FIELDS])
    for f in _NAV_FIELDS:
        out[f] = keep[f]
    return out


def plot_references(nav, hz, kinds, gate, path):
    """The navigation with references: the mode and the references in use,
    each used kind's NIS with the gate, the filter's sigmas."""
    plt = pyplot()
    t, tl = time_axis(nav["tick"] / hz)
    fig, ax = plt.subplots(3, 1, figsize=(9, 8), sharex=True)
    slots = {name: abi_kind - 1 for name, abi_kind in kinds.items()}
    rows = [("integrated", (nav["nav_mode"] == abi.PYINS_NAV_INTEGRATED).astype(float)),
            ("damped", (nav["nav_mode"] == abi.PYINS_NAV_DAMPED).astype(float))]
    rows += [(f"{name} in use", ((nav["ref_in_use"] >> s) & 1).astype(float))
             for name, s in sorted(slots.items(), key=lambda kv: kv[1])]
    for j, (label, on) in enumerate(rows):      # one lane each: up while on
        ax[0].step(t, on * 0.6 + j, where="post", lw=1.2, color="k" if j < 2 else f"C{j - 2}")
    ax[0].set_yticks([j + 0.3 for j in range(len(rows))], [label for label, _ in rows], fontsize=8)
    ax[0].set_ylim(-0.3, len(rows))
    for name, s in sorted(slots.items(), key=lambda kv: kv[1]):
        nis = nav["nav_nis"][:, s]
        ok = nis > 0.0
        if ok.any():
            ax[1].semilogy(t[ok], nis[ok], ".", ms=2, label=f"{name} NIS")
    ax[1].axhline(gate, color="r", lw=0.8, ls="--", label=f"gate {gate:.4g}")
    ax[1].set_ylabel("normalised innovation")
    line(ax[2], t, nav["nav_sigma_pos_m"], label="position sigma [m]")
    ax2 = ax[2].twinx()
    ax2.plot(t, nav["nav_sigma_heading_rad"] / ARCMIN_TO_RAD, color="C1", lw=0.8, label="heading sigma [']")
    ax2.set_ylabel("heading sigma [arcmin]")
    ax[2].set_ylabel("position sigma [m]")
    ax[2].set_xlabel(tl)
    for a in ax:
        a.grid(alpha=0.3)
    for a in ax[1:]:
        a.legend(fontsize=8, loc="upper right")
    ax2.legend(fontsize=8, loc="center right")
    ax[0].set_title("navigation with external references: the mode and the references in use (up: on)",
                    fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def _records(path):
    """The records the figures draw, read in blocks (`pyins.logs.iter_npz`), so
    the page of a 72 h replay does not hold its 259,200 records (112 MB):
    of each block the rows that keep every attitude curve's peaks (its
    share of MAX_POINTS a curve; plot_attitude's envelope of them is the
    whole log's), and every fine-alignment record."""
    n = logs.npz_shape(path, "outputs")[0]
    kept, fine, nav = [], [], []
    for rows in logs.iter_npz(path, "outputs", block=_RECORD_BLOCK):
        budget = max(16, MAX_POINTS * len(rows) // max(n, 1))
        kept.append(_kept(rows, budget).copy())
        fine.append(rows[rows["mode"] == abi.PYINS_MODE_FINE_ALIGN].copy())
        if "nav_nis" in rows.dtype.names:   # (records of ABI 0.15 on)
            nav.append(_nav_kept(rows, budget))
    if not kept:                        # no record: the empty array as it is
        with np.load(path, allow_pickle=False) as z:
            rec = z["outputs"]
        return rec, rec, None
    return np.concatenate(kept), np.concatenate(fine), np.concatenate(nav) if nav else None


def render(out_dir):
    """Figures and report.html of a replay directory; returns the page's path."""
    with open(os.path.join(out_dir, "summary.json")) as f:
        summary = json.load(f)
    for part in ("aligned", "final", "errors", "fine_alignment"):     # a null figure (NaN) prints as nan
        if isinstance(summary.get(part), dict):
            summary[part] = {k: (float("nan") if v is None and k != "time_s" else
                                 [float("nan") if x is None else x for x in v] if isinstance(v, list) else v)
                             for k, v in summary[part].items()}
    rec, fine, nav = _records(os.path.join(out_dir, "navigation.npz"))
    hz = summary.get("rate_hz", 100)
    figures = []
    if len(rec):
        plot_attitude(rec, hz, os.path.join(out_dir, "attitude.png"))
        figures.append("attitude.png")
        if plot_alignment(fine, hz, os.path.join(out_dir, "alignment.png")):
            figures.append("alignment.png")
    refs = summary.get("references") if isinstance(summary.get("references"), dict) else None
    if refs and nav is not None and len(nav):
        kinds = {name: contract.REF_KINDS[name] for name in refs.get("kinds", {}) if name in contract.REF_KINDS}
        plot_references(nav, hz, kinds, refs.get("gate", DEFAULT_NAV_GATE), os.path.join(out_dir, "references.png"))
        figures.append("references.png")
    errors_path = os.path.join(out_dir, "errors.npz")
    if os.path.exists(errors_path):
        with np.load(errors_path, allow_pickle=False) as z:
            err = {k: z[k] for k in z.files}
        err["reference"] = summary.get("errors", {}).get("reference", "the reference")
        plot_errors(err, os.path.join(out_dir, "errors.png"))
        figures.append("errors.png")

    rows = [_row("log", summary.get("log")), _row("samples", f"{summary['samples']} at {hz} Hz")]
    al = summary.get("aligned")
    if al:
        rows.append(_row("aligned attitude", f"at {al['time_s']:g} s: pitch {al['pitch_deg']:.4f} deg, "
                                             f"roll {al['roll_deg']:.4f} deg, heading {al['heading_deg']:.4f} deg"))
        if al.get("method"):
            sig = al.get("heading_sigma_arcmin")
            rows.append(_row("alignment", al["method"] + (f"; heading sigma {sig:.2f} arcmin as navigation began"
                                                          if sig is not None else "; heading sigma: none estimated")))
    fa = summary.get("fine_alignment")
    if fa:
        lvl = ", ".join(f"{s:.2f}" for s in fa["sigma_level_arcsec"])
        rows.append(_row("fine alignment at its end",
                         f"{fa['states']} states; level sigma {lvl} arcsec; heading sigma "
                         f"{fa['sigma_heading_arcmin']:.2f} arcmin; mean NIS {fa['nis']:.2f} (2 fits)"))
        if "r_vrw_ug_sqrt_hz" in fa:
            measured = fa["measured_vrw_ug_sqrt_hz"]
            source = ("the noise the coarse phase measured (vibration included)"
                      if measured > 0.0 and fa["r_vrw_ug_sqrt_hz"] == measured
                      else "the configured density" + (f" (measured {measured:.1f}, below it)" if measured > 0.0 else ""))
            rows.append(_row("measurement noise R", f"{fa['r_vrw_ug_sqrt_hz']:.1f} ug/sqrt(Hz): {source}"))
        if "drift_enu_dph" in fa:
            rows.append(_row("drift estimate E, N, U [deg/h]", ", ".join(f"{d:.4f}" for d in fa["drift_enu_dph"])))
        if "drift_nu_dph" in fa:
            rows.append(_row("drift estimate N, U [deg/h] (reduced filter)",
                             ", ".join(f"{d:.4f}" for d in fa["drift_nu_dph"])))
    fin = summary["final"]
    faults = abi.fault_names(fin["fault_flags"])
    rows.append(_row("final", f"{MODES.get(fin['mode'], fin['mode'])}; {fin['lat_deg']:.6f} N "
                              f"{fin['lon_deg']:.6f} E; faults: {', '.join(faults) or 'none'}"))
    for src in (refs or {}).get("sources", ()):
        rows.append(_row("reference file", source_text(src)))
    for name, k in (refs or {}).get("kinds", {}).items():
        rows.append(_row(f"references {name}",
                         f"{k['given']} given, {k['used']} used, {k['rejected']} rejected by the gate, "
                         f"{k['stale']} repeats unused, {k['skipped']} before navigation, "
                         f"{k['after_end']} after the log's end"))
    er = summary.get("errors")
    if er and summary.get("navigating_records") == 0:
        rows.append(_row(f"against {er.get('reference', 'the truth')}",
                         "nothing compared: no record is of navigation (the alignment, which holds the site, "
                         "covered the whole log)"))
    elif er:
        rows.append(_row(f"against {er.get('reference', 'the truth')}",
                         f"max horizontal {er['horizontal_max_m']:.2f} m, final {er['horizontal_final_m']:.2f} m"))
    warn = "".join(f"<li>{html.escape(w)}</li>" for w in summary.get("warnings", ()))
    page = ["<!doctype html><html><head><meta charset='utf-8'><title>pyins replay</title>",
            "<style>body{font-family:sans-serif;max-width:1200px;margin:1em auto}"
            "table{border-collapse:collapse}th,td{border:1px solid #ccc;padding:4px 8px;text-align:left}"
            "img{max-width:100%}.warn{color:#a00}</style></head><body>",
            f"<h1>Replay of {html.escape(os.path.basename(str(summary.get('log'))))}"
            + (" &mdash; PARTIAL: interrupted before the log's end" if summary.get("complete") is False else "")
            + "</h1>",
            f"<ul class='warn'>{warn}</ul>" if warn else "<p>No warnings: the figures below can be trusted "
            "as far as the firmware can tell.</p>",
            "<table>", *rows, "</table>",
            *[f"<p><img src='{f}' alt='{f}'></p>" for f in figures], "</body></html>"]
    path = os.path.join(out_dir, "report.html")
    with open(path, "w", encoding="utf-8") as f:
        f.write("\n".join(page))
    return path
