"""Running: a scenario into a run directory (what ``pyins run`` does), one
run of a scenario, and a recorded IMU log through the firmware (``pyins
replay``).

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

Every entry point takes ``engine``: "native" (the compiled firmware and
plant) or "reference" (their NumPy mirrors, `pyins.engine`).
"""
import json
import os
import re
import shutil
import time

import numpy as np

from pyins import engine as engines
from pyins import fil, metrics, native, records, runner, scenario, sim
from pyins.metrics import group_metrics
from pyins.records import CSV_MAX_ROWS
from pyins.reference import abi
from pyins.reference.fine_align import PHI
from pyins.reference.firmware import VALID_HEADING_SIGMA
from pyins.units import ARCMIN_TO_RAD, ARCSEC_TO_RAD, TICK_HZ

__all__ = ["execute", "run", "replay", "replay_config", "load_variant", "paper_rows", "slug",
           "group_metrics", "CHECKPOINT_S", "CSV_MAX_ROWS", "SUMMARY"]

CHECKPOINT_S = 1800.0          # ship time between checkpoints: 30 min = 180,000 ticks
SUMMARY = "summary.json"


def slug(label):
    """A directory name for a variant label."""
    s = re.sub(r"[^A-Za-z0-9._-]+", "_", label).strip("_")
    return s or "run"


def run(spec, engine="native", **kwargs):
    """One run of a scenario (a pyins.scenario.RunSpec) through the firmware
    in the loop; ``kwargs`` go to ``fil.run_fil`` (record_dir, resume,
    progress, ...). Returns a records.FilResult."""
    return fil.run_fil(spec.motion, spec.duration_ticks, config=spec.config, errors=spec.errors,
                       seed=spec.seed, table=spec.table, every=spec.every, dt=spec.dt, engine=engine,
                       **kwargs)


def load_variant(run_dir, spec):
    """A variant's records (complete or partial) as a FilResult beside its
    records.json info, or (None, None)."""
    return records.load_variant(os.path.join(run_dir, slug(spec.label), "records"), spec.motion, spec.dt)


def execute(scn, run_dir, progress=None, resume=False, log=None, engine="native"):
    """Run every variant of ``scn`` (a pyins.scenario.Scenario) into
    ``run_dir``; returns the summary dict (also written to summary.json).

    ``progress(label)`` returns a callable progress(done, total) per variant
    (e.g. ``lambda label: TextProgress()``); ``log(text)`` gets one line per
    finished variant. KeyboardInterrupt is caught: the summary of what was
    done is written (``complete: false``) and the interrupt re-raised.
    """
    # the guarded prefix
    engines.check(engine)

    # 1. the run directory: the scenario as written and as resolved
    os.makedirs(run_dir, exist_ok=True)
    src = scn.source if scn.source and os.path.exists(str(scn.source)) else None
    with open(os.path.join(run_dir, "scenario.toml"), "w") as f:
        f.write(scn.text)
    with open(os.path.join(run_dir, "resolved_scenario.json"), "w") as f:
        f.write(scn.resolved_json())
    summary = dict(scenario=scn.name, title=scn.title, source=str(scn.source) if src else scn.source,
                   digest=scn.digest(), core_version=native.version(), paper=scn.paper, variants=[],
                   complete=False)
    if engine != "native":
        summary["engine"] = engine

    # 2. each variant: the checkpointed run, its records, metrics and time series
    interrupted = None
    for spec in scn.runs():
        vdir = os.path.join(run_dir, slug(spec.label))
        if not resume and os.path.exists(vdir):
            shutil.rmtree(vdir)
        os.makedirs(vdir, exist_ok=True)
        t0 = time.perf_counter()
        entry = dict(label=spec.label, dir=slug(spec.label), ticks=spec.duration_ticks)
        try:
            if interrupted is None:
                checkpoint = int(round(CHECKPOINT_S / spec.dt))
                run(spec, engine, record_dir=os.path.join(vdir, "records"), resume=resume,
                    checkpoint_ticks=checkpoint, chunk_ticks=min(500_000, checkpoint),
                    progress=progress(spec.label) if progress else None)
        except KeyboardInterrupt as exc:
            interrupted = exc
        res, info = load_variant(run_dir, spec)
        entry["wall_s"] = time.perf_counter() - t0
        entry["ticks_done"] = int(info["ticks_done"]) if info else 0
        entry["complete"] = bool(info and info.get("complete"))
        entry["metrics"] = metrics.run_metrics(spec, res) if res is not None else {}
        if res is not None and len(res.outputs):
            records.write_timeseries(vdir, res)
        summary["variants"].append(entry)
        if log is not None and interrupted is None:
            mm = entry["metrics"]
            log(f"  {spec.label}: {entry['ticks_done'] * spec.dt / 3600:.3g} h, "
                f"max horizontal error {mm.get('horizontal_error_max', float('nan')):.1f} m, "
                f"heading error {mm.get('heading_error_final', float('nan')) / ARCMIN_TO_RAD:.3g}' "
                f"({entry['wall_s']:.1f} s)")

    # 3. the summary, over the variants
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
            mine = None if val is None else scenario.in_figure_unit(val, fig)
            verdict = ""
            if mine is not None and fig["relation"] == "<":
                verdict = "within" if mine < fig["value"] else "above"
            elif mine is not None and fig["value"]:
                verdict = f"x{mine / fig['value']:.2f}"
            rows.append(dict(metric=metric, variant=label, relation=fig["relation"], paper=fig["value"],
                             unit=fig["unit"], ours=mine, verdict=verdict, note=fig.get("note", "")))
    return rows


# ---------------------------------------------------------------------------
# Replaying a recorded IMU log
# ---------------------------------------------------------------------------
def replay_config(spec):
    """The firmware configuration replaying a log of ``spec`` (a RunSpec)
    starts from: its initial state and settings, without indexing (a log's
    table angles are recorded: the firmware commands nothing)."""
    cfg = scenario.initial_config(spec.motion, None, **spec.config)
    cfg["index_scheme"] = 0
    return cfg


_FAULT_NAMES = {v: k[len("PYINS_FAULT_"):] for k, v in vars(abi).items()
                if k.startswith("PYINS_FAULT_") and isinstance(v, int)}


def _replay_warnings(recs, aligning, hz):
    """What a replay's figures cannot be trusted for, in words: a log that
    ended before the alignment did, an attitude the firmware does not call
    valid, fault bits."""
    out = []
    last = recs[-1]
    t = float(last["tick"] / hz)
    if aligning and last["mode"] != abi.PYINS_MODE_NAVIGATE:
        phase = {abi.PYINS_MODE_COARSE_ALIGN: "coarse", abi.PYINS_MODE_FINE_ALIGN: "fine"}.get(
            int(last["mode"]), "the")
        out.append(f"the log ended during {phase} alignment (at {t:g} s): no aligned attitude")
    if not last["state_flags"] & abi.PYINS_STATE_ATT_VALID:
        integrity = abi.PYINS_FAULT_ALIGN_INCONSISTENT | abi.PYINS_FAULT_COARSE_UNSETTLED
        heading_sigma = float(last["kf_sigma"][PHI][2]) if last["kf_states"] else 0.0
        if int(last["fault_flags"]) & integrity:
            why = "an integrity test failed: the measurements do not fit the alignment's model"
        elif heading_sigma > VALID_HEADING_SIGMA:
            why = (f"the fine alignment left a heading sigma of {heading_sigma / ARCMIN_TO_RAD:.1f}', above "
                   f"{VALID_HEADING_SIGMA / ARCMIN_TO_RAD:g}': align longer")
        elif aligning:
            why = "the alignment had not ended"
        else:
            why = "it is the configured guess"
        out.append(f"the attitude at the end ({t:g} s) is not valid (ATT_VALID unset): {why}")
    faults = [name for bit, name in sorted(_FAULT_NAMES.items()) if bit and int(last["fault_flags"]) & bit]
    if faults:
        out.append("fault bits set: " + ", ".join(faults))
    return out


def replay(data, cfg, out_dir, every=100, spec=None, engine="native", log_path=None):
    """Run a recorded IMU log (``data``: a pyins.sim.io.ImuData) through the
    firmware configured by ``cfg`` into ``out_dir``: navigation.npz (the
    records every ``every`` samples) and summary.json (the final state and,
    with the ``spec`` the log was simulated from, the errors against its
    truth). Returns the summary dict."""
    # the guarded prefix
    engines.check(engine)
    every = max(1, int(every))

    # 1. the log through the firmware
    fw = engines.firmware(engine, cfg)
    samples = native.make_samples(np.ascontiguousarray(data.dtheta_p), np.ascontiguousarray(data.dv_p),
                                  np.ascontiguousarray(data.table_angle_rad))
    os.makedirs(out_dir, exist_ok=True)
    recs = fw.run(samples, every=every)
    np.savez(os.path.join(out_dir, "navigation.npz"), outputs=recs)

    # 2. the final state, and the errors against the truth when it is known
    summary = dict(log=os.path.abspath(log_path) if log_path else None, samples=int(len(samples)),
                   every=every,
                   final=dict(lat_deg=float(np.degrees(recs["lat_rad"][-1])),
                              lon_deg=float(np.degrees(recs["lon_rad"][-1])),
                              euler_deg=np.degrees(recs["euler_b_rad"][-1]).tolist(),
                              mode=int(recs["mode"][-1]), fault_flags=int(recs["fault_flags"][-1])))
    hz = cfg.get("tick_hz") or TICK_HZ
    aligning = cfg.get("coarse_ticks", 0) > 0 or cfg.get("fine_ticks", 0) > 0
    nav = np.flatnonzero(recs["mode"] == abi.PYINS_MODE_NAVIGATE)
    if aligning and len(nav):
        k = nav[0]
        pitch, roll, yaw = np.degrees(recs["euler_b_rad"][k])
        summary["aligned"] = dict(time_s=float(recs["tick"][k] / hz), pitch_deg=float(pitch),
                                  roll_deg=float(roll), heading_deg=float(np.mod(-yaw, 360.0)))
    summary["warnings"] = _replay_warnings(recs, aligning, hz)
    if spec is not None:
        truth = sim.truth_at(spec.motion, recs["tick"], dt=spec.dt)
        e = metrics.nav_errors(runner.RunResult(outputs=recs, truth=truth, dt=spec.dt))
        summary["errors"] = dict(horizontal_max_m=float(e.horizontal_m.max()),
                                 horizontal_final_m=float(e.horizontal_m[-1]),
                                 heading_final_arcmin=float(e.att_n_rad[-1, 2] / ARCMIN_TO_RAD),
                                 level_max_arcsec=float(np.abs(e.att_n_rad[:, :2]).max() / ARCSEC_TO_RAD))
    with open(os.path.join(out_dir, "summary.json"), "w") as f:
        json.dump(summary, f, indent=2)
    return summary
