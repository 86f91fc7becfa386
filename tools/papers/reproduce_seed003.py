#!/usr/bin/env python3
"""Reproduce seed 003 (single-position forward/reverse rotate-stop, 24 h).
The set-up (motion, sensor errors, the two schemes, the paper's bounds) is
the built-in scenario seed003 (pyins/builtin/scenarios/seed003.toml); this driver
adds the error theory, the figures and the explanation.

    .venv/bin/python tools/papers/reproduce_seed003.py [--out runs/seed003] [--hours 24] [--seed 1]

Static ship, 24 h, seed 003's sensor errors (docs/papers.md, seed 003 §3:
drift 0.003 deg/h, ARW 0.0005 deg/sqrt(h), gyro SF 0.466 ppm, accelerometer bias 20 ug and
SF 20 ppm, the +-2" installation matrix on both triads), the firmware
started from the true state, the IMU either fixed (no rotation) or indexed
by the single-position scheme (stop 60 s at zero, +360 deg at 6 deg/s, stop,
-360 deg). The paper states one value per error; ours is that value with a
plus sign on every axis (+0.003 deg/h on every gyro). Its latitude is not
given: 34.246 N is used. The paper also says its horizontal instruments are
slightly less accurate than the vertical one (a cost choice, since rotation
modulates only the horizontal ones): the up-gyro scan below asks what up
drift, the horizontal drifts left at 0.003 deg/h, meets its < 1.1 nmi.

Writes errors.png (position, level, heading, velocity errors over 24 h,
like its Figs. 4-9), table.md (maxima beside the paper's bounds) and
seed003.json.
"""
import argparse
import json
import os
import sys

import numpy as np

from pyins import analysis, metrics, progress, run_scenario, scenario
from pyins.units import ARCMIN_TO_RAD as ARCMIN
from pyins.units import DEG_TO_RAD as DEG
from pyins.units import NMI_TO_M, TICK_HZ

#: The built-in scenario holding the set-up: motion, sensors, the two schemes, the paper's bounds.
SCENARIO = "seed003"
#: The same runs with the constant drifts and biases only: what error theory covers.
BIASES_ONLY = {f"sensors.{k}": 0 for k in ("gyro_scale", "gyro_misalignment", "gyro_arw", "gyro_quantum",
                                           "accel_scale", "accel_misalignment", "accel_vrw",
                                           "accel_quantum")}
#: our figure -> the scenario's [paper] metric
FIGURES = {"position_nmi": "horizontal_error_max", "level_arcmin": "level_error_max",
           "heading_arcmin": "heading_error_max", "velocity_mps": "velocity_error_max"}


def paper_bounds(sc):
    """The paper's bounds, in the units the scenario writes them in."""
    figs = {f["metric"]: f["value"] for f in sc.paper["figures"]}
    return {k: figs[metric] for k, metric in FIGURES.items()}


PAPER = paper_bounds(scenario.load(SCENARIO))


def figures(err):
    """The paper's four maxima from a NavErrors or StaticErrors."""
    return {
        "position_nmi": err.horizontal_m.max() / NMI_TO_M,
        "level_arcmin": np.abs(err.att_n_rad[:, :2]).max() / ARCMIN,
        "heading_arcmin": np.abs(err.att_n_rad[:, 2]).max() / ARCMIN,
        "velocity_mps": np.abs(err.vel_n_mps[:, :2]).max(),
    }


def load(hours, seed):
    """The built-in scenario for ``hours`` of ship time (ticks as int(hours * 3600 * TICK_HZ))
    and noise ``seed``."""
    ticks = int(hours * (3600 * TICK_HZ))
    return scenario.load(SCENARIO).with_overrides({"duration": f"{ticks / TICK_HZ!r} s", "seed": seed})


def up_gyro_scan(res, lat, errors, up_theory, grid, bound_nmi=1.1):
    """The linear model on the rotating run's table history: the horizontal drifts and the
    accelerometer biases as stated, the up-gyro drift scaled by k in [-1, 1] (k = 1 the
    stated value); the maximum horizontal error over the run for each k, and the range of
    up drift [deg/h] that keeps it below ``bound_nmi`` (the paper's < 1.1 nmi)."""
    rest = analysis.predict_static_fil(res, lat, np.zeros(3), errors.gyro_bias * [1.0, 1.0, 0.0],
                                       errors.accel_bias, grid)
    eps_u = float(errors.gyro_bias[2])
    ks = np.linspace(-1.0, 1.0, 2001)
    worst = np.array([np.hypot(rest.north_m + k * up_theory.north_m, rest.east_m + k * up_theory.east_m).max()
                      for k in ks]) / NMI_TO_M
    ok = ks[worst < bound_nmi]
    to_dph = eps_u / (np.pi / 180 / 3600)
    return {"scan_without_up_max_nmi": float(rest.horizontal_m.max() / NMI_TO_M),
            "scan_stated_max_nmi": float(worst[-1]),
            "scan_up_dph_meeting_1.1nmi": [float(ok.min() * to_dph), float(ok.max() * to_dph)]
            if ok.size else [float("nan"), float("nan")]}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join("runs", "seed003"))
    ap.add_argument("--hours", type=float, default=24.0)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sc = load(args.hours, args.seed)
    specs = list(sc.runs())
    lat = specs[0].motion.lat
    grid = np.arange(1, int(args.hours * 12) + 1) * 300.0       # the linear model every 5 min
    fig_json = {"hours": args.hours, "latitude_deg": lat / DEG}
    rows = []
    fg, ax = plt.subplots(4, 1, figsize=(9, 11), sharex=True)
    zero3 = np.zeros(3)
    scan = None
    for spec, spec_b in zip(specs, sc.with_overrides(BIASES_ONLY).runs()):
        label, errors = spec.label, spec.errors
        up_only = np.array([0.0, 0.0, errors.gyro_bias[2]])
        res = run_scenario.run(spec, progress=progress.TextProgress())
        e = metrics.nav_errors(res)
        # error theory with the same constant drifts and biases, and split by source
        theory = {
            "all constant errors": analysis.predict_static_fil(res, lat, zero3, errors.gyro_bias,
                                                               errors.accel_bias, grid),
            "up-gyro drift only": analysis.predict_static_fil(res, lat, zero3, up_only, zero3, grid),
            "accelerometer biases only": analysis.predict_static_fil(res, lat, zero3, zero3,
                                                                     errors.accel_bias, grid),
        }
        tag = "rot" if spec.config["index_scheme"] else "norot"
        if spec.config["index_scheme"]:
            scan = up_gyro_scan(res, lat, errors, theory["up-gyro drift only"], grid)
            fig_json.update(scan)
        rows.append((f"ours, {label}", figures(e)))
        for k, v in rows[-1][1].items():
            fig_json[f"{tag}_max_{k}"] = float(v)
        # the same run with the constant drifts and biases only: what theory covers
        res_b = run_scenario.run(spec_b)
        rows.append((f"ours, {label}, constant drifts and biases only", figures(metrics.nav_errors(res_b))))
        for k, v in rows[-1][1].items():
            fig_json[f"{tag}_biases_only_max_{k}"] = float(v)
        for what, th_err in theory.items():
            rows.append((f"error theory, {label}, {what}", figures(th_err)))
            for k, v in rows[-1][1].items():
                fig_json[f"{tag}_theory_{what.split()[0].replace('-', '_')}_max_{k}"] = float(v)
        th = e.time_s / 3600
        ax[0].plot(th, e.horizontal_m / NMI_TO_M, label=label)
        ax[0].plot(grid / 3600, theory["all constant errors"].horizontal_m / NMI_TO_M, ":",
                   label=f"error theory, {label}")
        ax[1].plot(th, np.abs(e.att_n_rad[:, :2]).max(axis=1) / ARCMIN, label=label)
        ax[2].plot(th, e.att_n_rad[:, 2] / ARCMIN, label=label)
        ax[3].plot(th, np.hypot(e.vel_n_mps[:, 0], e.vel_n_mps[:, 1]), label=label)
    for a, yl in zip(ax, ["horizontal position error [nmi]", "max |level error| [arcmin]",
                          "heading error [arcmin]", "horizontal velocity error [m/s]"]):
        a.set_ylabel(yl)
        a.grid(alpha=0.3)
        a.legend(fontsize=8)
    ax[3].set_xlabel("time [h]")
    fg.suptitle(f"seed 003: static ship at {lat / DEG:g} N, {args.hours:g} h, its sensor errors")
    fg.tight_layout()
    fg.savefig(os.path.join(args.out, "errors.png"), dpi=100)

    md = ["| | max position (nmi) | max level (') | max heading (') | max velocity (m/s) |",
          "|---|---|---|---|---|",
          f"| paper, rotating (bounds) | < {PAPER['position_nmi']} | < {PAPER['level_arcmin']} | "
          f"< {PAPER['heading_arcmin']} | < {PAPER['velocity_mps']} |"]
    for label, f in rows:
        md.append(f"| {label} | {f['position_nmi']:.3f} | {f['level_arcmin']:.4f} | "
                  f"{f['heading_arcmin']:.3f} | {f['velocity_mps']:.4f} |")
    table = "\n".join(md)
    print(table)
    ours_rot = fig_json["rot_max_position_nmi"]
    up_rot = fig_json["rot_theory_up_gyro_max_position_nmi"]
    all_rot = fig_json["rot_theory_all_max_position_nmi"]
    pos_b = fig_json["rot_biases_only_max_position_nmi"]
    lev, lev_b, lev_b0 = (fig_json["rot_max_level_arcmin"], fig_json["rot_biases_only_max_level_arcmin"],
                          fig_json["norot_biases_only_max_level_arcmin"])
    lev_t, lev_t0 = fig_json["rot_theory_all_max_level_arcmin"], fig_json["norot_theory_all_max_level_arcmin"]
    lo, hi = scan["scan_up_dph_meeting_1.1nmi"]
    if hi < 0.0:
        up_verdict = ("A smaller up drift of the stated sign is not enough, not even zero: the bound needs "
                      "one of the opposite sign, whose error cancels part of what the horizontal drifts "
                      "leave, or horizontal drifts of other signs or smaller than the stated ones.")
    else:
        up_verdict = (f"The bound needs an up gyro of at most {hi:.4f} deg/h, "
                      f"{0.003 / hi:.0f} times better than the stated 0.003 deg/h.")
    explain = f"""
## Why our figures differ from the paper's

- **Our simulation agrees with error theory.** The linear static-INS error
  model (`pyins.analysis.static_error_model`, Qin 2014 sec. 4.2) driven by the
  same constant drifts and biases, projected through the recorded table angle,
  predicts {all_rot:.3f} nmi for the rotating IMU; the closed-loop firmware run
  with those errors only gives {pos_b:.3f} nmi, and {ours_rot:.3f} nmi with the
  full error set. The gap to the paper is therefore not in our integration.
- **Rotation about the vertical cannot modulate the up gyro.** With the up
  gyro's 0.003 deg/h as the *only* error, theory gives {up_rot:.2f} nmi in
  {args.hours:g} h: the drift component along the Earth's axis (eps_U sin L)
  feeds a longitude error that grows linearly. The single-position scheme
  stops only at 0 deg, so half of the horizontal drifts is left unmodulated
  too. The paper's < 1.1 nmi needs other drifts than the stated +0.003 deg/h
  on every axis ("The up gyro the paper's bound needs" below), or a shorter
  effective duration.
- **Level error.** With the constant drifts and biases only, our level error
  ({lev_b:.3f}' rotating, {lev_b0:.3f}' fixed) is what theory predicts
  ({lev_t:.3f}', {lev_t0:.3f}'); it comes from the 20 ug accelerometer bias
  (nabla/g = 4", i.e. 0.07', plus its Schuler and Earth-rate swings). The
  single-position scheme halves it, not more: the IMU stops only at 0 deg, so
  half the time the bias is not modulated. The angle random walk (one draw)
  and the +-2" installation errors times the 6 deg/s table rate make up the
  rest of our {lev:.3f}'. The paper's < 0.01' is below what its own 20 ug
  bias allows; we find no reading of its stated errors that gives it.
- **Latitude.** The paper does not give its latitude; 34.246 N (seed 002's
  site) is used. The longitude-error growth scales with the drift component
  along the Earth's axis, so a lower latitude would give less.
- **The up gyro the paper's bound needs.** The paper chose horizontal
  instruments "slightly worse than the vertical ones": a better up gyro is
  the one way to a smaller error that rotation cannot give. The linear model
  on the rotating run's table history, the horizontal drifts and the
  accelerometer biases held at the stated values (+0.003 deg/h, +20 ug) and
  the up drift scanned from -0.003 to +0.003 deg/h: the horizontal drifts and
  biases alone (an up drift of zero) leave {scan['scan_without_up_max_nmi']:.2f} nmi, the stated
  +0.003 {scan['scan_stated_max_nmi']:.2f} nmi, and the maximum stays below 1.1 nmi only for an
  up drift between {scan['scan_up_dph_meeting_1.1nmi'][0]:+.4f} and {scan['scan_up_dph_meeting_1.1nmi'][1]:+.4f} deg/h. {up_verdict}
  The noise (ARW, 1 sigma 0.18 nmi after 24 h) and the scale-factor and
  installation terms (below 0.1 nmi, the budget below) do not change this.
- **Draw.** The paper states one value for each error and does not say how
  it signed them on the three axes; ours are all +. Over production units
  of this grade (docs/results/montecarlo.md) the signs and sizes vary: they
  move the no-rotation errors by a factor of a few, the rotating ones less
  (there eps_U and the half of the horizontal drifts this scheme leaves
  matter).
"""
    with open(os.path.join(args.out, "table.md"), "w") as fh:
        fh.write(table + "\n")
    with open(os.path.join(args.out, "report.md"), "w") as fh:
        fh.write(f"# Seed 003 reproduced: single-position rotation vs none, {args.hours:g} h static\n\n"
                 f"{(chr(10) * 2).join(__doc__.split(chr(10) * 2)[2:]).strip()}\n\n![errors](errors.png)\n\n{table}\n{explain}")
    with open(os.path.join(args.out, "seed003.json"), "w") as fh:
        json.dump(fig_json, fh, indent=2)
    print(explain)
    print(f"written to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
