#!/usr/bin/env python3
"""The integrated navigation filter's heading error budget at sea: what
each of seed 002's error terms, alone at its +1 sigma, leaves in the
heading, against the filter's own heading sigma.

    .venv/bin/python tools/nav_error_budget.py [--hours 24] [--noise-seeds 4] [--noise-first 0]
                                               [--workers 1] [--only "gyro mis m_xy" ...] [--check-draw D]
                                               [--save runs/budget.npz]

The voyage, the indexing and the filter's settings are tools/nees_gnss.py's
acceptance run (`pyins.sim.default_voyage`, route seed 1; two-position
indexing in the closed loop; the filter told seed 002's grade, `--prior
seed002`, and its four gyro-error priors at 10 ppm / 10 arcsec). Each run
is noise-free and starts from the true state but for one term: a random
constant of seed 002 (a bias, a scale factor, a misalignment; the ones the
filter's 19 states carry and the ones they do not) or one of the filter's
initial errors at its prior (attitude 2', 2', 10'; velocity 0.1 m/s;
position 10 m). The noise (the gyros' and accelerometers' white noise at
seed 002's densities and the GNSS's 3 m / 0.05 m/s) is run on its own with
`--noise-seeds` seeds; the GNSS fixes of the other runs are the truth, the
filter told 3 m / 0.05 m/s as always.

The filter is linear in these errors at their size (arc-seconds, ppm), so
a unit whose terms are drawn independently, each with its sigma, has an
expected squared heading error of the sum of the terms' squares plus the
noise's mean square: the Monte Carlo of tools/nees_gnss.py --errors
seed002-draws without its sampling spread, and split by term. Printed, at
a few times: each term's heading error [arcsec], the filter's heading
sigma, the root-sum-squares of the terms the filter models, of those it
leaves out, of the initial errors and of the noise, and the expected mean
NEES, the total's square over the sigma's (1 when the filter is
consistent; the terms it leaves out add their share on top).
``--check-draw D``: also run unit D of seed 002's production (every
random constant drawn, `draw_random_constants("seed002", D)`, no noise,
no initial error) and print its heading error against the sum of the
terms' errors weighted with D's normals: the linearity the budget rests
on. ``--only``: run these terms alone (their names as printed; the others
count as 0, and the sums say so): the long voyages, where a run of every
term takes hours. ``--save``: the trajectories to an .npz.
"""
import argparse
import concurrent.futures
import os
import sys
import time
from dataclasses import replace

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import nees_gnss  # noqa: E402  (the acceptance run's settings and one run of it)
from pyins import contract, sim  # noqa: E402
from pyins.sim import references  # noqa: E402
from pyins.sim.sensors import PRESETS, RANDOM_CONSTANT_TERMS, random_constant_normals  # noqa: E402
from pyins.units import ARCMIN_TO_RAD, DT  # noqa: E402

ARCSEC = ARCMIN_TO_RAD / 60.0
TABLE = (10.0, 10.0)    # nav_table_scale_sigma [ppm], nav_table_mis_sigma [arcsec]: seed 002's gyros
LEVEL = (10.0, 10.0)    # nav_level_scale_sigma, nav_level_mis_sigma

# (name, field of SensorErrors, index into it, carried by the filter's 19 states)
_XYZ = "xyz"
TERMS = ([(f"gyro bias {a}", "gyro_bias", i, True) for i, a in enumerate(_XYZ)]
         + [(f"gyro scale k_{a}", "gyro_scale", i, True) for i, a in enumerate(_XYZ)]
         + [(f"gyro mis m_{_XYZ[r]}{_XYZ[c]}", "gyro_misalignment", (r, c), r < 2)
            for r in range(3) for c in range(3) if r != c]
         + [(f"accel bias {a}", "accel_bias", i, i < 2) for i, a in enumerate(_XYZ)]
         + [(f"accel scale {a}", "accel_scale", i, False) for i, a in enumerate(_XYZ)]
         + [(f"accel mis a_{_XYZ[r]}{_XYZ[c]}", "accel_misalignment", (r, c), False)
            for r in range(3) for c in range(3) if r > c])
INITIAL = ([(f"initial phi_{a}", "phi", i) for i, a in enumerate("ENU")]
           + [(f"initial dv_{a}", "dv", i) for i, a in enumerate("EN")]
           + [(f"initial dp_{a}", "dp", i) for i, a in enumerate("EN")])
# Where each field's normals start in random_constant_normals (its fields in RANDOM_CONSTANT_TERMS' order,
# a matrix row by row).
_NORMAL_INDEX = {term: int(sum(np.size(getattr(sim.SensorErrors(), t)) for t, _, _ in RANDOM_CONSTANT_TERMS[:k]))
                 for k, (term, _, _) in enumerate(RANDOM_CONSTANT_TERMS)}


def _normal_of(field, idx, z):
    """The standard normal that draws (field, idx) in random_constant_normals."""
    k = idx if isinstance(idx, int) else 3 * idx[0] + idx[1]
    return z[_NORMAL_INDEX[field] + k]


def _quiet(sens):
    """``sens`` without its white noise."""
    return replace(sens, gyro_arw=0.0, accel_vrw=0.0)


def _term_errors(field, idx):
    """No error but seed 002's +1 sigma of (field, idx)."""
    sens = sim.SensorErrors()
    v = getattr(sens, field).copy()
    v[idx] = abs(getattr(PRESETS["seed002"], field)[idx])
    return replace(sens, **{field: v})


_MOTIONS = {}


def _gnss(motion, n, noisy, seed=0):
    """Fixes at 1 Hz told 3 m (5 m up) / 0.05 m/s; their values the truth
    unless ``noisy`` (then that noise, seeded)."""
    g = references.gnss(motion, n * DT, seed=2000 + seed, bias_sigma_m=0.0)
    refs = g.refs.astype(contract.REF_DTYPE)
    if not noisy:
        exact = references.gnss(motion, n * DT, seed=0, bias_sigma_m=0.0, pos_noise_m=0.0, vel_noise_mps=0.0)
        refs["value"] = exact.refs["value"]
    return refs, g.avail_tick


def _run(job):
    """One run of the budget: job = (hours, kind, spec)."""
    hours, kind, spec = job
    if hours not in _MOTIONS:
        _MOTIONS[hours] = sim.default_voyage(hours, seed=1)
    motion = _MOTIONS[hours]
    n = int(round(hours * 3600.0 / DT))
    init = {"phi": np.zeros(3), "dv": np.zeros(2), "dp": np.zeros(2)}
    seed = 0
    if kind == "term":
        sens = _term_errors(*spec)
    elif kind == "initial":
        field, i = spec
        init[field][i] = {"phi": nees_gnss.SIGMA0_ATT[i], "dv": nees_gnss.SIGMA0_VEL,
                          "dp": nees_gnss.SIGMA0_POS}[field]
        sens = sim.SensorErrors()
    elif kind == "noise":
        seed = spec
        p = PRESETS["seed002"]
        sens = sim.SensorErrors(gyro_arw=p.gyro_arw, accel_vrw=p.accel_vrw)
    else:  # "draw": a whole unit, no noise
        sens = _quiet(sim.sensors.draw_random_constants("seed002", spec))
    cfg = nees_gnss.filter_config(motion, "seed002", TABLE, 0.0, LEVEL, init["phi"], init["dv"], init["dp"])
    refs, avail = _gnss(motion, n, kind == "noise", seed)
    t, head, sig, _, _ = nees_gnss.fly(motion, n, sens, seed, cfg, refs, avail, True)
    return t, head, sig


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hours", type=float, default=24.0)
    ap.add_argument("--noise-seeds", type=int, default=4)
    ap.add_argument("--noise-first", type=int, default=0, help="the first noise seed (more seeds in another run)")
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--check-draw", type=int, default=None)
    ap.add_argument("--only", nargs="+", default=None, metavar="TERM",
                    help="only these terms (names as printed), the rest counted as 0")
    ap.add_argument("--save", default=None, help="an .npz for the trajectories")
    args = ap.parse_args()
    terms_run, initial_run = TERMS, INITIAL
    if args.only is not None:
        known = [x[0] for x in TERMS] + [x[0] for x in INITIAL]
        unknown = [name for name in args.only if name not in known]
        if unknown:
            ap.error(f"--only: no term {', '.join(map(repr, unknown))}; the terms: {', '.join(known)}")
        if args.check_draw is not None:
            ap.error("--check-draw needs every term (the unit's error is their sum): not with --only")
        terms_run = [x for x in TERMS if x[0] in args.only]
        initial_run = [x for x in INITIAL if x[0] in args.only]
    if args.workers < 1 or args.noise_seeds < 1 or args.noise_first < 0:
        ap.error("--workers and --noise-seeds: at least 1; --noise-first: at least 0")
    noise_seeds = range(args.noise_first, args.noise_first + args.noise_seeds)
    if not args.hours * 3600.0 > 600.0:
        ap.error(f"--hours {args.hours:g}: more than 10 min")
    jobs = ([(args.hours, "term", (f, i)) for _, f, i, _ in terms_run]
            + [(args.hours, "initial", (f, i)) for _, f, i in initial_run]
            + [(args.hours, "noise", s) for s in noise_seeds])
    names = ([t[0] for t in terms_run] + [t[0] for t in initial_run]
             + [f"noise seed {s}" for s in noise_seeds])
    if args.check_draw is not None:
        jobs.append((args.hours, "draw", args.check_draw))
        names.append(f"unit {args.check_draw}")
    t0 = time.perf_counter()
    out = []
    pool = concurrent.futures.ProcessPoolExecutor(args.workers)
    with pool:
        for name, r in zip(names, pool.map(_run, jobs)):
            out.append(r)
            print(f"  {name}: done ({time.perf_counter() - t0:.0f} s)", flush=True)
    t = out[0][0]
    sig = out[0][2]
    head = np.array([r[1] for r in out])
    nt, ni = len(terms_run), len(initial_run)
    terms, initial = head[:nt], head[nt:nt + ni]
    noise = head[nt + ni:nt + ni + args.noise_seeds]
    modelled = np.array([m for *_, m in terms_run], dtype=bool)
    groups = {"modelled terms (RSS)": np.sqrt(np.sum(terms[modelled] ** 2, axis=0)),
              "unmodelled terms (RSS)": np.sqrt(np.sum(terms[~modelled] ** 2, axis=0)),
              "initial errors (RSS)": np.sqrt(np.sum(initial ** 2, axis=0)),
              "noise (RMS over seeds)": np.sqrt(np.mean(noise ** 2, axis=0))}
    total_model = np.sqrt(groups["modelled terms (RSS)"] ** 2 + groups["initial errors (RSS)"] ** 2
                          + groups["noise (RMS over seeds)"] ** 2)
    total = np.sqrt(total_model ** 2 + groups["unmodelled terms (RSS)"] ** 2)
    times = sorted({3600, *range(6 * 3600, int(args.hours * 3600), 6 * 3600), int(args.hours * 3600) - 1})
    ks = [int(np.searchsorted(t, ts)) for ts in times if int(np.searchsorted(t, ts)) < len(t)]
    print(f"\nheading error [arcsec] of each term alone at seed 002's +1 sigma, voyage {args.hours:g} h, "
          "two-position indexing, the filter told seed 002's grade")
    print(f"{'':28s}" + "".join(f"{t[k] / 3600:9.1f} h" for k in ks))
    rows = ([(n, terms[j], m) for j, (n, _f, _i, m) in enumerate(terms_run)]
            + [(n, initial[j], True) for j, (n, *_r) in enumerate(initial_run)])
    for name, v, carried in rows:
        flag = "" if carried else " *"
        print(f"{name + flag:28s}" + "".join(f"{v[k] / ARCSEC:11.2f}" for k in ks))
    print("(* not a state of the filter)")
    if args.only is not None:
        print(f"(only {len(terms_run) + len(initial_run)} of the {len(TERMS) + len(INITIAL)} terms run: the "
              "sums below leave the others out)")
    for name, v in groups.items():
        print(f"{name:28s}" + "".join(f"{v[k] / ARCSEC:11.2f}" for k in ks))
    print(f"{'the filter sigma':28s}" + "".join(f"{sig[k] / ARCSEC:11.2f}" for k in ks))
    late = t >= 600.0
    for name, v in (("expected NEES, modelled", total_model), ("expected NEES, all", total)):
        nees = (v / sig) ** 2
        print(f"{name:28s}" + "".join(f"{nees[k]:11.3f}" for k in ks)
              + f"   time average after 10 min {nees[late].mean():.3f}")
    if args.check_draw is not None:
        z = random_constant_normals(args.check_draw)
        pred = sum(_normal_of(f, i, z) * terms[j] for j, (_, f, i, _) in enumerate(terms_run))
        got = head[-1]
        print(f"\nunit {args.check_draw} (no noise, no initial error): heading error [arcsec] as run, and the "
              "terms' sum with its normals")
        print(f"{'as run':28s}" + "".join(f"{got[k] / ARCSEC:11.2f}" for k in ks))
        print(f"{'sum of the terms':28s}" + "".join(f"{pred[k] / ARCSEC:11.2f}" for k in ks))
        print(f"largest difference after 10 min: {np.max(np.abs(got - pred)[late]) / ARCSEC:.3f} arcsec")
    if args.save:
        np.savez_compressed(args.save, t=t, sigma=sig, head=head, names=np.array(names))
        print(f"saved {args.save}")


if __name__ == "__main__":
    main()
