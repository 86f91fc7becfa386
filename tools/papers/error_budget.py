#!/usr/bin/env python3
"""The error budget of seeds 002 and 003: each sensor error's signed share of
the position error, by the linear error model (pyins.budget.run_budget)
and by the firmware in the loop with that error alone.

    .venv/bin/python tools/papers/error_budget.py [--out runs/error_budget] [--hours H]
                                                  [--scenarios seed002_exp1 seed002_exp2 seed003]
                                                  [--no-check] [--no-level]

For every scenario and scheme (the scenario's [compare] variants: seed 002
none / two-position / flexible / flexible, derivation form, 72 h; seed 003
none / single-position, 24 h): one closed-loop run with all the scenario's
deterministic errors (noise left out) and its initial errors gives the
table's history; the model splits its error by source (gyro bias, scale
factor, misalignment; accelerometer bias, scale factor, misalignment;
initial state), and gives the 1 sigma of the sensors' noise (ARW, VRW) by
covariance. With the check (the default) every source also runs alone
through the firmware and the model, driven by that run's own table
history, is held to it: "rel. diff." is the largest distance over the run
between the model's and the run's (north, east) errors over the run's
largest horizontal error; the "sum" row holds the model's sum to the run
with every error. For seed 002 the gyro misalignment alone is run on a
level deck too (pitch = roll = 0): the misalignment-times-tilt case.

Writes budget.md (every table), budget_SCENARIO.md and budget_misalignment_tilt.md
(the tables of docs/results/seed002.md and seed003.md) and budget.json (every
figure) to --out; --tables-only rewrites the tables from budget.json.
"""
import argparse
import json
import os
import sys
import time

from pyins import budget as error_budget, scenario
from pyins.units import DPH_TO_RPS, NMI_TO_M, TICK_HZ

LABELS = {"gyro_bias": "gyro bias", "gyro_scale": "gyro scale factor",
          "gyro_misalignment": "gyro misalignment", "accel_bias": "accel. bias",
          "accel_scale": "accel. scale factor", "accel_misalignment": "accel. misalignment",
          "initial": "initial errors", "sum": "sum (all together)",
          "noise": "noise, 1 sigma (ARW, VRW)"}


def fmt_nmi(m):
    return f"{m / NMI_TO_M:+.3f}"


FLOOR_M = error_budget.BUDGET_FLOOR_M     #: below it a run is judged in metres (pyins.budget.budget_verdict)
judged = error_budget.budget_verdict


def table_rows(scheme, rows, check):
    out = []
    for r in rows:
        if r.get("one_sigma"):           # the noise: 1 sigma of north and east, RMS of the horizontal
            ne = f"+-{r['model_north_m'] / NMI_TO_M:.3f} / +-{r['model_east_m'] / NMI_TO_M:.3f}"
        else:
            ne = f"{fmt_nmi(r['model_north_m'])} / {fmt_nmi(r['model_east_m'])}"
        cells = [scheme, LABELS.get(r["source"], r["source"]), ne,
                 f"{r['model_final_m'] / NMI_TO_M:.3f}", f"{r['model_max_m'] / NMI_TO_M:.3f}"]
        if "fil_north_m" in r:
            other = (f"{100 * max(r['rel_level'], r['rel_heading']):.2f} % / {100 * r['rel_velocity']:.2f} %"
                     if r["run_max_m"] >= FLOOR_M else "")
            cells += [f"{fmt_nmi(r['fil_north_m'])} / {fmt_nmi(r['fil_east_m'])}",
                      f"{r['fil_final_m'] / NMI_TO_M:.3f}", f"{r['fil_max_m'] / NMI_TO_M:.3f}",
                      judged(r)[1], other]
        elif check:
            cells += ["", "", "", "", ""]
        out.append("| " + " | ".join(cells) + " |")
    return out


def write_tables(out, out_dir):
    """budget.md (every table) and budget_SCENARIO.md (one scenario's, to paste into
    docs/results) from the figures ``out`` (what budget.json holds)."""
    check = out["check"]
    head = ["| scheme | source | model final N / E (nmi) | model final | model max |"]
    rule = "|---|---|---|---|---|"
    if check:
        head[0] += " FIL final N / E (nmi) | FIL final | FIL max | rel. diff. | attitude / velocity |"
        rule += "---|---|---|---|---|"
    per = {}
    level = ["| experiment | deck | scheme | model final (nmi) | FIL final (nmi) | rel. diff. | "
             "mean eps_U of the misalignment (deg/h) |", "|---|---|---|---|---|---|---|"]
    for run in out["runs"]:
        if run["deck"] == "tilted":
            per.setdefault(run["scenario"], head + [rule])
            per[run["scenario"]] += table_rows(run["scheme"], run["rows"], check)
        mis = next((r for r in run["rows"] if r["source"] == ("sum" if run["deck"] == "level"
                                                              else "gyro_misalignment")), None)
        if run.get("mis_table") and mis is not None and "fil_final_m" in mis:
            level.append(f"| {run['scenario']} | {run['deck']} | {run['scheme']} | "
                         f"{mis['model_final_m'] / NMI_TO_M:.3f} | {mis['fil_final_m'] / NMI_TO_M:.3f} | "
                         f"{100 * mis['rel_max']:.2f} % | {run['eps_u_mean_dph']['gyro_misalignment']:+.5f} |")
    note = ("Final north / east error (signed, nmi), final and maximum horizontal error (nmi); "
            "rel. diff. = max over the run of |model - FIL| (north, east) / max FIL horizontal error "
            f"(a run below {FLOOR_M:g} m: the absolute difference, within 10 % of {FLOOR_M:g} m); "
            "attitude / velocity: the same measure for the attitude error (the larger of level and "
            "heading) and the horizontal velocity error. The noise row is the model's 1 sigma of one "
            "draw of the sensors' noise (north, east; final and max horizontal: RMS), not a signed "
            "share, and is not in the sum.")
    text = ["# Error budget by source: linear model and firmware in the loop", "", note, ""]
    for name, rows in per.items():
        hours = next(r["hours"] for r in out["runs"] if r["scenario"] == name)
        text += [f"## {name}, {hours:g} h", ""] + rows + [""]
        with open(os.path.join(out_dir, f"budget_{name}.md"), "w") as fh:
            fh.write("\n".join(rows) + "\n")
    if len(level) > 2:
        text += ["## The gyro misalignment alone on a tilted and a level deck", ""] + level + [""]
        with open(os.path.join(out_dir, "budget_misalignment_tilt.md"), "w") as fh:
            fh.write("\n".join(level) + "\n")
    if check:
        judged_rows = [(run, r) for run in out["runs"] for r in run["rows"]
                       if "rel_max" in r and r["run_max_m"] >= FLOOR_M]
        for key, what in (("rel_24h", "at 24 h"), ("rel_final", "at the end")):
            vals = [(r[key], run, r) for run, r in judged_rows if r.get(key) is not None]
            if vals:
                v, run, r = max(vals, key=lambda x: x[0])
                text.append(f"|model - FIL| / |FIL| {what} (north, east), worst of {len(vals)} rows: "
                            f"{100 * v:.2f} % ({run['scenario']}, {run['scheme']}, {r['source']}).")
        text += ["", f"All sources and sums within 10 %: {'yes' if out['all_within_10_percent'] else 'NO'} "
                 f"({out['wall_s']:.0f} s wall)."]
    with open(os.path.join(out_dir, "budget.md"), "w") as fh:
        fh.write("\n".join(text) + "\n")
    return "\n".join(text)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join("runs", "error_budget"))
    ap.add_argument("--hours", type=float, default=None, help="duration (default: each scenario's, 72 h / 24 h)")
    ap.add_argument("--scenarios", nargs="+", default=["seed002_exp1", "seed002_exp2", "seed003"])
    ap.add_argument("--no-check", action="store_true", help="the model only (one FIL run per scheme)")
    ap.add_argument("--no-level", action="store_true", help="skip seed 002's level-deck misalignment runs")
    ap.add_argument("--tables-only", action="store_true", help="rewrite the tables from --out's budget.json")
    args = ap.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    if args.tables_only:
        with open(os.path.join(args.out, "budget.json")) as fh:
            print(write_tables(json.load(fh), args.out))
        return 0
    check = not args.no_check
    out = {"check": check, "runs": []}
    t_start = time.time()
    for name in args.scenarios:
        sc = scenario.load(name)
        overrides = {} if args.hours is None else {"duration": f"{args.hours * 3600:g} s"}
        decks = [("tilted", {})]
        if name.startswith("seed002") and not args.no_level:
            decks.append(("level", {"motion.pitch": "0 deg", "motion.roll": "0 deg"}))
        for deck, over in decks:
            for spec in sc.with_overrides({**overrides, **over}).runs():
                t0 = time.time()
                if deck == "tilted":
                    rows, budget = error_budget.run_budget(spec, check=check)
                else:                    # the gyro misalignment alone, no initial errors: its "sum" row
                    only = error_budget.deterministic(spec.errors)
                    spec.errors = type(only)(gyro_misalignment=only.gyro_misalignment)
                    spec.config = {k: v for k, v in spec.config.items() if k not in error_budget._INITIAL_FIELDS}
                    rows, budget = error_budget.run_budget(spec, check=False)
                eps_u = {n: float(budget.eps_n_mean[i, 2] / DPH_TO_RPS) for i, n in enumerate(budget.names)}
                out["runs"].append(dict(scenario=name, deck=deck, scheme=spec.label, mis_table=len(decks) > 1,
                                        hours=spec.duration_ticks / TICK_HZ / 3600, rows=rows,
                                        eps_u_mean_dph=eps_u))
                worst = max((r["rel_max"] for r in rows if "rel_max" in r and r["run_max_m"] >= FLOOR_M),
                            default=0.0)
                print(f"{name} {deck} {spec.label}: {time.time() - t0:.0f} s, worst rel. diff. "
                      f"{100 * worst:.2f} %", flush=True)
    passed = all(judged(r)[0] for run in out["runs"] for r in run["rows"] if "rel_max" in r)
    out["all_within_10_percent"] = passed
    out["wall_s"] = time.time() - t_start
    with open(os.path.join(args.out, "budget.json"), "w") as fh:
        json.dump(out, fh, indent=1)
    print(write_tables(out, args.out))
    return 0 if passed or not check else 1


if __name__ == "__main__":
    sys.exit(main())
