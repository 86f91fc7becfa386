"""Run a scenario into a run directory: what ``pyins run`` does.

A run directory holds::

    scenario.toml              the scenario as written (built-ins: their file)
    resolved_scenario.json     every value in SI units, as run
    summary.json               per variant: metrics (SI, units in the names),
                               ticks done, wall time; the paper's figures
    <variant>/records/         the firmware and plant records (fil.run_fil
                               record_dir: raw binary, checkpoints)
    <variant>/timeseries.npz   the records and the errors against the truth
    <variant>/timeseries.csv   the errors, at most CSV_MAX_ROWS rows
    *.png, report.html         written by pyins.report

Runs are checkpointed (every CHECKPOINT_S of ship time): ``execute(...,
resume=True)`` after a kill or Ctrl-C continues each unfinished variant from
its last checkpoint and skips the finished ones. Ctrl-C leaves a valid partial
result: summary.json then says ``"complete": false`` and the metrics cover
the ticks done.
"""
import json
import os
import re
import shutil
import time

import numpy as np

from pyins import analysis, fil, native, runner, sim
from pyins.reference import earth

CHECKPOINT_S = 1800.0          # ship time between checkpoints: 30 min = 180,000 ticks
CSV_MAX_ROWS = 20_000
SUMMARY = "summary.json"


def slug(label):
    """A directory name for a variant label."""
    s = re.sub(r"[^A-Za-z0-9._-]+", "_", label).strip("_")
    return s or "run"


def _truth_result(spec, outputs, plant):
    truth = sim.truth_at(spec.motion, np.asarray(outputs["tick"]), dt=spec.dt)
    return fil.FilResult(outputs=outputs, plant=plant, truth=truth, dt=spec.dt)


def metrics(spec, res):
    """The METRICS of pyins.scenario one run gives (SI units)."""
    m = {}
    if len(res.outputs) == 0:
        return m
    e = runner.nav_errors(res)
    level = np.abs(e.att_n_rad[:, :2]).max(axis=1)
    m.update(horizontal_error_final=float(e.horizontal_m[-1]),
             horizontal_error_max=float(e.horizontal_m.max()),
             level_error_final=float(level[-1]), level_error_max=float(level.max()),
             heading_error_final=float(abs(e.att_n_rad[-1, 2])),
             heading_error_max=float(np.abs(e.att_n_rad[:, 2]).max()),
             velocity_error_max=float(np.abs(e.vel_n_mps[:, :2]).max()),
             phi_e_final=float(e.att_n_rad[-1, 0]), phi_n_final=float(e.att_n_rad[-1, 1]),
             phi_u_final=float(e.att_n_rad[-1, 2]))
    if spec.config.get("coarse_ticks", 0) or spec.config.get("fine_ticks", 0):
        # an alignment's errors against the theoretical limit at the final
        # true attitude (seed 001 eq. 21; the papers compare with their own
        # fine alignment, which shares this unobservable part)
        lim = analysis.alignment_limits(float(res.truth.lat[-1]), res.truth.euler[-1],
                                        spec.errors.gyro_bias, spec.errors.accel_bias)
        d = e.att_n_rad[-1] - lim.phi_n
        m.update(level_error_vs_limit_final=float(np.abs(d[:2]).max()),
                 heading_error_vs_limit_final=float(abs(d[2])))
    fine = spec.config.get("fine_ticks", 0)
    if fine and isinstance(spec.motion, sim.Static):
        # seed 001: the filter's errors beside the theoretical limits (analysis)
        st = spec.motion.state(np.array([0.0]))
        lim = analysis.alignment_limits(float(st.lat[0]), st.euler[0], spec.errors.gyro_bias,
                                        spec.errors.accel_bias)
        out = res.outputs
        if spec.config.get("fine_states", 8) == 5:
            eps = np.array([0.0, out["kf_x"][-1, 3], out["kf_x"][-1, 4]])
        else:
            eps = np.asarray(out["kf_x"][-1, 3:6])
        eps_err = lim.eps_n - eps
        m.update(att_east_gap_final=float(abs(e.att_n_rad[-1, 0] - lim.phi_n[0])),
                 att_up_gap_final=float(abs(e.att_n_rad[-1, 2] - lim.phi_n[2])),
                 drift_north_gap_final=float(abs(eps_err[1] - lim.eps_n_limit[1])))
    return m


def group_metrics(variants):
    """Metrics over the variants of one scenario (seeds, headings): the std of
    the final attitude errors (seed 000's Table 1 std)."""
    finals = np.array([[v["metrics"][k] for k in ("phi_e_final", "phi_n_final", "phi_u_final")]
                       for v in variants if "phi_e_final" in v["metrics"]])
    if len(finals) < 2:
        return {}
    sd = finals.std(axis=0, ddof=1)
    return {"level_error_std": float(sd[:2].max()), "heading_error_std": float(sd[2])}


def _write_timeseries(vdir, res):
    e = runner.nav_errors(res)
    out = np.asarray(res.outputs)
    np.savez(os.path.join(vdir, "timeseries.npz"), time_s=e.time_s, north_m=e.north_m, east_m=e.east_m,
             horizontal_m=e.horizontal_m, vel_err_n_mps=e.vel_n_mps, att_err_n_rad=e.att_n_rad,
             outputs=out, plant=np.asarray(res.plant))
    step = max(1, -(-len(out) // CSV_MAX_ROWS))
    k = np.arange(0, len(out), step)
    cols = np.column_stack([e.time_s[k], e.north_m[k], e.east_m[k], e.horizontal_m[k],
                            e.vel_n_mps[k], e.att_n_rad[k] / earth.ARCSEC_TO_RAD,
                            out["table_angle_rad"][k], out["yaw_p_rad"][k], out["mode"][k]])
    np.savetxt(os.path.join(vdir, "timeseries.csv"), cols, delimiter=",", fmt="%.10g",
               header="time_s,north_m,east_m,horizontal_m,vel_err_e_mps,vel_err_n_mps,vel_err_u_mps,"
                      "att_err_e_arcsec,att_err_n_arcsec,att_err_u_arcsec,table_angle_rad,yaw_p_rad,mode",
               comments="")


def load_variant(run_dir, spec):
    """A variant's records (complete or partial) as a FilResult, or None."""
    rdir = os.path.join(run_dir, slug(spec.label), "records")
    if not os.path.exists(os.path.join(rdir, "records.json")):
        return None, None
    outputs, plant, info = fil.load_records(rdir)
    return _truth_result(spec, outputs, plant), info


def execute(scn, run_dir, progress=None, resume=False, log=None):
    """Run every variant of ``scn`` (a pyins.scenario.Scenario) into
    ``run_dir``; returns the summary dict (also written to summary.json).

    ``progress(label)`` returns a callable progress(done, total) per variant
    (e.g. ``lambda label: fil.TextProgress()``); ``log(text)`` gets one line
    per finished variant. KeyboardInterrupt is caught: the summary of what was
    done is written (``complete: false``) and the interrupt re-raised.
    """
    os.makedirs(run_dir, exist_ok=True)
    src = scn.source if scn.source and os.path.exists(str(scn.source)) else None
    with open(os.path.join(run_dir, "scenario.toml"), "w") as f:
        f.write(scn.text)
    with open(os.path.join(run_dir, "resolved_scenario.json"), "w") as f:
        f.write(scn.resolved_json())
    summary = dict(scenario=scn.name, title=scn.title, source=str(scn.source) if src else scn.source,
                   digest=scn.digest(), core_version=native.version(), paper=scn.paper, variants=[],
                   complete=False)
    interrupted = None
    for spec in scn.runs():
        vdir = os.path.join(run_dir, slug(spec.label))
        rdir = os.path.join(vdir, "records")
        if not resume and os.path.exists(vdir):
            shutil.rmtree(vdir)
        os.makedirs(vdir, exist_ok=True)
        t0 = time.perf_counter()
        entry = dict(label=spec.label, dir=slug(spec.label), ticks=spec.duration_ticks)
        try:
            if interrupted is None:
                spec.run(record_dir=rdir, resume=resume,
                         checkpoint_ticks=int(round(CHECKPOINT_S / spec.dt)),
                         chunk_ticks=min(500_000, int(round(CHECKPOINT_S / spec.dt))),
                         progress=progress(spec.label) if progress else None)
        except KeyboardInterrupt as exc:
            interrupted = exc
        res, info = load_variant(run_dir, spec)
        entry["wall_s"] = time.perf_counter() - t0
        entry["ticks_done"] = int(info["ticks_done"]) if info else 0
        entry["complete"] = bool(info and info.get("complete"))
        entry["metrics"] = metrics(spec, res) if res is not None else {}
        if res is not None and len(res.outputs):
            _write_timeseries(vdir, res)
        summary["variants"].append(entry)
        if log is not None and interrupted is None:
            mm = entry["metrics"]
            log(f"  {spec.label}: {entry['ticks_done'] * spec.dt / 3600:.3g} h, "
                f"max horizontal error {mm.get('horizontal_error_max', float('nan')):.1f} m, "
                f"heading error {mm.get('heading_error_final', float('nan')) / earth.ARCMIN_TO_RAD:.3g}' "
                f"({entry['wall_s']:.1f} s)")
    summary["group_metrics"] = group_metrics(summary["variants"])
    summary["complete"] = all(v["complete"] for v in summary["variants"])
    tmp = os.path.join(run_dir, SUMMARY + ".tmp")
    with open(tmp, "w") as f:
        json.dump(summary, f, indent=2)
    os.replace(tmp, os.path.join(run_dir, SUMMARY))
    if interrupted is not None:
        raise interrupted
    return summary


def paper_rows(summary):
    """The paper's figures beside ours: (metric, variant, relation, paper value,
    unit, our value in the paper's unit, verdict) for the report and the CLI."""
    from pyins import scenario as scenario_mod
    rows = []
    paper = summary.get("paper") or {}
    for fig in paper.get("figures", []):
        metric = fig["metric"]
        targets = [v for v in summary["variants"] if fig.get("variant") in (None, v["label"])]
        if metric in summary.get("group_metrics", {}):
            ours = [("all", summary["group_metrics"][metric])]
        else:
            ours = [(v["label"], v["metrics"].get(metric)) for v in targets]
        for label, val in ours:
            mine = None if val is None else scenario_mod.in_figure_unit(val, fig)
            verdict = ""
            if mine is not None and fig["relation"] == "<":
                verdict = "within" if mine < fig["value"] else "above"
            elif mine is not None and fig["value"]:
                verdict = f"x{mine / fig['value']:.2f}"
            rows.append(dict(metric=metric, variant=label, relation=fig["relation"], paper=fig["value"],
                             unit=fig["unit"], ours=mine, verdict=verdict, note=fig.get("note", "")))
    return rows
