#!/usr/bin/env python3
"""Alignment of a ship swinging at anchor (the alignment issue's
acceptance 1): with a GNSS receiver, and with no reference at all.

    .venv/bin/python tools/anchor_alignment.py [--headings 6] [--seeds 5] [--out docs/results]

The ship (`pyins.sim.at_anchor`, the built-in scenario `at_anchor`): seed
000's general sea state's pitch and roll, the moored ship's heave and lever
arm, and the swing about the anchor: cell (h, s) of the grid has mean
heading 60 h deg, noise seed s, the radius 30 + 12.5 s m (30-80 m), the
period 20 + 10 ((s + h) mod 5) min (20-60 min), the half angle 30 deg and
the swing's phase 72 h + 144 s deg. Seed 000's sensor errors, drawn per
cell from its 1-sigma values (`pyins.sim.sensors.draw_random_constants`,
draw 6 s + h).

Alignments per cell, each from nothing; the receiver's noise seed 100 +
10 h + s:
- ``gnss``: the built-in `at_anchor`: FIT coarse 60 s, then the navigation
  filter aided by GNSS (3 m, 0.05 m/s at 1 Hz) with the table indexed,
  540 s;
- ``gnss_fixed``: the same with the table fixed (the static limit holds);
- ``none``: no reference: FIT coarse 120 s (its wander test needs the
  waves' periods well below a fifth of it, docs/results/harbour.md), then
  the moving-base 12-state fine alignment, 2880 s,
  told the anchorage's bound on the swing (``fine_site_swing`` = the grid's
  largest radius, fastest swing and its half angle, 80 m, 20 min, 30 deg:
  ``fine_site_accel`` 4015 ug/sqrt(Hz), `pyins.analysis.
  site_accel_for_swing`), the same bound in every cell, as a user who knows
  the chain's length and the weather but not the swing of the day;
- ``none_harbour``: the same, 1080 s, told a harbour's ranging instead
  (``fine_site_accel`` 1000 ug/sqrt(Hz), the built-in `harbour_ranging`'s):
  a model too small for the anchorage;
- ``none_rigid``: the same told a rigid site (the firmware's default,
  right at a pier and wrong here): what integrity has to catch.
Per cell: the static limit (eps_E / (Omega cos L) - tan L nabla_E / g,
`pyins.analysis.alignment_limits`), the heading error at 600 s, and at
every record whether the firmware says ATT_VALID while the heading is more
than 10 arcmin off. Printed, and with --out written to
OUT/anchor_alignment.{md,json}.
"""
import argparse
import json
import time
from pathlib import Path

import numpy as np

from pyins import analysis, metrics, scenario
from pyins.reference import abi
from pyins.run_scenario import run
from pyins.sim.sensors import draw_random_constants, random_constant_overrides
from pyins.units import ARCMIN_TO_RAD

#: The line acceptance 1 draws: a record more than this far off in heading
#: must not say ATT_VALID.
VALID_LIMIT = 10.0 * ARCMIN_TO_RAD
METHODS = ("gnss", "gnss_fixed", "none", "none_harbour", "none_rigid")
#: a harbour's ranging (the built-in harbour_ranging's site model)
SITE_ACCEL = "1000 ug/sqrt(Hz)"
#: the anchorage's bound on the swing: the grid's largest radius, fastest swing, half angle
SWING_BOUND = ["80 m", "20 min", "30 deg"]
#: the fine alignment's length without a reference [s], told the swing / the harbour's model
NONE_FINE_S = {"none": 2880, "none_harbour": 1080, "none_rigid": 1080}


def cell(h, s):
    """The ship of grid cell (h, s): the overrides of the built-in scenario."""
    return {"motion.heading": f"{60 * h} deg", "motion.radius": f"{30 + 12.5 * s:g} m",
            "motion.swing_period": f"{20 + 10 * ((s + h) % 5)} min",
            "motion.swing_phase": f"{(72 * h + 144 * s) % 360} deg", "seed": s}


def one(h, s, method):
    """(time [s], heading error [rad], ATT_VALID per record, limit [rad], the filter's heading sigma
    [rad]) of one alignment."""
    draw = 6 * s + h
    over = dict(random_constant_overrides("seed000", draw), **cell(h, s))
    if method == "gnss_fixed":
        over["indexing.scheme"] = "none"
    elif method in NONE_FINE_S:
        fine = NONE_FINE_S[method]
        over.update({"indexing.scheme": "none", "references": None, "firmware.coarse_time": "120 s",
                     "firmware.fine_time": f"{fine} s", "firmware.fine_states": 12,
                     "duration": f"{fine + 120} s"})
        if method == "none":
            over["firmware.fine_site_swing"] = SWING_BOUND
        elif method == "none_harbour":
            over["firmware.fine_site_accel"] = SITE_ACCEL
    scn = scenario.load("at_anchor")
    if method in ("gnss", "gnss_fixed"):
        # the receiver's noise drawn per cell (one realisation for all would leave the
        # spread over the cells a single noise draw's)
        refs = scn.data["references"]
        over["references"] = dict(refs, gnss=dict(refs["gnss"], seed=100 + 10 * h + s))
    spec = next(iter(scn.with_overrides(over).runs()))
    res = run(spec)
    e = metrics.nav_errors(res)
    o = res.outputs
    valid = (o["state_flags"] & abi.PYINS_STATE_ATT_VALID) != 0
    sigma = np.where(o["mode"] == abi.PYINS_MODE_NAVIGATE, o["nav_sigma_heading_rad"], o["kf_sigma"][:, 2])
    lat, _, _, _, euler = scenario.initial_truth(spec.motion)
    eb = draw_random_constants("seed000", draw)
    limit = analysis.alignment_limits(lat, euler, eb.gyro_bias, eb.accel_bias).phi_n[2]
    return e.time_s, e.att_n_rad[:, 2], valid, limit, sigma


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--headings", type=int, default=6, help="mean headings 0, 60, ... deg (at most 6)")
    ap.add_argument("--seeds", type=int, default=5, help="seeds per heading (at most 5: the radii 30-80 m)")
    ap.add_argument("--out", type=Path, default=None, help="write anchor_alignment.{md,json} here")
    args = ap.parse_args()
    if not (1 <= args.headings <= 6 and 1 <= args.seeds <= 5):
        ap.error("--headings 1..6, --seeds 1..5")
    t0 = time.perf_counter()
    rows = []
    for h in range(args.headings):
        for s in range(args.seeds):
            row = dict(heading_deg=60 * h, seed=s, **{k.split(".")[-1]: v for k, v in cell(h, s).items()
                                                       if k.startswith("motion.")})
            for method in METHODS:
                t, err, valid, lim, sigma = one(h, s, method)
                k = int(np.searchsorted(t, 599.0))
                row[f"{method}_first_valid_s"] = float(t[valid][0]) if valid.any() else None
                row[f"{method}_valid_at_end"] = bool(valid[-1])
                row[f"{method}_end_s"] = float(t[-1])
                row[f"{method}_end_sigma_arcmin"] = float(sigma[-1]) / ARCMIN_TO_RAD
                bad = valid & (np.abs(err) > VALID_LIMIT)
                row["limit_arcmin"] = lim / ARCMIN_TO_RAD
                row[f"{method}_arcmin"] = err[k] / ARCMIN_TO_RAD
                row[f"{method}_end_arcmin"] = err[-1] / ARCMIN_TO_RAD
                row[f"{method}_max_valid_arcmin"] = (float(np.max(np.abs(err[valid]))) / ARCMIN_TO_RAD
                                                     if valid.any() else None)
                row[f"{method}_valid_when_off"] = int(bad.sum())
            rows.append(row)
            print(f"  heading {60 * h:3d} deg, seed {s} (radius {row['radius']}, period {row['swing_period']}): "
                  f"limit {row['limit_arcmin']:+.3f}'; at 600 s GNSS indexed {row['gnss_arcmin']:+.3f}', "
                  f"GNSS fixed {row['gnss_fixed_arcmin']:+.3f}', no reference {row['none_arcmin']:+.3f}' "
                  f"({row['none_end_arcmin']:+.3f}' at the end, first valid {row['none_first_valid_s']} s; rigid site "
                  f"{row['none_rigid_end_arcmin']:+.3f}'); "
                  "ATT_VALID > 10' off: "
                  + ", ".join(str(row[f"{m}_valid_when_off"]) for m in METHODS)
                  + f" records ({time.perf_counter() - t0:.0f} s)", flush=True)
    n = len(rows)
    lines = [f"{n} cells ({args.headings} headings x {args.seeds} seeds), FIT coarse 60 s (with GNSS) or 120 s "
             f"(none); median |heading error| at 600 s, and the worst:"]
    for m in METHODS:
        a = np.abs([r[f"{m}_arcmin"] for r in rows])
        d = np.abs([r[f"{m}_arcmin"] - r["limit_arcmin"] for r in rows])
        off = sum(r[f"{m}_valid_when_off"] for r in rows)
        lines.append(f"  {m:10s}: {np.median(a):.3f}' (worst {a.max():.3f}'); from the static limit: median "
                     f"{np.median(d):.3f}', worst {d.max():.3f}'; ATT_VALID while > 10' off: {off} records")
    lines.append(f"  static limit: median |limit| {np.median(np.abs([r['limit_arcmin'] for r in rows])):.3f}'")
    lines.append("")
    lines.append("When ATT_VALID (every 1 s record): first valid median / latest, cells valid at the end, the "
                 "worst |heading error| while valid, at the end: median |error|, median sigma:")
    for m in METHODS:
        first = [r[f"{m}_first_valid_s"] for r in rows if r[f"{m}_first_valid_s"] is not None]
        worst = [r[f"{m}_max_valid_arcmin"] for r in rows if r[f"{m}_max_valid_arcmin"] is not None]
        lines.append(f"  {m:12s} ({rows[0][f'{m}_end_s']:.0f} s): first valid "
                     + (f"{np.median(first):.0f} / {max(first):.0f} s in {len(first)} cells" if first else "never")
                     + f"; valid at the end {sum(r[f'{m}_valid_at_end'] for r in rows)} of {n}; worst while valid "
                     + (f"{max(worst):.2f}'" if worst else "-")
                     + f"; at the end {np.median(np.abs([r[f'{m}_end_arcmin'] for r in rows])):.2f}', sigma "
                     f"{np.median([r[f'{m}_end_sigma_arcmin'] for r in rows]):.2f}'")
    print("\n" + "\n".join(lines))
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
        (args.out / "anchor_alignment.json").write_text(json.dumps(dict(cells=rows, summary=lines), indent=1)
                                                        + "\n")
        (args.out / "anchor_alignment.md").write_text(
            "# Alignment at anchor\n\nWritten by `tools/anchor_alignment.py` (its docstring says what runs).\n\n"
            + "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
