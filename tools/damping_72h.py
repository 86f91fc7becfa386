#!/usr/bin/env python3
"""A ship under way for 72 h damped by its EM log, beside the same ship
unaided: the at-sea issue's first acceptance line, measured.

    .venv/bin/python tools/damping_72h.py [--hours 72] [--scheme flexible]
        [--out docs/results/damping_72h]

The built-in scenario ``voyage_log`` (route seed 1: 15.5 -> 11.5 kn with
course changes, the general sea state, a 0.2 m/s current with a 0.05 m/s
tide at the M2 period, seed 002's sensor errors, an EM log at 1 Hz with
0.05 m/s noise and a 0.5 % scale factor) run for ``--hours`` with seed
002's flexible two-position scheme (``--scheme``), through the firmware in
the loop, twice: with the log (AUTO: DAMPED on the straight legs) and
without it (UNDAMPED). Prints and writes (``OUT.json``, ``OUT.png``):

- the spectrum of the velocity error, and its largest amplitude within
  0.6-1.6 x the Schuler frequency (84.4 min), damped against unaided;
- the position error, against what dead reckoning with this log predicts
  from the truth alone: the damped velocity follows the log's velocity plus
  the current learnt from its first 60 readings, so its error is
      e(t) = s [w(t) b(t) - <w b>_0] - [c(t) - <c>_0] + <e_ins>_0
  (s the log's scale factor, w the speed through water along the bow b,
  c the current, <>_0 the mean over the learning minute, e_ins the INS's
  own velocity error then), and the position error its integral; then
  with the north velocity error -R W cos(L) psi' / w_s that the heading
  error's drift leaves through the network's integrator (the damped loop
  does not gyrocompass); the residual's RMS says how much of the growth
  that explains;
- the heading error against its prediction psi(2 h) + int (W cos(L) dN /
  R - eps_U) dt (the vertical Earth rate computed at a latitude dN / R
  off, less the up gyro's drift);
- every switch of the navigation mode: the jump of the output velocity and
  position across it (the velocity error's and the position error's change
  from the record before, at 1 s records).
"""
import argparse
import dataclasses
import json
import os
import sys
import time

import numpy as np

from pyins import metrics, scenario
from pyins import run_scenario
from pyins.reference import abi, earth
from pyins.units import DT

SCHULER_HZ = 1.0 / 5064.0
TRANSIENT_S = 7200.0     # the damped start's transient: ~1.5 Schuler periods


def band_amplitude(v, lo=0.6, hi=1.6):
    """(frequencies, amplitudes, largest amplitude within lo..hi x the
    Schuler frequency) of v, one record a second."""
    x = v - v.mean()
    f = np.fft.rfftfreq(len(x), 1.0)
    a = np.abs(np.fft.rfft(x)) * 2.0 / len(x)
    band = (f > lo * SCHULER_HZ) & (f < hi * SCHULER_HZ)
    return f, a, float(a[band].max())


def _bow(quat_nb):
    """The bow (body y) in n, horizontal, unit: column 1 of C_b^n."""
    w_, x_, y_, z_ = np.asarray(quat_nb).T
    bow = np.stack([2 * (x_ * y_ - w_ * z_), w_ * w_ - x_ * x_ + y_ * y_ - z_ * z_], axis=1)
    return bow / np.linalg.norm(bow, axis=1)[:, None]


def predicted_errors(spec, res, err, learn, scale):
    """The dead-reckoning prediction (module docstring) on the records'
    times: (velocity error (n, 2), position error east/north (n, 2)) from
    the learning window's end on, zero before. The firmware's damped
    velocity follows (1 + s) w b_c + c_learnt, b_c the bow by its own
    attitude (its heading error turns the log's velocity), c_learnt the mean
    of v_ins - (1 + s) w b_c over the learning minute; so with
    d = (1 + s) w b_c - v_true:  e = d - <d>_0 + <e_ins>_0."""
    tr = res.truth
    t = err.time_s
    cur = spec.motion.current.velocity(t)[:, :2]
    water = tr.vel_n[:, :2] - cur
    along = np.sum(water * _bow(tr.quat_nb), axis=1)
    d = (1.0 + scale) * along[:, None] * _bow(res.outputs["quat_nb"]) - tr.vel_n[:, :2]
    t0, t1 = learn
    win = (t >= t0) & (t < t1)
    e = d - d[win].mean(axis=0) + err.vel_n_mps[win, :2].mean(axis=0)
    e[t < t1] = 0.0
    p = np.cumsum(e, axis=0) * np.diff(t, prepend=t[0])[:, None]
    k1 = np.searchsorted(t, t1)
    p += np.array([err.east_m[k1], err.north_m[k1]])[None, :] * (t >= t1)[:, None]
    return e, p


def _smooth(x, k):
    return np.convolve(x, np.ones(k) / k, mode="same")


def heading_growth(time_s, psi, north_m, lat, eps_up):
    """The damped loop's heading error from TRANSIENT_S on, predicted: not
    gyrocompassed (the network's integrator takes up the Earth-rate term
    that bounds it unaided), it integrates W cos(L) dN / R (the vertical
    Earth rate computed at a latitude dN / R off) less the up gyro's drift
    eps_up: psi(t0) + int (W cos(L) dN / R - eps_up) dt. [rad]"""
    rm, rn = earth.principal_radii(np.sin(lat))
    rate = earth.OMEGA_IE * np.cos(lat) * north_m / rm - eps_up
    dt = np.diff(time_s, prepend=time_s[0])
    k0 = int(np.searchsorted(time_s, TRANSIENT_S))
    acc = np.cumsum(rate * dt)
    return psi[k0] + acc - acc[k0]


def heading_drift_term(time_s, psi, lat):
    """The north velocity error the network's integrator leaves while the
    heading error psi drifts (module docstring): -R W cos(L) psi' / w_s,
    psi' from the records' psi over 1-h means (m/s, one per record)."""
    k = 3600
    n = len(psi) // k
    tm = time_s[:n * k].reshape(n, k).mean(axis=1)
    rate = np.gradient(psi[:n * k].reshape(n, k).mean(axis=1), tm)
    rm, rn = earth.principal_radii(np.sin(lat))
    r = np.sqrt(rm * rn)
    w_s = np.sqrt(earth.normal_gravity(np.sin(lat), 0.0) / r)
    return -r * earth.OMEGA_IE * np.cos(lat) * np.interp(time_s, tm, rate) / w_s


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hours", type=float, default=72.0)
    ap.add_argument("--scheme", default="flexible")
    ap.add_argument("--out", default=os.path.join("docs", "results", "damping_72h"))
    ap.add_argument("--save", help="also write the time series to this .npz")
    args = ap.parse_args(argv)
    if not args.hours >= 3.0:
        # the spectrum needs two Schuler periods for its band, the analysis
        # its 2 h transient and 1-h means after it
        ap.error(f"--hours {args.hours:g}: at least 3 (the Schuler band of the spectrum, the 2 h transient)")
    base = scenario.load("voyage_log").with_overrides({"duration": f"{args.hours:g} h",
                                                        "indexing.scheme": args.scheme})
    spec = next(base.runs())
    assert abs(spec.refs["value"][:, 0].mean()) > 1.0          # the log reads the ship's speed
    runs = {}
    for label, refs in (("damped", spec.refs), ("unaided", None)):
        t0 = time.perf_counter()
        s = dataclasses.replace(next(base.runs()), refs=refs,
                                avail_tick=spec.avail_tick if refs is not None else None)
        res = run_scenario.run(s)
        runs[label] = (s, res, metrics.nav_errors(res))
        print(f"{label}: {time.perf_counter() - t0:.0f} s wall", flush=True)
    (sd, rd, ed), (_, ru, eu) = runs["damped"], runs["unaided"]
    out = rd.outputs
    fig = {"hours": args.hours, "scheme": args.scheme, "scenario": "voyage_log", "date": time.strftime("%Y-%m-%d")}
    # 1. the Schuler oscillation
    for axis, name in ((0, "east"), (1, "north")):
        _, _, a_d = band_amplitude(ed.vel_n_mps[:, axis])
        _, _, a_u = band_amplitude(eu.vel_n_mps[:, axis])
        fig[f"schuler_band_{name}_mps"] = {"damped": a_d, "unaided": a_u, "ratio": a_u / a_d}
    # 2. the position error and its prediction
    lg_ticks = sd.refs["tick"][sd.refs["kind"] == abi.PYINS_REF_SPEED_LOG]
    learn = (lg_ticks[0] * DT, lg_ticks[59] * DT + 1.0)
    scale = float(base.data["references"]["speed_log"]["scale_factor"])
    e_pred, p_pred = predicted_errors(sd, rd, ed, learn, scale)
    pos = np.stack([ed.east_m, ed.north_m], axis=1)
    after = ed.time_s >= learn[1]
    resid = pos[after] - p_pred[after]
    fig["position"] = {
        "damped_final_m": float(ed.horizontal_m[-1]), "damped_max_m": float(ed.horizontal_m.max()),
        "unaided_final_m": float(eu.horizontal_m[-1]), "unaided_max_m": float(eu.horizontal_m.max()),
        "predicted_final_m": float(np.hypot(*p_pred[-1])),
        "rms_error_m": float(np.sqrt(np.mean(np.sum(pos[after] ** 2, axis=1)))),
        "rms_residual_m": float(np.sqrt(np.mean(np.sum(resid ** 2, axis=1)))),
    }
    fig["position"]["explained_fraction"] = 1.0 - (fig["position"]["rms_residual_m"]
                                                   / fig["position"]["rms_error_m"]) ** 2
    # the heading: not gyrocompassed in the damped loop, it integrates the
    # up gyro's errors; the z gyro's scale factor turns the IMU's net rotation
    # about z (the ship's course changes and the table's turns) into heading
    lat0 = float(rd.truth.lat[0])
    psi = ed.att_n_rad[:, 2]
    extra = np.zeros_like(e_pred)
    extra[:, 1] = heading_drift_term(ed.time_s, psi, lat0)
    extra[ed.time_s < learn[1]] = 0.0
    p_pred2 = p_pred + np.cumsum(extra, axis=0) * np.diff(ed.time_s, prepend=ed.time_s[0])[:, None]
    resid2 = pos[after] - p_pred2[after]
    table = np.unwrap(out["table_angle_rad"])
    ship = np.unwrap(rd.truth.euler[:, 2])
    turns = (table - table[0]) + (ship - ship[0])
    # what drives it: the latitude error makes the computed Earth rate about
    # the vertical wrong by W cos(L) dN / R, an up drift that grows with the
    # dead reckoning's error, less the up gyro's own drift (heading_growth)
    psi_pred = heading_growth(ed.time_s, psi, ed.north_m, lat0, float(sd.errors.gyro_bias[2]))
    hours = [h for h in (1, 12, 24, 48, 72) if h <= args.hours]
    at = [min(int(h * 3600), len(psi) - 1) for h in hours]
    fig["heading"] = {
        "error_arcmin_at_h": {str(h): float(np.degrees(psi[k]) * 60) for h, k in zip(hours, at)},
        "predicted_arcmin_at_h": {str(h): float(np.degrees(psi_pred[k]) * 60) for h, k in zip(hours, at)
                                  if ed.time_s[k] >= TRANSIENT_S},
        "imu_net_turns_about_z_rev": float(turns[-1] / (2.0 * np.pi)),
        "z_scale_factor_times_turns_arcmin": float(np.degrees(sd.errors.gyro_scale[2] * turns[-1]) * 60),
        "z_bias_times_time_arcmin": float(np.degrees(sd.errors.gyro_bias[2] * ed.time_s[-1]) * 60)}
    fig["position"]["with_heading_drift"] = {
        "predicted_final_m": float(np.hypot(*p_pred2[-1])),
        "rms_residual_m": float(np.sqrt(np.mean(np.sum(resid2 ** 2, axis=1)))),
        "explained_fraction": 1.0 - float(np.mean(np.sum(resid2 ** 2, axis=1))
                                          / np.mean(np.sum(pos[after] ** 2, axis=1)))}
    # after the start's transient: the 0.5' tilt's Schuler oscillation (~1 m/s)
    # is damped out over the first ~2 h, which the prediction (v = v_ref at
    # once) does not have; from then on, the growth of the run and of its
    # residual
    k2 = int(np.searchsorted(ed.time_s, TRANSIENT_S))
    grow = pos[-1] - pos[k2]
    resid_grow = (pos[-1] - p_pred[-1]) - (pos[k2] - p_pred[k2])
    fig["position"]["after_transient"] = {
        "from_s": TRANSIENT_S, "run_growth_m": float(np.hypot(*grow)),
        "residual_growth_m": float(np.hypot(*resid_grow)),
        "residual_share": float(np.hypot(*resid_grow) / np.hypot(*grow)),
        "transient_residual_m": float(np.hypot(*(pos[k2] - p_pred[k2]))),
        "residual_growth_with_heading_drift_m": float(np.hypot(*((pos[-1] - p_pred2[-1]) - (pos[k2] - p_pred2[k2]))))}
    # 3. the switches
    mode = out["nav_mode"]
    sw = np.flatnonzero(np.diff(mode) != 0)
    dv, dp = metrics.record_steps(ed)
    steady = np.ones(len(dv), bool)
    steady[sw] = False
    fig["switches"] = {"count": int(len(sw)), "max_velocity_jump_mps": float(dv[sw].max()),
                       "max_position_step_m": float(dp[sw].max()),
                       "typical_velocity_step_mps": float(np.median(dv[steady])),
                       "damped_fraction": float(np.mean(mode == abi.PYINS_NAV_DAMPED))}
    fig["log_readings_used"] = int(out["n_ref_used"][-1, abi.PYINS_REF_SPEED_LOG - 1])
    fig["fault_flags_final"] = int(out["fault_flags"][-1])
    print(json.dumps(fig, indent=2))
    if args.save:
        np.savez_compressed(args.save, time_s=ed.time_s, pos=pos, p_pred=p_pred, p_pred2=p_pred2,
                            table=table, ship_yaw=ship, vel=ed.vel_n_mps[:, :2],
                            e_pred=e_pred, vel_unaided=eu.vel_n_mps[:, :2], nav_mode=mode,
                            att=ed.att_n_rad, learn=np.array(learn))
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out + ".json", "w") as f:
        json.dump(fig, f, indent=2)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fg, ax = plt.subplots(3, 1, figsize=(9, 11))
    for e, label, c in ((eu, "unaided", "tab:red"), (ed, "damped by the log", "tab:blue")):
        f, a, _ = band_amplitude(e.vel_n_mps[:, 1])
        ax[0].loglog(f[1:] * 3600, a[1:], color=c, lw=0.8, label=label)
    ax[0].axvspan(0.6 * SCHULER_HZ * 3600, 1.6 * SCHULER_HZ * 3600, color="0.85", label="Schuler band")
    ax[0].set_xlabel("frequency [cycles/h]")
    ax[0].set_ylabel("north velocity error amplitude [m/s]")
    ax[0].legend()
    h = ed.time_s / 3600
    ax[1].plot(h, eu.horizontal_m / 1852, color="tab:red", lw=0.8, label="unaided")
    ax[1].plot(h, ed.horizontal_m / 1852, color="tab:blue", lw=0.8, label="damped")
    ax[1].plot(h, np.hypot(*p_pred.T) / 1852, "k--", lw=0.8, label="predicted: log scale factor + current change")
    ax[1].plot(h, np.hypot(*p_pred2.T) / 1852, "k-", lw=0.8, label="... + the heading's drift through the network")
    ax[1].set_ylabel("horizontal error [nmi]")
    ax[1].legend()
    k = 600     # 10-min means: the log along a yawing bow swings the prediction by w sin(yaw) at the waves'
    ax[2].plot(h, _smooth(ed.vel_n_mps[:, 1], k), color="tab:blue", lw=0.8,
               label="north velocity error, damped (10-min mean)")
    ax[2].plot(h, _smooth(e_pred[:, 1], k), "k", lw=0.8, label="predicted (10-min mean)")
    ax[2].set_xlabel("time [h]")
    ax[2].set_ylabel("[m/s]")
    ax[2].legend()
    fg.suptitle(f"voyage_log, {args.hours:g} h, {args.scheme} scheme, seed 002 errors: "
                f"EM log damping (0.05 m/s, 0.5 %, 0.2 m/s current)")
    fg.tight_layout()
    fg.savefig(args.out + ".png", dpi=90)
    print(f"wrote {args.out}.json, {args.out}.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
