#!/usr/bin/env python3
"""Alignment of a ship under way (the alignment issue's acceptance 2): the
coarse alignment FIT_VEL with a GNSS velocity, then the navigation filter.

    .venv/bin/python tools/underway_alignment.py [--headings 6] [--seeds 10] [--out docs/results]

The ship: the built-in scenario `under_way` (12 kn in seed 000's general sea
state: its pitch and roll swing and 0.5 m of heave at 8 s; GNSS at 1 Hz with
3 m and 0.05 m/s of white noise, no bias; the table fixed). Cell (h, s):
course 60 h deg, noise seed s for the IMU and 100 + 10 h + s for the
receiver, seed 000's sensor errors drawn from their 1-sigma values
(`pyins.sim.sensors.draw_random_constants`, draw 10 h + s). Two tracks per
cell, 720 s each (120 s coarse, 600 s navigation filter):
- ``straight``: the course held;
- ``turn``: 300 s on it, a 90 deg turn to port in 120 s (peak 1.5 deg/s),
  300 s on the new course.
Per cell and track: the heading error at the coarse alignment's end (its
last solution, 120 s) and after 10 min of fine alignment (720 s), the
static limits eps_E / (Omega cos L) - tan L nabla_E / g at the first and
the last course (`pyins.analysis.alignment_limits`), and the records that
say ATT_VALID while the heading is more than 10' off. Printed: the medians
and the 90 % spread; with --out, OUT/underway_alignment.{md,json}.
"""
import argparse
import json
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from pyins import analysis, metrics, scenario
from pyins.reference import abi
from pyins.run_scenario import run
from pyins.sim.sensors import draw_random_constants, random_constant_overrides
from pyins.units import ARCMIN_TO_RAD, DEG_TO_RAD

#: A record more than this far off in heading must not say ATT_VALID.
VALID_LIMIT = 10.0 * ARCMIN_TO_RAD
TRACKS = {
    "straight": '[{ kind = "cruise", duration = "720 s" }]',
    "turn": '[{ kind = "cruise", duration = "300 s" }, { kind = "turn", duration = "120 s", angle = "90 deg" }, '
            '{ kind = "cruise", duration = "300 s" }]',
}
BASE_SEGMENTS = 'segments = [{ kind = "cruise", duration = "720 s" }]'
BASE_GNSS_SEED = "seed = 5"


def spec_of(h, s, track):
    """The run of cell (h, s) on ``track``."""
    text = Path(scenario.builtin_path("under_way")).read_text()
    assert BASE_SEGMENTS in text and BASE_GNSS_SEED in text
    text = text.replace(BASE_SEGMENTS, f"segments = {TRACKS[track]}")
    text = text.replace(BASE_GNSS_SEED, f"seed = {100 + 10 * h + s}")
    draw = 10 * h + s
    over = dict(random_constant_overrides("seed000", draw), **{"motion.heading": f"{60 * h} deg", "seed": s})
    return next(iter(scenario.loads(text, name="under_way").with_overrides(over).runs())), draw


def one(args):
    """The figures of cell (h, s) on ``track``."""
    h, s, track = args
    spec, draw = spec_of(h, s, track)
    res = run(spec)
    e = metrics.nav_errors(res)
    o = res.outputs
    valid = (o["state_flags"] & abi.PYINS_STATE_ATT_VALID) != 0
    err = e.att_n_rad[:, 2]
    coarse = np.flatnonzero(o["mode"] == abi.PYINS_MODE_COARSE_ALIGN)
    k120 = int(coarse[-1])
    lat, _, _, _, euler = scenario.initial_truth(spec.motion)
    eb = draw_random_constants("seed000", draw)
    lim0 = analysis.alignment_limits(lat, euler, eb.gyro_bias, eb.accel_bias).phi_n[2]
    euler1 = np.array(euler, dtype=float)
    if track == "turn":
        euler1[2] = euler1[2] + 90.0 * DEG_TO_RAD
    lim1 = analysis.alignment_limits(lat, euler1, eb.gyro_bias, eb.accel_bias).phi_n[2]
    bad = valid & (np.abs(err) > VALID_LIMIT)
    return dict(heading_deg=60 * h, seed=s, track=track, coarse_t_s=float(e.time_s[k120]),
                coarse_arcmin=err[k120] / ARCMIN_TO_RAD, end_arcmin=err[-1] / ARCMIN_TO_RAD,
                sigma_end_arcmin=float(o["nav_sigma_heading_rad"][-1]) / ARCMIN_TO_RAD,
                limit_arcmin=lim0 / ARCMIN_TO_RAD, limit_end_arcmin=lim1 / ARCMIN_TO_RAD,
                valid_when_off=int(bad.sum()), valid_end=bool(valid[-1]),
                faults=int(np.bitwise_or.reduce(o["fault_flags"])))


def summary(rows):
    lines = []
    for track in TRACKS:
        r = [x for x in rows if x["track"] == track]
        if not r:
            continue
        c = np.abs([x["coarse_arcmin"] for x in r]) / 60.0
        end = np.abs([x["end_arcmin"] for x in r])
        d0 = np.abs([x["end_arcmin"] - x["limit_arcmin"] for x in r])
        below = [abs(x["end_arcmin"]) < min(abs(x["limit_arcmin"]), abs(x["limit_end_arcmin"])) for x in r]
        lim = np.abs([x["limit_arcmin"] for x in r])
        nees = np.mean([(x["end_arcmin"] / x["sigma_end_arcmin"]) ** 2 for x in r])
        lines.append(
            f"  {track:8s} ({len(r)} cells): coarse |heading| at 120 s median {np.median(c):.3f} deg "
            f"(90 %: {np.percentile(c, 90):.3f} deg, worst {c.max():.3f} deg); at 720 s median {np.median(end):.3f}' "
            f"(90 %: {np.percentile(end, 90):.3f}'), from the static limit median {np.median(d0):.3f}' "
            f"(90 %: {np.percentile(d0, 90):.3f}'), |limit| median {np.median(lim):.3f}'; below both courses' "
            f"limits in {sum(below)} of {len(r)}; heading NEES at 720 s {nees:.2f}; valid at the end "
            f"{sum(x['valid_end'] for x in r)} of {len(r)}; ATT_VALID while > 10' off: "
            f"{sum(x['valid_when_off'] for x in r)} records; faults in {sum(1 for x in r if x['faults'])} cells")
    return lines


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--headings", type=int, default=6, help="courses 0, 60, ... deg (at most 6)")
    ap.add_argument("--seeds", type=int, default=10, help="seeds per course (at most 10)")
    ap.add_argument("--tracks", default="straight,turn", help="straight, turn or both")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", type=Path, default=None, help="write underway_alignment.{md,json} here")
    args = ap.parse_args()
    if not (1 <= args.headings <= 6 and 1 <= args.seeds <= 10):
        ap.error("--headings 1..6, --seeds 1..10")
    tracks = [t for t in args.tracks.split(",") if t]
    if any(t not in TRACKS for t in tracks):
        ap.error(f"--tracks: {', '.join(TRACKS)}")
    t0 = time.perf_counter()
    jobs = [(h, s, t) for t in tracks for h in range(args.headings) for s in range(args.seeds)]
    rows = []
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        for row in pool.map(one, jobs):
            rows.append(row)
            print(f"  {row['track']:8s} course {row['heading_deg']:3d} deg, seed {row['seed']}: coarse "
                  f"{row['coarse_arcmin']:+8.2f}' at {row['coarse_t_s']:.0f} s; at 720 s {row['end_arcmin']:+.3f}' "
                  f"(sigma {row['sigma_end_arcmin']:.3f}', limit {row['limit_arcmin']:+.3f}' / "
                  f"{row['limit_end_arcmin']:+.3f}'), valid when off {row['valid_when_off']}, faults "
                  f"{row['faults']} ({time.perf_counter() - t0:.0f} s)", flush=True)
    lines = [f"{len(rows)} runs ({args.headings} courses x {args.seeds} seeds x {len(tracks)} tracks), 12 kn, "
             "FIT_VEL 120 s then the navigation filter; GNSS 3 m, 0.05 m/s at 1 Hz; the table fixed:"]
    lines += summary(rows)
    print("\n" + "\n".join(lines))
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
        (args.out / "underway_alignment.json").write_text(json.dumps(dict(runs=rows, summary=lines), indent=1)
                                                          + "\n")
        (args.out / "underway_alignment.md").write_text(
            "# Alignment under way\n\nWritten by `tools/underway_alignment.py` (its docstring says what runs).\n\n"
            + "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
