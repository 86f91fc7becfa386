#!/usr/bin/env python3
"""Alignment below the static limit by indexing the table: the built-in
scenario `pier_indexed` (coarse 120 s, then 480 s of the navigation filter
aided by zero velocity with the table indexed between two positions) beside
the static 8-state fine alignment of the same IMU (coarse 120 s, fine 480 s,
the table fixed), over error draws.

    .venv/bin/python tools/indexed_alignment.py [--draws 30] [--stop 60] [--site static|moored]
                                                [--gnss 3m|rtk] [--out docs/results]

--site moored: the built-in `moored_indexed` instead (moored_general's
heaving ship with its lever arm, FIT coarse 120 s, the filter aided by GNSS
at 1 Hz, 3 m / 0.05 m/s or with --gnss rtk 0.02 m / 0.01 m/s) beside the
moving-base 12-state fine alignment (FIT 120 s, 480 s).

Draw d: seed d (the receiver's 100 + d), heading 60 d mod 360 deg, seed 000's random constants
drawn from its 1-sigma values (`pyins.sim.sensors.draw_random_constants`:
drifts 0.01 deg/h and biases 100 ug per axis, signs and sizes random).
Per draw: the static limit of the heading, eps_E / (Omega cos L) - tan(L)
nabla_E / g for that draw's drifts and biases at that heading
(`pyins.analysis.alignment_limits`, seed 001 sec. 2), the static filter's
heading error at 600 s, the indexed alignment's, and its NEES (error over
the filter's own sigma, squared). Printed and written to
OUT/indexed_alignment.{md,json,png}: the medians, the NEES against the
chi-square 95 % bounds, and the heading sigma of both filters against time.
"""
import argparse
import json
import time
from pathlib import Path

import numpy as np
from scipy.stats import chi2

from pyins import analysis, metrics, scenario
from pyins.run_scenario import run
from pyins.sim.sensors import draw_random_constants, random_constant_overrides
from pyins.units import ARCMIN_TO_RAD

ROOT = Path(__file__).resolve().parents[1]
#: site -> (the built-in scenario, the fine alignment with the table fixed that it is set beside)
SITES = {"static": ("pier_indexed", {"firmware.fine_states": 8}),
         "moored": ("moored_indexed", {"firmware.fine_states": 12})}


#: the receiver's noise seed of draw d: RECEIVER_SEED + d
RECEIVER_SEED = 100
#: --gnss rtk: the moored ship's receiver RTK-grade (as KF-GINS's data)
RTK = {"references": {"gnss": {"rate": "1 Hz", "pos_noise": ["0.02 m", "0.02 m", "0.02 m"],
                               "vel_noise": "0.01 m/s", "bias_sigma": "0 m", "seed": 5}}}


def one(draw, stop_s, static, site="static", rtk=False):
    """(time [s], heading error [rad], heading sigma [rad], limit [rad]) of draw ``draw``."""
    name, fixed = SITES[site]
    scn = scenario.load(name)
    over = dict(random_constant_overrides("seed000", draw), seed=draw,
                **{"motion.heading": f"{60 * (draw % 6)} deg", "indexing.stop": f"{stop_s:g} s"})
    if rtk:
        over.update(RTK)
    if not static and "gnss" in scn.data.get("references", {}):
        # the receiver's noise drawn per draw too (one realisation for all the draws
        # would leave the NEES a single noise draw's: 0.22 at 3 m, 2026-12-06)
        refs = dict(over["references"] if rtk else scn.data["references"])
        refs["gnss"] = dict(refs["gnss"], seed=RECEIVER_SEED + draw)
        over["references"] = refs
    if static:
        over.update({"indexing.scheme": "none", "references": None, "firmware.fine_time": "480 s", **fixed})
        over.pop("indexing.stop")
        for key in RTK:
            over.pop(key, None)
    spec = next(iter(scn.with_overrides(over).runs()))
    res = run(spec)
    e = metrics.nav_errors(res)
    o = res.outputs
    sigma = np.where(o["mode"] == 3, o["nav_sigma_heading_rad"], o["kf_sigma"][:, 2])
    lat, _, _, _, euler = scenario.initial_truth(spec.motion)
    eb = draw_random_constants("seed000", draw)
    limit = analysis.alignment_limits(lat, euler, eb.gyro_bias, eb.accel_bias).phi_n[2]
    return e.time_s, e.att_n_rad[:, 2], sigma, limit


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--draws", type=int, default=30)
    ap.add_argument("--stop", type=float, default=60.0, help="the indexing stop [s]")
    ap.add_argument("--site", choices=tuple(SITES), default="static",
                    help="static: pier_indexed beside the 8-state filter; moored: moored_indexed (GNSS "
                         "aided) beside the moving-base 12-state filter")
    ap.add_argument("--gnss", choices=("3m", "rtk"), default="3m",
                    help="moored: the receiver as the scenario's (3 m, 0.05 m/s) or RTK-grade (0.02 m, 0.01 m/s)")
    ap.add_argument("--out", type=Path, default=None, help="write indexed_alignment.{md,json,png} here")
    args = ap.parse_args()
    if args.draws < 1:
        ap.error("--draws: at least 1")
    t0 = time.perf_counter()
    rows = []
    sig_idx, sig_static, t_rec = [], [], None
    for d in range(args.draws):
        t, h_i, s_i, lim = one(d, args.stop, static=False, site=args.site, rtk=args.gnss == "rtk")
        _, h_s, s_s, _ = one(d, args.stop, static=True, site=args.site)
        k = int(np.searchsorted(t, 599.0))
        rows.append(dict(draw=d, heading_deg=60 * (d % 6), limit_arcmin=lim / ARCMIN_TO_RAD,
                         static_arcmin=h_s[k] / ARCMIN_TO_RAD, indexed_arcmin=h_i[k] / ARCMIN_TO_RAD,
                         indexed_sigma_arcmin=s_i[k] / ARCMIN_TO_RAD, nees=float((h_i[k] / s_i[k]) ** 2)))
        sig_idx.append(s_i)
        sig_static.append(s_s)
        t_rec = t
        r = rows[-1]
        print(f"  draw {d:2d} (heading {r['heading_deg']:3d} deg): limit {r['limit_arcmin']:+.3f}', static "
              f"{r['static_arcmin']:+.3f}', indexed {r['indexed_arcmin']:+.3f}' (sigma "
              f"{r['indexed_sigma_arcmin']:.3f}') ({time.perf_counter() - t0:.0f} s)", flush=True)
    n = len(rows)
    med = {key: float(np.median(np.abs([r[key] for r in rows])))
           for key in ("limit_arcmin", "static_arcmin", "indexed_arcmin")}
    nees = float(np.mean([r["nees"] for r in rows]))
    bounds = (chi2.ppf(0.025, n) / n, chi2.ppf(0.975, n) / n)
    ratio = med["indexed_arcmin"] / med["limit_arcmin"]
    fixed = "static 8-state filter" if args.site == "static" else "moving-base 12-state filter"
    what = SITES[args.site][0] + (", GNSS RTK-grade" if args.site == "moored" and args.gnss == "rtk" else "")
    lines = [
        f"{what}, {n} draws, stop {args.stop:g} s: median |heading error| at 600 s: static limit "
        f"{med['limit_arcmin']:.3f}', {fixed} (table fixed) {med['static_arcmin']:.3f}', indexed "
        f"{med['indexed_arcmin']:.3f}' ({ratio:.3f} of the limit)",
        f"indexed NEES (mean over the draws) {nees:.2f}, chi-square 95 % bounds {bounds[0]:.2f} .. "
        f"{bounds[1]:.2f}: {'inside' if bounds[0] <= nees <= bounds[1] else 'OUTSIDE'}",
    ]
    print("\n" + "\n".join(lines))
    if args.out is None:
        return
    args.out.mkdir(parents=True, exist_ok=True)
    stem = "indexed_alignment" + ("" if args.site == "static" else f"_moored_{args.gnss}")
    (args.out / f"{stem}.json").write_text(json.dumps(
        dict(draws=rows, stop_s=args.stop, medians_arcmin=med, nees=nees, nees_bounds=bounds), indent=1) + "\n")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 4.5))
    late = t_rec >= 120.0
    aid = "zero velocity" if args.site == "static" else "GNSS"
    for sig, label, c in ((sig_static, f"{fixed}, table fixed", "C0"),
                          (sig_idx, f"navigation filter, {aid}, two-position every {args.stop:g} s", "C3")):
        s = np.median(np.array(sig), axis=0) / ARCMIN_TO_RAD
        ax.semilogy(t_rec[late], s[late], color=c, label=f"{label}: filter's heading sigma (median)")
    ax.axhline(med["limit_arcmin"], color="k", ls="--", label="static limit (median |eps_E / (Omega cos L)|)")
    ax.set_xlabel("time [s] (coarse alignment 0-120 s)")
    ax.set_ylabel("heading sigma [arcmin]")
    ax.legend(fontsize=8)
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(args.out / f"{stem}.png", dpi=110)
    table = [f"| draw | heading | static limit | {fixed} | indexed | indexed sigma |", "|---|---|---|---|---|---|"]
    table += [f"| {r['draw']} | {r['heading_deg']} deg | {r['limit_arcmin']:+.3f}' | {r['static_arcmin']:+.3f}' | "
              f"{r['indexed_arcmin']:+.3f}' | {r['indexed_sigma_arcmin']:.3f}' |" for r in rows]
    (args.out / f"{stem}.md").write_text(
        "# Alignment below the static limit by indexing the table\n\n"
        f"Written by `.venv/bin/python tools/indexed_alignment.py --draws {n} --stop {args.stop:g} --site "
        f"{args.site}{' --gnss ' + args.gnss if args.site == 'moored' else ''} --out docs/results` (the set-up: "
        f"its docstring and the built-in scenario `{SITES[args.site][0]}`).\n\n"
        + "\n\n".join(lines) + f"\n\n![heading sigma]({stem}.png)\n\n" + "\n".join(table) + "\n")


if __name__ == "__main__":
    main()
