#!/usr/bin/env python3
"""A moored ship ranging on its lines: slow surge and sway against the alignment.

    .venv/bin/python tools/papers/harbour_ranging.py [--out runs/harbour] [--seeds 5] [--jobs 1]

The ship is the built-in scenario harbour_ranging (moored_general's swing,
waves and 2 m lever arm, plus a slow surge and sway of the reference point),
the headings and noise seeds those of tools/papers/moored_alignment.py
(seed 000's six headings 0..300, the campaign seed000_swing's seed formula).
The slow component is varied over DISTURBANCES below (surge and sway of the
same amplitude and period, sway a quarter period behind, the phase turned
by 360 / N deg from seed to seed so that the seeds see the disturbance at
different phases), and the alignment over ALIGNMENTS: the issue's (FIT
120 s, then the moving-base 12-state filter 480 s) with a rigid site (the
firmware's default) and with the site-motion model (fine_site_accel), then
longer with the model, the coarse phase 120, 300 or 600 s (or one
alignment of your own: --coarse / --fine / --set).

Every record (1 s) of every run is checked: its marine heading against the
truth and its PYINS_STATE_ATT_VALID bit. Per disturbance: the largest
heading error among the ATT_VALID records, the records more than 10' off
that are still ATT_VALID (must be 0), the earliest ATT_VALID time (the
first valid record of each run: its median and largest over the runs, and
the runs that never become valid), and the heading error at 300 s and at the
end. Writes harbour.json and harbour.md into --out (~15 min with --jobs 2).
"""
import argparse
import json
import os
import sys
import time
import tomllib
from concurrent.futures import ProcessPoolExecutor

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reproduce_seed000 import HEADINGS, SWING  # noqa: E402

from pyins import campaign, native, scenario, sim  # noqa: E402
from pyins.units import ARCMIN_TO_RAD as ARCMIN  # noqa: E402
from pyins.units import TICK_HZ, TWO_PI  # noqa: E402

SCENARIO = "harbour_ranging"
#: the slow surge/sway: (amplitude [m], period [s]); None: moored_general's waves alone
DISTURBANCES = ((None, None), (0.5, 60), (0.5, 90), (0.5, 120), (0.5, 150), (0.5, 200),
                (1.0, 300), (2.0, 600))
#: moored_general's waves (pyins.sim.MOORED_SHIP), kept under the slow component
_SURGE = {"amplitude": "0.3 m", "period": "12 s", "phase": "0 deg"}
_SWAY = {"amplitude": "0.3 m", "period": "10 s", "phase": "0 deg"}
VALID_BIT = 1        # PYINS_STATE_ATT_VALID
NIS_BIT, WANDER_BIT = 256, 512   # PYINS_FAULT_ALIGN_INCONSISTENT, PYINS_FAULT_COARSE_UNSETTLED
BOUND = 10.0         # arcmin: firmware.cpp's kValidHeadingSigma; a record beyond it must not be valid
RECORD_EVERY = 100   # ticks: every record of the scenario (1 s)
_RIGID = {"firmware.fine_site_accel": None}      # the firmware's default: a rigid site
#: label -> (coarse, fine, further overrides); the scenario's own: fine_site_accel 1000 ug/sqrt(Hz)
ALIGNMENTS = {
    "120+480 s, rigid site": ("120 s", "480 s", _RIGID),
    "120+480 s, site model": ("120 s", "480 s", {}),
    "120+1080 s, site model": ("120 s", "1080 s", {}),
    "300+1500 s, site model": ("300 s", "1500 s", {}),
    "600+1200 s, site model": ("600 s", "1200 s", {}),
}


def ship_overrides(amp, period, phase_deg):
    """The scenario overrides of one slow disturbance (surge at phase_deg, sway 90 deg later)."""
    if amp is None:
        return {"motion.surge": [_SURGE], "motion.sway": [_SWAY]}
    slow = lambda ph: {"amplitude": f"{amp} m", "period": f"{period} s", "phase": f"{ph % 360:g} deg"}
    return {"motion.surge": [_SURGE, slow(phase_deg)], "motion.sway": [_SWAY, slow(phase_deg + 90.0)]}


def points(n_seeds, headings=HEADINGS):
    """heading [deg] -> [Scenario]: harbour_ranging at that mean heading, one per noise seed
    (seed000_swing's seed formula, as tools/papers/moored_alignment.py)."""
    swing = campaign.load_campaign(SWING)
    camp = campaign.from_args(SCENARIO, {"motion.heading": [f"{h} deg" for h in headings]},
                              seeds=n_seeds, seed_formula=swing.seed_formula, compare="drop")
    out = {h: [] for h in headings}
    for point in camp.points:
        heading = int(point.values["motion.heading"].split()[0])
        out[heading].append(camp.base.with_overrides(point.overrides))
    return out


def wrap(a):
    return (a + np.pi) % TWO_PI - np.pi


def run_one(job):
    """One run: (scenario, disturbance, seed index, n_seeds, alignment overrides) -> its records'
    (t [s], |heading err| [arcmin], valid, heading sigma [arcmin]) and the coarse wander."""
    scn, (amp, period), s, n_seeds, align = job
    scn = scn.with_overrides({**ship_overrides(amp, period, 360.0 * s / n_seeds), **align})
    (spec,) = scn.runs()
    n = spec.duration_ticks
    dtheta, dv, _ = sim.exact_increments(spec.motion, n)
    dtheta, dv = sim.SensorModel(spec.errors, seed=spec.seed).apply(dtheta, dv)
    cfg = scenario.initial_config(spec.motion, None, **spec.config)
    rec = native.Firmware(cfg).run(native.make_samples(dtheta, dv), every=RECORD_EVERY)
    truth = sim.truth_at(spec.motion, rec["tick"])
    err = np.abs(wrap(rec["euler_b_rad"][:, 2] - truth.euler[:, 2])) / ARCMIN
    return dict(t=(rec["tick"] / TICK_HZ).tolist(), err=err.tolist(),
                valid=((rec["state_flags"] & VALID_BIT) != 0).tolist(),
                sigma=(rec["kf_sigma"][:, 2] / ARCMIN).tolist(),
                wander=float(rec["coarse_wander_rad"][-1]) / ARCMIN,
                faults=int(rec["fault_flags"][-1]))


def summarise(runs, t_end):
    errs_valid = [e for r in runs for e, v in zip(r["err"], r["valid"]) if v]
    wrong_valid = sum(1 for r in runs for e, v in zip(r["err"], r["valid"]) if v and e > BOUND)
    firsts = [next((t for t, v in zip(r["t"], r["valid"]) if v), None) for r in runs]
    seen = [f for f in firsts if f is not None]

    def at(t):
        v = [r["err"][r["t"].index(t)] for r in runs if t in r["t"]]
        return max(v) if v else None

    return dict(runs=len(runs), records=sum(len(r["t"]) for r in runs),
                worst_valid_heading_err_arcmin=max(errs_valid) if errs_valid else None,
                wrong_but_valid_records=wrong_valid,
                wrong_but_valid_runs=sum(1 for r in runs
                                         if any(v and e > BOUND for e, v in zip(r["err"], r["valid"]))),
                first_valid_s_median=float(np.median(seen)) if seen else None,
                first_valid_s_max=max(seen) if seen else None,
                never_valid_runs=len(firsts) - len(seen),
                heading_err_300s_max_arcmin=at(300.0), heading_err_end_max_arcmin=at(t_end),
                valid_at_end_runs=sum(1 for r in runs if r["valid"][-1]),
                sigma_end_median_arcmin=float(np.median([r["sigma"][-1] for r in runs])),
                wander_max_arcmin=max(r["wander"] for r in runs),
                coarse_unsettled_runs=sum(1 for r in runs if r["faults"] & WANDER_BIT),
                inconsistent_runs=sum(1 for r in runs if r["faults"] & NIS_BIT))


def fmt(v, spec=".1f"):
    return "-" if v is None else format(v, spec)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="runs/harbour")
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--headings", default=",".join(str(h) for h in HEADINGS))
    ap.add_argument("--disturbances", default=None,
                    help="indices into DISTURBANCES, e.g. 3,7 (default: all)")
    ap.add_argument("--coarse", default=None, help="coarse alignment length, e.g. '300 s'")
    ap.add_argument("--fine", default=None, help="fine alignment length, e.g. '480 s'")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="a further scenario override (TOML value), e.g. firmware.coarse_ratio=0.5")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--label", default="", help="a line naming the build measured (for the .md)")
    args = ap.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    headings = tuple(int(h) for h in args.headings.split(","))
    dists = (DISTURBANCES if args.disturbances is None
             else tuple(DISTURBANCES[int(i)] for i in args.disturbances.split(",")))
    if args.coarse or args.fine or args.set:
        extra = {}
        for item in args.set:
            key, _, value = item.partition("=")
            extra[key.strip()] = tomllib.loads(f"v = {value}")["v"]
        variants = {"custom": (args.coarse or "120 s", args.fine or "1080 s", extra)}
    else:
        variants = ALIGNMENTS
    base = scenario.load(SCENARIO)
    t0 = time.time()
    scns = points(args.seeds, headings)
    jobs, lengths = [], {}
    for label, (coarse, fine, extra) in variants.items():
        align = {"firmware.coarse_time": coarse, "firmware.fine_time": fine, **extra}
        (spec0,) = base.with_overrides({**align, "duration": "1 d"}).runs()   # the lengths alone
        c_s = spec0.config["coarse_ticks"] / TICK_HZ
        f_s = spec0.config["fine_ticks"] / TICK_HZ
        lengths[label] = (c_s, f_s, spec0.config.get("fine_site_accel", 0.0))
        align["duration"] = f"{c_s + f_s:g} s"
        jobs += [(label, (scn, d, s, args.seeds, align)) for d in dists
                 for h in headings for s, scn in enumerate(scns[h])]
    if args.jobs > 1:
        with ProcessPoolExecutor(args.jobs) as ex:
            results = list(ex.map(run_one, [j for _, j in jobs], chunksize=2))
    else:
        results = [run_one(j) for _, j in jobs]
    per = {}
    for (label, (_, d, _, _, _)), r in zip(jobs, results):
        per.setdefault((label, d), []).append(r)
    summary = {}
    md = ["Written by `.venv/bin/python tools/papers/harbour_ranging.py --seeds " + str(args.seeds)
          + (f" --coarse '{args.coarse}'" if args.coarse else "")
          + (f" --fine '{args.fine}'" if args.fine else "")
          + "".join(f" --set '{item}'" for item in args.set) + "`"
          + (f" ({args.label})" if args.label else "")
          + f": headings {', '.join(str(h) for h in headings)} deg x {args.seeds} seeds; every "
          "record (1 s) of every run checked. Alignment: FIT coarse + moving-base 12-state filter, "
          "lengths in seconds; 'site model': fine_site_accel = "
          + ", ".join(sorted({f"{v[2] / 9.80665e-6:.0f} ug/sqrt(Hz)" for v in lengths.values() if v[2]}))
          + "; 'rigid site': 0 (the firmware's default).",
          "",
          "| alignment | slow surge+sway | runs | worst \\|heading err\\| while ATT_VALID (') | records > 10' "
          "and ATT_VALID | first ATT_VALID, median / latest (s) | never valid | \\|heading err\\| at 300 s, "
          "at the end (worst, ') | valid at the end | heading sigma at the end (median, ') | coarse wander (worst, ') "
          "| runs flagged: coarse unsettled, NIS |",
          "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    total_wrong = 0
    for label in variants:
        c_s, f_s, _ = lengths[label]
        for d in dists:
            s = summarise(per[(label, d)], c_s + f_s)
            name = "none (moored_general)" if d[0] is None else f"{d[0]:g} m at {d[1]:g} s"
            summary[f"{label} / {name}"] = s
            total_wrong += s["wrong_but_valid_records"]
            md.append(f"| {label} | {name} | {s['runs']} | {fmt(s['worst_valid_heading_err_arcmin'], '.2f')} | "
                      f"{s['wrong_but_valid_records']} ({s['wrong_but_valid_runs']} runs) | "
                      f"{fmt(s['first_valid_s_median'], '.0f')} / {fmt(s['first_valid_s_max'], '.0f')} | "
                      f"{s['never_valid_runs']} | {fmt(s['heading_err_300s_max_arcmin'])}, "
                      f"{fmt(s['heading_err_end_max_arcmin'])} | {s['valid_at_end_runs']} | "
                      f"{s['sigma_end_median_arcmin']:.2f} | {s['wander_max_arcmin']:.1f} | "
                      f"{s['coarse_unsettled_runs']}, {s['inconsistent_runs']} |")
    md.append("")
    md.append(f"Records more than {BOUND:g}' off in heading and flagged ATT_VALID, per alignment: "
              + "; ".join(f"{label}: {sum(summary[f'{label} / ' + ('none (moored_general)' if d[0] is None else f'{d[0]:g} m at {d[1]:g} s')]['wrong_but_valid_records'] for d in dists)}"
                          for label in variants) + ".")
    out = {"seeds": args.seeds, "headings_deg": list(headings),
           "alignments": {k: dict(coarse_s=v[0], fine_s=v[1], fine_site_accel=v[2]) for k, v in lengths.items()},
           "label": args.label, "wrong_but_valid_records": total_wrong,
           "wall_s": time.time() - t0, "disturbances": summary}
    with open(os.path.join(args.out, "harbour.json"), "w") as f:
        json.dump(out, f, indent=1)
    with open(os.path.join(args.out, "harbour.md"), "w") as f:
        f.write("\n".join(md) + "\n")
    print("\n".join(md))
    print(f"wall {time.time() - t0:.0f} s; {args.out}/harbour.json")
    return 0


if __name__ == "__main__":
    sys.exit(main())
