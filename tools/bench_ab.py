#!/usr/bin/env python3
"""Benchmark: the closed loop of two commits side by side, in one run.

    .venv/bin/python tools/bench_ab.py BASE [NEW] [--hours 72] [--rounds 3] [--every 100]

Each commit (NEW defaults to HEAD) is exported with ``git archive`` into
build/ab/<sha>/ and its core and plant libraries built there with CMake
(Release, Ninja: the flags `pip install .` uses), once; then the same
closed loop runs in child processes that import that commit's pyins and
load that build's libraries (``PYINS_CORE_LIB``; the editable install's
finder is set aside in the child), alternating BASE, NEW, BASE, NEW ... so
both see the same load. The case is `tools/bench_fil.py`'s long run: seed
002 experiment 1, flexible scheme, seed 002's errors, ``--hours`` of ship
time with a record every ``--every`` ticks held in memory (100: the 1-s
records bench_fil.py keeps; 6000: the 60-s records of the Monte Carlo
campaigns).

Printed: each child's wall and CPU time and peak resident set, the medians,
and NEW / BASE per round (paired: the rounds share their moment's load) with
their median; and whether both gave the same final latitude bit for bit
(the same inputs must give the same bits unless a commit between them moved
them on purpose). It prints and never asserts.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tarfile
import io
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
AB = ROOT / "build" / "ab"

CHILD = r"""
import json, os, resource, sys, time
tree, hours, every = sys.argv[1], float(sys.argv[2]), int(sys.argv[3])
sys.meta_path[:] = [f for f in sys.meta_path if "ScikitBuild" not in type(f).__name__]
sys.path.insert(0, tree)
import pyins
from pyins import fil, sim
assert pyins.__file__.startswith(tree), pyins.__file__
m, errors, cfg = sim.HeadingSwing.experiment(1), sim.preset("seed002"), dict(index_scheme=4)
fil.run_fil(m, 1000, config=cfg, errors=errors, seed=1, every=every)       # warm-up
t0, c0 = time.perf_counter(), os.times()
res = fil.run_fil(m, int(round(hours * 360_000)), config=cfg, errors=errors, seed=1, every=every)
wall, c1 = time.perf_counter() - t0, os.times()
print(json.dumps({"wall_s": wall, "cpu_s": (c1.user + c1.system) - (c0.user + c0.system),
                  "peak_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
                  "lat_hex": float(res.outputs["lat_rad"][-1]).hex()}))
"""


def _sha(ref):
    return subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--verify", f"{ref}^{{commit}}"],
                          check=True, capture_output=True, text=True).stdout.strip()


def build(ref):
    """The tree of commit ``ref`` in build/ab/<sha>, its libraries built: (sha, tree, library dir)."""
    sha = _sha(ref)
    tree = AB / sha[:12]
    lib_dir = tree / "_build"
    if not (lib_dir / "libpyins_core.so").is_file() or not (lib_dir / "libpyins_plant.so").is_file():
        tree.mkdir(parents=True, exist_ok=True)
        blob = subprocess.run(["git", "-C", str(ROOT), "archive", sha], check=True, capture_output=True).stdout
        with tarfile.open(fileobj=io.BytesIO(blob)) as tar:
            tar.extractall(tree, filter="data")
        print(f"building {ref} ({sha[:12]}) in {tree} ...", flush=True)
        subprocess.run(["cmake", "-S", str(tree), "-B", str(lib_dir), "-G", "Ninja",
                        "-DCMAKE_BUILD_TYPE=Release"], check=True, capture_output=True)
        subprocess.run(["cmake", "--build", str(lib_dir), "--target", "pyins_core", "pyins_plant"],
                       check=True, capture_output=True)
    return sha, tree, lib_dir


def child(tree, lib_dir, hours, every):
    env = dict(os.environ, PYINS_CORE_LIB=str(lib_dir / "libpyins_core.so"))
    out = subprocess.run([sys.executable, "-c", CHILD, str(tree), str(hours), str(every)], env=env,
                         capture_output=True, text=True)
    if out.returncode != 0:
        raise SystemExit(f"the child for {tree} failed:\n{out.stderr[-2000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("base", help="the commit to compare against (a ref or sha)")
    ap.add_argument("new", nargs="?", default="HEAD", help="the commit to time (default HEAD)")
    ap.add_argument("--hours", type=float, default=72.0, help="ship time of a run (default 72 h)")
    ap.add_argument("--rounds", type=int, default=3, help="pairs of runs (default 3)")
    ap.add_argument("--every", type=int, default=100, help="ticks between kept records (default 100: 1 s)")
    ap.add_argument("--json", default=os.path.join("runs", "bench", "ab.json"))
    args = ap.parse_args(argv)
    if args.rounds < 1 or args.hours <= 0 or args.every < 1:
        raise SystemExit("--rounds and --every must be >= 1 and --hours > 0")
    sides = {"base": build(args.base), "new": build(args.new)}
    load = os.getloadavg()[0]
    print(f"{args.hours:g} h closed loop (seed 002 exp. 1, flexible, seed 002 errors), a record every "
          f"{args.every} ticks in memory; base {sides['base'][0][:12]}, new {sides['new'][0][:12]}; "
          f"load {load:.2f} before")
    runs = {"base": [], "new": []}
    for r in range(args.rounds):
        for side in ("base", "new"):
            _, tree, lib_dir = sides[side]
            res = child(tree, lib_dir, args.hours, args.every)
            runs[side].append(res)
            print(f"  round {r + 1} {side:4s}: {res['wall_s']:6.2f} s wall, {res['cpu_s']:6.2f} s CPU, "
                  f"peak {res['peak_mib']:4.0f} MiB", flush=True)
    ratios = [n["wall_s"] / b["wall_s"] for b, n in zip(runs["base"], runs["new"])]
    med = {s: statistics.median(x["wall_s"] for x in runs[s]) for s in runs}
    cpu = {s: statistics.median(x["cpu_s"] for x in runs[s]) for s in runs}
    same = {x["lat_hex"] for x in runs["base"]} == {x["lat_hex"] for x in runs["new"]}
    print(f"median wall: base {med['base']:.2f} s, new {med['new']:.2f} s; CPU base {cpu['base']:.2f} s, "
          f"new {cpu['new']:.2f} s")
    print(f"new / base, paired by round: {', '.join(f'{x:.3f}' for x in ratios)}; median "
          f"{statistics.median(ratios):.3f}")
    print(f"final latitude: {'the same bits' if same else 'DIFFERENT bits'} "
          f"({sorted({x['lat_hex'] for s in runs for x in runs[s]})})")
    os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
    with open(args.json, "w") as f:
        json.dump({"base": sides["base"][0], "new": sides["new"][0], "hours": args.hours, "every": args.every,
                   "load_before": load, "runs": runs, "ratios": ratios, "same_bits": same}, f, indent=2)
    print(f"figures written to {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
