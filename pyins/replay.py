"""A recorded IMU log through the firmware (what ``pyins replay`` does).

`replay` is a guarded prefix, then named steps:

1. the log through the firmware, one record every ``every`` samples
   (navigation.npz);
2. what the run says: the final state, the attitude at the end of the
   alignment, the fine alignment's sigmas and drift estimates, and the
   warnings for anything its figures cannot be trusted for (`warnings`);
3. the errors against a reference when there is one: the truth of the
   scenario the log was simulated from, or ``reference="parked"`` (the
   configured site and zero velocity: a vehicle or a ship at the pier that
   did not move), north and east apart (errors.npz);
4. summary.json; the page and figures are `pyins.report.replay`.

The CLI checks the user's options before any of this (the rate, an
attitude someone gave, the firmware's limits: `pyins.__main__`,
`pyins.limits`).
"""
import json
import os

import numpy as np

from pyins import engine as engines
from pyins import metrics, native, runner, scenario, sim
from pyins.reference import abi
from pyins.reference.fine_align import PHI
from pyins.reference.firmware import VALID_HEADING_SIGMA
from pyins.report.replay import alignment_figures
from pyins.units import ARCMIN_TO_RAD, ARCSEC_TO_RAD, TICK_HZ

__all__ = ["replay", "replay_config", "warnings", "REFERENCES"]

#: the references a log's errors can be taken against without a scenario
REFERENCES = ("parked",)

def replay_config(spec):
    """The firmware configuration replaying a log of ``spec`` (a RunSpec)
    starts from: its initial state and settings, without indexing (a log's
    table angles are recorded: the firmware commands nothing)."""
    cfg = scenario.initial_config(spec.motion, None, **spec.config)
    cfg["index_scheme"] = 0
    return cfg


def warnings(recs, aligning, hz):
    """What a replay's figures cannot be trusted for, in words: a log that
    ended before the alignment did, an attitude the firmware does not call
    valid (and why), fault bits."""
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
    faults = abi.fault_names(last["fault_flags"])
    if faults:
        out.append("fault bits set: " + ", ".join(faults))
    return out


def _parked_errors(recs, cfg, hz):
    """Errors against the configured site and zero velocity (a parked
    vehicle): `pyins.metrics.nav_errors` against a static truth at the site
    (its attitude errors mean nothing here and are not kept)."""
    site = sim.Static(cfg["lat_rad"], cfg["lon_rad"], cfg.get("height_m", 0.0))
    dt = 1.0 / hz
    e = metrics.nav_errors(runner.RunResult(outputs=recs, truth=sim.truth_at(site, recs["tick"], dt=dt), dt=dt))
    return dict(time_s=e.time_s, north_m=e.north_m, east_m=e.east_m, vel_n_mps=e.vel_n_mps)


def replay(data, cfg, out_dir, every=TICK_HZ, spec=None, engine="native", log_path=None, reference=None):
    """Run a recorded IMU log (``data``: a pyins.sim.io.ImuData) through the
    firmware configured by ``cfg`` into ``out_dir`` and return the summary
    dict (also summary.json). ``spec``: the RunSpec the log was simulated
    from (its truth is the reference); ``reference="parked"``: the site and
    zero velocity."""
    # the guarded prefix
    engines.check(engine)
    every = max(1, int(every))
    if reference is not None and reference not in REFERENCES:
        raise ValueError(f"reference: {reference!r} is not one of {', '.join(REFERENCES)}")
    hz = cfg.get("tick_hz") or TICK_HZ

    # 1. the log through the firmware
    fw = engines.firmware(engine, cfg)
    samples = native.make_samples(data.dtheta_p, data.dv_p, data.table_angle_rad)
    os.makedirs(out_dir, exist_ok=True)
    recs = fw.run(samples, every=every)
    if not len(recs):
        raise ValueError(f"{log_path or 'the log'}: {len(samples)} samples, fewer than one record "
                         f"interval ({every} samples): nothing to report (a smaller --every, or a longer log)")
    np.savez(os.path.join(out_dir, "navigation.npz"), outputs=recs)

    # 2. what the run says
    summary = dict(log=os.path.abspath(log_path) if log_path else None, samples=int(len(samples)),
                   rate_hz=int(hz), every=every,
                   final=dict(lat_deg=float(np.degrees(recs["lat_rad"][-1])),
                              lon_deg=float(np.degrees(recs["lon_rad"][-1])),
                              euler_deg=np.degrees(recs["euler_b_rad"][-1]).tolist(),
                              mode=int(recs["mode"][-1]), fault_flags=int(recs["fault_flags"][-1])))
    aligning = cfg.get("coarse_ticks", 0) > 0 or cfg.get("fine_ticks", 0) > 0
    nav = np.flatnonzero(recs["mode"] == abi.PYINS_MODE_NAVIGATE)
    if aligning and len(nav):
        k = nav[0]
        pitch, roll, yaw = np.degrees(recs["euler_b_rad"][k])
        summary["aligned"] = dict(time_s=float(recs["tick"][k] / hz), pitch_deg=float(pitch),
                                  roll_deg=float(roll), heading_deg=float(np.mod(-yaw, 360.0)))
    fine = alignment_figures(recs)
    if fine is not None:
        summary["fine_alignment"] = fine
    summary["warnings"] = warnings(recs, aligning, hz)

    # 3. the errors against a reference
    err = None
    if spec is not None:
        truth = sim.truth_at(spec.motion, recs["tick"], dt=spec.dt)
        e = metrics.nav_errors(runner.RunResult(outputs=recs, truth=truth, dt=spec.dt))
        err = dict(time_s=e.time_s, north_m=e.north_m, east_m=e.east_m, vel_n_mps=e.vel_n_mps)
        summary["errors"] = dict(reference=f"the truth of {spec.scenario}",
                                 horizontal_max_m=float(e.horizontal_m.max()),
                                 horizontal_final_m=float(e.horizontal_m[-1]),
                                 heading_final_arcmin=float(e.att_n_rad[-1, 2] / ARCMIN_TO_RAD),
                                 level_max_arcsec=float(np.abs(e.att_n_rad[:, :2]).max() / ARCSEC_TO_RAD))
    elif reference == "parked":
        err = _parked_errors(recs, cfg, hz)
        horizontal = np.hypot(err["north_m"], err["east_m"])
        speed = np.linalg.norm(err["vel_n_mps"][:, :2], axis=1)
        summary["errors"] = dict(reference="the site, parked (zero velocity)",
                                 horizontal_max_m=float(horizontal.max()),
                                 horizontal_final_m=float(horizontal[-1]),
                                 north_final_m=float(err["north_m"][-1]), east_final_m=float(err["east_m"][-1]),
                                 speed_max_mps=float(speed.max()))
    if err is not None:
        np.savez(os.path.join(out_dir, "errors.npz"), **err)

    # 4. summary.json
    with open(os.path.join(out_dir, "summary.json"), "w", encoding="utf-8") as f:
        json.dump(summary, f, indent=2)
    return summary
