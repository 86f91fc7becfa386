#!/usr/bin/env python3
"""Reproduce seed 002 (flexible two-position scheme under heading motion, 72 h).

    .venv/bin/python tools/papers/reproduce_seed002.py [--out runs/seed002] [--hours 72]

Experiments 1 and 2 (heading swing omega = 6 cos(pi t/60) and 6 cos(pi t/30)
deg/s), its Table 1 initial state and initial errors (pitch/roll/heading
-10", 10", 1'; velocity 0.01 m/s; position 10 m north and east), its Table 2
sensor errors (preset seed002), for no rotation, the traditional two-position
scheme and the flexible scheme (stops 300 s, 6 deg/s), literal (docs/papers.md,
seed 002 §6, scheme 4) and in the form of its derivation (eqs. 9-13, scheme 6). The
paper's turns run at a constant 6 deg/s: we command 600 deg/s^2, which
reaches 6 deg/s within one 10-ms tick (the firmware default, 30 deg/s^2,
lengthens each cycle by 0.8 s; why that matters is in the report). Also the
isolated comparison (the horizontal gyro drifts, 0.003 deg/h, as the only
error, under both accelerations), a split of the Table 2 result by source
(up-gyro drift; scale-factor and installation errors), and the derivation
form with its sums taken over the turns too (index_sums = all, our
extension; docs/indexing.md, "What the turns leave").

Writes positions.png, table.md (final and maximum horizontal errors beside
the paper's 8.57 / 3.70 / 2.97 and 16.13 / 12.90 / 1.98 nmi), report.md
(the tables and why each figure differs from the paper's) and seed002.json.
docs/papers.md, seed 002 §7-§10, explains why experiment 2's traditional result may not
reproduce; nothing is tuned to match.
"""
import argparse
import json
import os
import re
import sys

import numpy as np

from pyins import analysis, fil, metrics, progress, scenario, sim
from pyins.sim.turntable import TableConfig
from pyins.units import ARCSEC_TO_RAD as ARCSEC
from pyins.units import DEG_TO_RAD as DEG
from pyins.units import DPH_TO_RPS, NMI_TO_M, TICK_HZ

PAPER = {1: (8.57, 3.70, 2.97), 2: (16.13, 12.90, 1.98)}
SCHEMES = ((0, "no rotation"), (2, "traditional two-position"), (4, "flexible two-position"),
           (6, "flexible, derivation form"))        # the variants of the built-in seed002_exp* scenarios
# (variant id, scheme, index_sums, label): SCHEMES with seed 002's sums, and our extension
VARIANTS = tuple((str(s), s, 0, label) for s, label in SCHEMES) + (
    ("6all", 6, 1, "flexible, derivation form, turns summed"),)
VIDS = tuple(v[0] for v in VARIANTS)
PAPER_ACCEL = 600.0 * DEG        # 6 deg/s within one tick: the paper's constant-rate turns
DEFAULT_ACCEL = 30.0 * DEG       # the firmware default
PLANT_ACCEL = 1000.0 * DEG       # a motor that can follow PAPER_ACCEL


def initial_errors(m):
    """Seed 002 Table 1 errors applied to the true initial state of ``m``
    (`pyins.scenario.initial_errors`): pitch -10", roll 10", heading +1'
    (yaw -1'), velocity 0.01 m/s east and north, position 10 m north and east."""
    return scenario.initial_errors(m, pitch=-10.0 * ARCSEC, roll=10.0 * ARCSEC, yaw=-60.0 * ARCSEC,
                                   velocity=[0.01, 0.01, 0.0], north=10.0, east=10.0)


def error_sets():
    """The error sets run, name -> (SensorErrors, with Table 1 initial errors)."""
    t2 = sim.preset("seed002")
    drift = 0.003 * DPH_TO_RPS
    return {
        "table2": (t2, True),
        "hdrift": (sim.SensorErrors(gyro_bias=np.array([drift, drift, 0.0])), False),
        "updrift": (sim.SensorErrors(gyro_bias=np.array([0.0, 0.0, drift])), False),
        "sf_mis": (sim.SensorErrors(gyro_scale=t2.gyro_scale, gyro_misalignment=t2.gyro_misalignment,
                                    accel_scale=t2.accel_scale,
                                    accel_misalignment=t2.accel_misalignment), False),
    }


SET_LABEL = {"table2": "Table 2 (all), Table 1 initial errors", "hdrift": "horizontal gyro drifts only",
             "updrift": "up-gyro drift only", "sf_mis": "scale-factor and installation errors only"}


def run_one(exp, scheme, sums, errors, with_init, accel, hours, seed):
    m = sim.HeadingSwing.experiment(exp)
    cfg = dict(index_scheme=scheme, index_accel_rad_s2=accel)
    if sums:
        cfg["index_sums"] = sums
    if with_init:
        cfg.update(initial_errors(m))
    res = fil.run_fil(m, int(hours * (3600 * TICK_HZ)), config=cfg, errors=errors, seed=seed,
                      every=TICK_HZ,
                      table=TableConfig(accel_max_rad_s2=PLANT_ACCEL), progress=progress.TextProgress())
    e = metrics.nav_errors(res)
    psi = res.outputs["yaw_p_rad"]
    # the proxy of docs/papers.md, seed 002 §10 (from the 1 Hz records), split into the stopped
    # and the turning part
    stopped = np.asarray(res.outputs["index_state"]) != 2
    return dict(final_nmi=float(e.horizontal_m[-1] / NMI_TO_M),
                max_nmi=float(e.horizontal_m.max() / NMI_TO_M),
                survives=analysis.drift_surviving(psi),
                survives_stops=analysis.drift_surviving(psi, stopped),
                survives_turns=analysis.drift_surviving(psi, ~stopped),
                fallbacks=int(res.outputs["index_fallbacks"][-1]),
                index_faults=int(np.count_nonzero(res.outputs["index_fault"]))), e


def explain(r, hours):
    """Why each figure differs from the paper's, from the measured figures."""
    def g(exp, es, sch, acc="paper", k="final_nmi"):
        return r[(exp, es, str(sch), acc)][k]
    lines = ["## Why our figures differ from the paper's", ""]
    for exp in (1, 2):
        no, tr, fl, fd, fa = (g(exp, "table2", s) for s in VIDS)
        p_no, p_tr, p_fl = PAPER[exp]
        up = [g(exp, "updrift", s) for s in VIDS]
        sfm = [g(exp, "sf_mis", s) for s in VIDS]
        hd = [g(exp, "hdrift", s, k="max_nmi") for s in VIDS]
        sv = [g(exp, "hdrift", s, k="survives") for s in VIDS]
        svs = [g(exp, "hdrift", s, k="survives_stops") for s in VIDS]
        svt = [g(exp, "hdrift", s, k="survives_turns") for s in VIDS]
        hd30 = [g(exp, "hdrift", s, "default", "max_nmi") for s in VIDS]
        sv30 = [g(exp, "hdrift", s, "default", "survives") for s in VIDS]
        lines += [f"### Experiment {exp}", "",
                  f"- **No rotation**: ours {no:.2f} nmi, the paper {p_no:.2f}. The drifts are random "
                  "constants (随机常值漂移) in the paper, one draw; ours are +0.003 deg/h on every "
                  "axis. Their signs decide how the sources add: see the split below.",
                  f"- **What rotation cannot remove**: the up gyro's drift alone gives "
                  f"{up[0]:.2f} / {up[1]:.2f} / {up[2]:.2f} / {up[3]:.2f} / {up[4]:.2f} nmi (none / "
                  "traditional / flexible / derivation form / the same, turns summed) in "
                  f"{hours:g} h: a vertical-axis table does not modulate it (its component along "
                  "the Earth's axis feeds a growing longitude error). It is the same for every "
                  "scheme and adds to the other errors with their signs (a total can be below "
                  "it), so the draw of the paper's random-constant drifts decides much.",
                  f"- **Heading-correlated errors**: the scale-factor and installation errors alone "
                  f"give {sfm[0]:.2f} / {sfm[1]:.2f} / {sfm[2]:.2f} / {sfm[3]:.2f} / {sfm[4]:.2f} nmi. "
                  "Times the "
                  "6 deg/s heading swing and the table rate they act like drifts that move with "
                  "the heading; no scheme is designed against them.",
                  f"- **Horizontal drifts only** (the effect the paper's analysis is about): max "
                  f"{hd[0]:.3f} / {hd[1]:.3f} / {hd[2]:.3f} / {hd[3]:.3f} / {hd[4]:.3f} nmi; the "
                  f"fraction of a constant x/y drift that survives (the proxy of docs/papers.md, "
                  f"seed 002 §10): "
                  f"{' / '.join(f'{x:.4f}' for x in sv)}, of which the stopped ticks leave "
                  f"{' / '.join(f'{x:.4f}' for x in svs[1:])} and the turns "
                  f"{' / '.join(f'{x:.4f}' for x in svt[1:])} (the rotating schemes).",
                  f"- **What the turns leave** (docs/indexing.md): with seed 002's sums the drift "
                  f"integrated over the stops stays between {min(svs[1:4]):.4f} and "
                  f"{max(svs[1:4]):.4f} of the run for every rotating scheme; the turns (about 9 % "
                  f"of the time) leave {svt[1]:.4f} (traditional), {svt[2]:.4f} (literal flexible) "
                  f"and {svt[3]:.4f} (derivation form). Seed 002 freezes A_c, A_s while the table "
                  f"turns, so its flexible stops never see that part. Summing the turns too "
                  f"(index_sums = all) lets the stops cancel it: the derivation form's survival "
                  f"{sv[3]:.4f} -> {sv[4]:.4f}, max {hd[3]:.3f} -> {hd[4]:.3f} nmi; with 30 deg/s^2 "
                  f"turns {sv30[3]:.4f} -> {sv30[4]:.4f}, {hd30[3]:.3f} -> {hd30[4]:.3f} nmi."]
        if exp == 1:
            lines += [
                f"- **The traditional scheme and the swing period lock** when the turns take "
                f"exactly 30 s: a cycle is then 4 x 330 s = 1320 s = 11 swing periods, every cycle "
                f"sees the swing at the same phases and a constant part of the drift survives "
                f"({sv[1]:.4f}; docs/papers.md, seed 002 §10, found 0.083 with the same ideal turns). With the "
                f"firmware's default 30 deg/s^2 each turn takes 0.2 s longer, the phase slips "
                f"0.8 s per cycle, and over {hours:g} h the residue averages out: survival "
                f"{sv30[1]:.4f}, max {hd30[1]:.3f} nmi instead of {hd[1]:.3f}. The paper's "
                f"traditional result depends on this unstated detail.",
                f"- **Flexible, literal vs derivation form**: the literal cycle (docs/papers.md, seed 002 §6) turns a "
                f"variable angle and then a fixed 180 deg each way; even on a static ship those "
                f"four turns leave (sin P2 - sin P0 - 2 sin P1)/omega of cos-integral per cycle "
                f"(P0, P1, P2 its stop headings), where the traditional 0/180 turns leave none. "
                f"Survival {sv[2]:.4f} (docs/papers.md, seed 002 §10: 0.034{', the same' if abs(sv[2] - 0.034) < 0.002 else ''}), "
                f"{svt[2]:.4f} of it from "
                f"the turns. The derivation form (eqs. 9-13, no fixed 180-deg moves) "
                f"leaves {sv[3]:.4f}. With the paper's turns the literal scheme beats the "
                f"traditional one by {100 * (1 - hd[2] / hd[1]):.0f} % (max {hd[2]:.3f} vs "
                f"{hd[1]:.3f} nmi), the derivation form by {100 * (1 - hd[3] / hd[1]):.0f} % and "
                f"with its turns summed by {100 * (1 - hd[4] / hd[1]):.0f} %; with 30 deg/s^2 turns "
                f"{100 * (1 - hd30[2] / hd30[1]):.0f} %, {100 * (1 - hd30[3] / hd30[1]):.0f} % and "
                f"{100 * (1 - hd30[4] / hd30[1]):.0f} %.",
                f"- **With all errors**: ours {tr:.2f} (traditional) and {fl:.2f} / {fd:.2f} / "
                f"{fa:.2f} nmi (flexible, literal / derivation / derivation with turns summed) "
                f"beside the paper's {p_tr:.2f} and {p_fl:.2f}. "
                f"The paper's order (none > traditional > flexible) "
                f"{'holds' if no > tr > fl else 'does not hold'} for the literal scheme and "
                f"{'holds' if no > tr > fd else 'does not hold'} for the derivation form; the sizes "
                f"follow from the split above."]
        else:
            lines += [
                f"- **Why the traditional scheme does not fail here** (the paper: {p_tr:.2f} nmi, "
                f"'basically fails'): the decoded swing has a 60 s period, and every 300-s stop "
                f"covers exactly 5 periods, so the x/y drift cancels almost perfectly "
                f"(survival {sv[1]:.4f}, {hd[1]:.3f} nmi with horizontal drifts only; docs/papers.md, seed 002 §7 "
                f"and §10 predicted this). The paper's text says the swing period equals the stop "
                f"time, which the decoded formula does not give; nothing was changed to match.",
                f"- **With all errors**: ours {tr:.2f} (traditional) and {fl:.2f} / {fd:.2f} / "
                f"{fa:.2f} nmi (flexible, literal / derivation / derivation with turns summed) "
                f"beside the paper's {p_tr:.2f} and {p_fl:.2f}. What remains of ours is the up-gyro drift ({up[1]:.2f} nmi alone) and the "
                f"heading-correlated errors ({sfm[1]:.2f} / {sfm[2]:.2f} nmi alone)."]
        lines.append("")
    lines += ["### Common to both", "",
              "- Latitude 34.246 N, 380 m (Table 1); the vertical channel is held at the true "
              "height (the paper does not say how it treats it).",
              "- The paper does not say whether its figures are final or maximum errors: both are "
              "in the table.",
              "- Nothing is tuned to match: each figure is what the firmware gives on the "
              "simulated data."]
    return "\n".join(lines) + "\n"


def write_report_from_json(out_dir):
    """report.md again from a previous run's figures (e.g. after editing the
    explanations): nothing is simulated."""
    with open(os.path.join(out_dir, "seed002.json")) as fh:
        out = json.load(fh)
    results = {}
    for key, val in out.items():
        m = re.match(r"exp(\d)_(\w+?)_(paper|default)accel_scheme(\d(?:all)?)_(\w+)$", key)
        if m:
            exp, es, acc, vid, k = m.groups()
            results.setdefault((int(exp), es, vid, acc), {})[k] = val
    with open(os.path.join(out_dir, "table.md")) as fh:
        table = fh.read()
    write_report(out_dir, table, explain(results, out["hours"]), out["hours"])
    return 0


def write_report(out_dir, table, why, hours):
    with open(os.path.join(out_dir, "report.md"), "w") as fh:
        fh.write(f"# Seed 002 reproduced: no rotation, traditional and flexible two-position, "
                 f"{hours:g} h\n\n{chr(10).join(__doc__.split(chr(10) * 2)[2:]).strip()}\n\n"
                 f"![positions](positions.png)\n\n{table}\n{why}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join("runs", "seed002"))
    ap.add_argument("--hours", type=float, default=72.0)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--explain-only", action="store_true",
                    help="rewrite report.md from the seed002.json and table.md in --out, run nothing")
    args = ap.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    if args.explain_only:
        return write_report_from_json(args.out)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    plan = [("table2", "paper"), ("hdrift", "paper"), ("hdrift", "default"), ("updrift", "paper"),
            ("sf_mis", "paper")]
    accels = {"paper": PAPER_ACCEL, "default": DEFAULT_ACCEL}
    sets = error_sets()
    results, out = {}, {"hours": args.hours, "paper_accel_deg_s2": PAPER_ACCEL / DEG,
                        "default_accel_deg_s2": DEFAULT_ACCEL / DEG}
    md = ["| experiment | errors | turn acceleration | scheme | final (nmi) | max (nmi) | paper (nmi) "
          "| drift surviving | of it: stops | turns |", "|---|---|---|---|---|---|---|---|---|---|"]
    fg, ax = plt.subplots(2, 2, figsize=(12, 8), sharex=True)
    for col, exp in enumerate((1, 2)):
        for es, acc in plan:
            errors, with_init = sets[es]
            for vid, scheme, sums, label in VARIANTS:
                f, e = run_one(exp, scheme, sums, errors, with_init, accels[acc], args.hours, args.seed)
                results[(exp, es, vid, acc)] = f
                key = f"exp{exp}_{es}_{acc}accel_scheme{vid}"
                for k, v in f.items():
                    out[f"{key}_{k}"] = v
                paper = PAPER[exp][[0, 2, 4].index(scheme)] if es == "table2" and scheme != 6 else ""
                md.append(f"| {exp} | {SET_LABEL[es]} | {accels[acc] / DEG:g} deg/s^2 | {label} | "
                          f"{f['final_nmi']:.3f} | {f['max_nmi']:.3f} | {paper} | {f['survives']:.4f} | "
                          f"{f['survives_stops']:.4f} | {f['survives_turns']:.4f} |")
                print(md[-1], flush=True)
                if acc == "paper" and es in ("table2", "hdrift"):
                    row = 0 if es == "table2" else 1
                    ax[row, col].plot(e.time_s / 3600, e.horizontal_m / NMI_TO_M, label=label)
                    ax[row, col].set_title(f"experiment {exp}, {SET_LABEL[es]}", fontsize=9)
                    ax[row, col].set_ylabel("horizontal error [nmi]")
    for a in ax.flat:
        a.grid(alpha=0.3)
        a.legend(fontsize=8)
    ax[1, 0].set_xlabel("time [h]")
    ax[1, 1].set_xlabel("time [h]")
    fg.tight_layout()
    fg.savefig(os.path.join(args.out, "positions.png"), dpi=100)
    table = "\n".join(md) + "\n"
    why = explain(results, args.hours)
    with open(os.path.join(args.out, "table.md"), "w") as fh:
        fh.write(table)
    write_report(args.out, table, why, args.hours)
    with open(os.path.join(args.out, "seed002.json"), "w") as fh:
        json.dump(out, fh, indent=2)
    print(why)
    print(f"written to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
