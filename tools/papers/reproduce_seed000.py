#!/usr/bin/env python3
"""Reproduce seed 000 (inertial-frame coarse alignment) with the C++ firmware.
The set-up is the built-in campaigns seed000_static and seed000_swing (their
headings, seed formulas and base scenarios, pyins/campaigns/ and
pyins/scenarios/); this driver adds the theoretical limits, tables and curves.

    .venv/bin/python tools/papers/reproduce_seed000.py [--out runs/seed000] [--seeds 5]

Writes into --out:
- table1_static.csv / .md: 6 headings x N noise seeds, pitch/roll/heading
  errors at 150 s and the std per heading (the layout of the paper's Table 1),
  against the truth and against the theoretical limit;
- swing.csv / .md: 3 sea states x 6 headings x N seeds, errors at 200 s;
- fig1_gyro_bias.png, fig1_accel_bias.png, fig2_ratio.png: convergence curves
  like the paper's Figs. 1 and 2;
- seed000.json: every headline figure (units in the keys).

Sensors: seed 000 gives bias levels only (0.01 deg/h, 0.1 mg). Noise is
needed for "noise seeds": we use the levels seeds 002 and 003 give for the
same class of marine RLG IMU (ARW 0.0005 deg/sqrt(h), VRW 5 ug/sqrt(Hz)).
In 150 s an ARW of 0.0005 deg/sqrt(h) alone leaves a heading noise of
about 0.7' (sigma of the equivalent east drift, ARW / sqrt(T), divided by
W cos L), so the heading std is noise-limited near the paper's 1'.
The paper's errors are against its own fine alignment, which carries the
same unobservable part as the theoretical limit: compare our "vs limit"
columns with its Table 1.
"""
import argparse
import json
import os
import sys

import numpy as np

from pyins import analysis, campaign, metrics, runner, scenario, sim
from pyins.reference.config import DEFAULT_COARSE_FIRST_S
from pyins.units import ARCMIN_TO_RAD as ARCMIN
from pyins.units import ARCSEC_TO_RAD as ARCSEC
from pyins.units import DEG_TO_RAD as DEG
from pyins.units import TICK_HZ, TWO_PI, split_quantity

#: the built-in campaigns (and their base scenarios) holding the set-up: Table 1's static
#: alignments, the swinging base's, their headings and noise seeds
STATIC, SWING = "seed000_static", "seed000_swing"
_STATIC_BASE = scenario.load(STATIC).with_overrides({"compare": None, "paper": None})
_SITE = next(_STATIC_BASE.runs()).motion
LAT, LON = _SITE.lat, _SITE.lon
HEADINGS = tuple(int(split_quantity(h)[0])
                 for h in campaign.load_campaign(STATIC).grid["motion.heading"])
#: the convergence curves (Figs. 1 and 2): 250 s at heading 0, one noise seed
CURVES = {"duration": "250 s", "firmware.coarse_time": "250 s"}
CURVES_HEADING, CURVES_SEED = 0, 5


def sensors(gyro_dph=None, accel_ug=None, seed=0, noise=True):
    """(SensorModel drawing from ``seed``, SensorErrors): the sensors of seed000_static, its
    drift [deg/h] and bias [ug] replaced when given, without noise when ``noise`` is False."""
    overrides = {}
    if gyro_dph is not None:
        overrides["sensors.gyro_bias"] = f"{gyro_dph!r} deg/h"
    if accel_ug is not None:
        overrides["sensors.accel_bias"] = f"{accel_ug!r} ug"
    if not noise:
        overrides.update({"sensors.gyro_arw": 0, "sensors.accel_vrw": 0})
    (spec,) = _STATIC_BASE.with_overrides(overrides).runs()
    return sim.SensorModel(spec.errors, seed=seed), spec.errors


def run_spec(state, heading, seed, overrides=None):
    """The RunSpec of one alignment: seed000_static (``state`` "static") or seed000_swing at
    sea state ``state``, at mean ``heading`` [deg] with noise ``seed``, and ``overrides``."""
    o = {"compare": None, "paper": None, "motion.heading": f"{heading} deg", "seed": seed}
    if state != "static":
        o["motion.sea_state"] = state
    (spec,) = scenario.load(STATIC if state == "static" else SWING).with_overrides(
        {**o, **(overrides or {})}).runs()
    return spec


def motion(state, heading):
    """The ship of `run_spec` (heading [deg])."""
    return run_spec(state, heading, 0).motion


def campaign_specs(name, n_seeds):
    """[(grid values, run, RunSpec)] of built-in campaign ``name`` with ``n_seeds`` noise
    seeds per grid point (its seed formula), in its order (grid, then seeds)."""
    camp = campaign.load_campaign(name)
    camp = campaign.from_args(camp.base, camp.grid, seeds=n_seeds, group_by=camp.group_by,
                              overrides=camp.overrides, seed_formula=camp.seed_formula,
                              compare=camp.compare)
    out = []
    for point in camp.points:
        (spec,) = camp.base.with_overrides(point.overrides).runs()
        out.append((point.values, point.run, spec))
    return out


def navigate(spec):
    """One alignment of ``spec``, open loop (pyins.runner.navigate, no turntable), its sensor
    noise drawn from its seed."""
    res = runner.navigate(spec.motion, spec.duration_ticks, every=spec.every,
                          sensors=sim.SensorModel(spec.errors, seed=spec.seed), config=spec.config)
    return res, metrics.nav_errors(res)


def euler_errors(res, k=-1):
    """pitch, roll, heading errors [arcsec] of record k (heading = marine)."""
    d = res.outputs["euler_b_rad"][k] - res.truth.euler[k]
    d = (d + np.pi) % TWO_PI - np.pi
    return np.array([d[0], d[1], -d[2]]) / ARCSEC


def limit_euler(m, errors, t):
    """The theoretical limit expressed as pitch/roll/heading errors [arcsec]:
    phi in n rotated into the Euler-angle errors at the true attitude."""
    st = m.state(np.array([t]))
    lim = analysis.alignment_limits(LAT, st.euler[0], errors.gyro_bias, errors.accel_bias)
    phi = lim.phi_n
    pitch, roll, yaw = st.euler[0]
    # small-angle: d(pitch, roll, yaw) for C' = (I - phi x) C with C = Rz Rx Ry
    cy, sy = np.cos(yaw), np.sin(yaw)
    cp, sp = np.cos(pitch), np.sin(pitch)
    d_pitch = -(cy * phi[0] + sy * phi[1])
    d_roll = -(-sy * phi[0] + cy * phi[1]) / cp
    d_yaw = -(phi[2] + sp / cp * (-sy * phi[0] + cy * phi[1]))
    return np.array([d_pitch, d_roll, -d_yaw]) / ARCSEC


def table_static(out, n_seeds, fig):
    rows = []
    for values, run, spec in campaign_specs(STATIC, n_seeds):
        h = int(split_quantity(values["motion.heading"])[0])
        res, _ = navigate(spec)
        err = euler_errors(res)
        lim = limit_euler(spec.motion, spec.errors, spec.duration_ticks / TICK_HZ)
        rows.append([h, run, *err, *(err - lim)])
    a = np.array(rows)
    with open(os.path.join(out, "table1_static.csv"), "w") as f:
        f.write("heading_deg,seed,pitch_err_arcsec,roll_err_arcsec,heading_err_arcsec,"
                "pitch_vs_limit_arcsec,roll_vs_limit_arcsec,heading_vs_limit_arcsec\n")
        for r in a:
            f.write(",".join(f"{v:.6g}" for v in r) + "\n")
    md = ["| heading | pitch err (\") | roll err (\") | heading err (\") | std pitch vs limit | std roll vs limit | std heading vs limit |",
          "|---|---|---|---|---|---|---|"]
    stds = []
    for h in HEADINGS:
        g = a[a[:, 0] == h]
        sd = g[:, 5:8].std(axis=0, ddof=1)
        stds.append(sd)
        md.append(f"| {h} | {g[:, 2].mean():.3f} | {g[:, 3].mean():.3f} | {g[:, 4].mean():.2f} | "
                  f"{sd[0]:.3f} | {sd[1]:.3f} | {sd[2]:.2f} |")
    stds = np.array(stds)
    md.append("")
    md.append("Errors are means over the seeds (against the truth); std columns are the std over "
              "the seeds of the error against the theoretical limit (the paper's Table 1 std: "
              "pitch/roll < 1\", heading < 1' = 60\").")
    with open(os.path.join(out, "table1_static.md"), "w") as f:
        f.write("\n".join(md) + "\n")
    fig["static_max_std_level_arcsec"] = float(stds[:, :2].max())
    fig["static_max_std_heading_arcsec"] = float(stds[:, 2].max())
    fig["static_max_abs_level_vs_limit_arcsec"] = float(np.abs(a[:, 5:7]).max())
    fig["static_max_abs_heading_vs_limit_arcmin"] = float(np.abs(a[:, 7]).max() / 60.0)
    return "\n".join(md)


def table_swing(out, n_seeds, fig):
    rows = []
    for values, run, spec in campaign_specs(SWING, n_seeds):
        h = int(split_quantity(values["motion.heading"])[0])
        res, _ = navigate(spec)
        err = euler_errors(res)
        lim = limit_euler(spec.motion, spec.errors, spec.duration_ticks / TICK_HZ)
        rows.append([values["motion.sea_state"], h, run, *err, *(err - lim)])
    with open(os.path.join(out, "swing.csv"), "w") as f:
        f.write("sea_state,heading_deg,seed,pitch_err_arcsec,roll_err_arcsec,heading_err_arcsec,"
                "pitch_vs_limit_arcsec,roll_vs_limit_arcsec,heading_vs_limit_arcsec\n")
        for r in rows:
            f.write(",".join([r[0]] + [f"{v:.6g}" for v in r[1:]]) + "\n")
    md = ["| sea state | max \\|level err\\| (\") | max \\|heading err\\| (') | max \\|level vs limit\\| (\") | max \\|heading vs limit\\| (') |",
          "|---|---|---|---|---|"]
    for state in campaign.load_campaign(SWING).grid["motion.sea_state"]:
        g = np.array([r[3:] for r in rows if r[0] == state], dtype=float)
        lv, hd = np.abs(g[:, 0:2]).max(), np.abs(g[:, 2]).max() / 60
        lvl, hdl = np.abs(g[:, 3:5]).max(), np.abs(g[:, 5]).max() / 60
        md.append(f"| {state} | {lv:.2f} | {hd:.3f} | {lvl:.2f} | {hdl:.3f} |")
        fig[f"swing_{state}_max_level_vs_limit_arcsec"] = float(lvl)
        fig[f"swing_{state}_max_heading_vs_limit_arcmin"] = float(hdl)
    md.append("")
    md.append("At 200 s, over 6 headings x the seeds. Paper: level < 7\", heading < 1.5' (against its fine alignment).")
    with open(os.path.join(out, "swing.md"), "w") as f:
        f.write("\n".join(md) + "\n")
    return "\n".join(md)


def curves(out, fig):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = [
        ("fig1_gyro_bias.png", "gyro bias",
         [(f"{b} deg/h", {"sensors.gyro_bias": f"{b} deg/h"}) for b in (0.01, 0.03, 0.05)]),
        ("fig1_accel_bias.png", "accelerometer bias",
         [(f"{b / 1000:g} mg", {"sensors.accel_bias": f"{b} ug"}) for b in (100.0, 300.0, 500.0)]),
        ("fig2_ratio.png", "ratio r = t_k1 / t_k2",
         [(label, {"firmware.coarse_ratio": r}) for label, r in (("r = 1/4", 0.25), ("r = 1/2", 0.5),
                                                                  ("r = 3/4", 0.75))]),
    ]
    for name, title, curves_of in panels:
        fg, ax = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
        for label, overrides in curves_of:
            spec = run_spec("static", CURVES_HEADING, CURVES_SEED, {**CURVES, **overrides})
            m, errs = spec.motion, spec.errors
            res, e = navigate(spec)
            # every record after the first coarse output holds a solution; they
            # are all provisional (ATT_VALID unset) while the coarse phase runs
            ok = e.time_s > DEFAULT_COARSE_FIRST_S
            t = e.time_s[ok]
            lim = analysis.alignment_limits(LAT, m.state(np.array([0.0])).euler[0], errs.gyro_bias,
                                            errs.accel_bias).phi_n
            d = e.att_n_rad[ok] - lim
            ax[0].plot(t, np.abs(d[:, 2]) / ARCMIN, label=label)
            ax[1].plot(t, np.abs(d[:, :2]).max(axis=1) / ARCSEC, label=label)
            key = f"{name[:-4]}_{label.replace(' ', '').replace('/', '_')}_heading_vs_limit_at_150s_arcmin"
            fig[key] = float(abs(d[t == 150.0, 2][0]) / ARCMIN)
        ax[0].set_ylabel("|heading error - limit| [arcmin]")
        ax[0].set_yscale("log")
        ax[1].set_ylabel("max |level error - limit| [arcsec]")
        ax[1].set_xlabel("alignment time [s]")
        ax[0].legend()
        ax[0].set_title(f"seed 000 static coarse alignment, heading 0: {title}\n"
                        "error beside the theoretical limit (one noise seed)")
        fg.tight_layout()
        fg.savefig(os.path.join(out, name), dpi=100)
        plt.close(fg)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join("runs", "seed000"))
    ap.add_argument("--seeds", type=int, default=5, help="noise seeds per heading (paper: 5)")
    args = ap.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    fig = {"noise_seeds": args.seeds, "latitude_deg": LAT / DEG}
    print("seed 000 static, errors at 150 s (Table 1 layout)")
    print(table_static(args.out, args.seeds, fig))
    print("\nseed 000 swing, errors at 200 s")
    print(table_swing(args.out, args.seeds, fig))
    curves(args.out, fig)
    with open(os.path.join(args.out, "seed000.json"), "w") as f:
        json.dump(fig, f, indent=2)
    print(f"\nfigures, tables and seed000.json written to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
