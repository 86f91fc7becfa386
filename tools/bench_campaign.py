#!/usr/bin/env python3
"""Benchmark: what a Monte Carlo campaign costs per run, and whether a second
worker delivers a second core's worth (the Monte Carlo at scale issue).

    .venv/bin/python tools/bench_campaign.py [--hours 72] [--runs 4] [--json runs/bench/campaign.json]

Every run is a child process (os.wait4: its own peak resident set, user and
system CPU time, wall time; nothing of this script). The case is the
closed loop of `tools/bench_fil.py` (seed 002 experiment 1, flexible scheme,
seed 002's sensor errors, noise seeded per run).

1. Peak memory of one --hours run, four ways: `pyins.fil.run_fil` keeping
   a record every 1 s and every 60 s (the rate the campaign's metrics use:
   the built-in Monte Carlo campaigns record every 60 s), and the campaign's
   own path (`pyins.run_scenario.execute`: records streamed to disk, the
   metrics read back) at 1 s and at 60 s.
2. Flat over a campaign: --runs runs one after the other in one process (as
   a pool worker runs them), its peak after each run.
3. Runs per second with one worker and with two: --runs children one at a
   time, then two at a time (the same runs, seeds 0 .. runs-1), both in this
   one invocation. Printed: the ratio of the throughputs, each child's CPU
   time over its wall time (above 1: the run keeps more than one core busy,
   e.g. the noise drawn ahead on a helper thread), and the ratio the CPU
   times allow (2 / that share), so a shortfall can be put on the program
   (its helper thread, its memory traffic: the CPU time per run grows with
   two at once) or on the machine. Then the same with the noise drawn in
   the loop's own thread (``run_fil(draw_ahead=False)``: each run one
   core): two such workers against one, and against one drawing ahead.

4. (``--dask``) the campaign engine itself (`pyins.campaign.run_campaign`:
   a pool of workers that keep the libraries loaded) on --runs draws of
   seed 002 exp. 1 (flexible scheme, --dask-hours each): the local pool
   with one and two workers, and a Dask LocalCluster of one and two
   worker processes; runs per second of each, and the scheduler's cost per
   run (Dask's wall time less the local pool's of the same width, over the
   runs).

It prints and never asserts: the figures are for a person; docs/benchmarks.md
keeps them with their conditions (load, commit).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

CHILD = r"""
import sys, resource
mode, hours, every, seed, out = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), int(sys.argv[4]), sys.argv[5]
n_runs = int(sys.argv[6]) if len(sys.argv) > 6 else 1
ahead = mode != "run_fil_serial"
mode = "run_fil" if mode == "run_fil_serial" else mode
from pyins import fil, metrics, sim, scenario, run_scenario
peaks = []
for k in range(n_runs):
    if mode == "run_fil":
        res = fil.run_fil(sim.HeadingSwing.experiment(1), int(round(hours * 360_000)),
                          config=dict(index_scheme=4), errors=sim.preset("seed002"), seed=seed + k,
                          every=int(round(every * 100)), draw_ahead=ahead)
        metrics.nav_errors(res)
    else:
        scn = scenario.load("seed002_exp1").with_overrides(
            {"duration": f"{hours} h", "record_every": f"{every} s", "outputs.plots": False,
             "outputs.csv": False, "indexing.scheme": "flexible", "compare": None, "paper": None,
             "seed": seed + k})
        run_scenario.execute(scn, f"{out}/run{seed + k}", resume=False)
    peaks.append(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0)
print(" ".join(f"{p:.1f}" for p in peaks))
"""


def child(args):
    """Start one child: (Popen, start time)."""
    return subprocess.Popen([sys.executable, "-c", CHILD, *map(str, args)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True), time.perf_counter()


def reap(proc, t0):
    """Wait for one child: dict of its peak [MiB], wall, user, sys [s], stdout."""
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    out, err = proc.communicate()
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"a child failed: {err.strip()[-800:]}")
    return {"peak_mib": usage.ru_maxrss / 1024.0, "wall_s": wall, "user_s": usage.ru_utime,
            "sys_s": usage.ru_stime, "stdout": out.strip()}


def one(args):
    return reap(*child(args))


def batch(jobs, width):
    """Run ``jobs`` (argument lists) ``width`` at a time; (wall of all, results)."""
    t0 = time.perf_counter()
    running, done, queue = {}, [], list(jobs)
    while queue or running:
        while queue and len(running) < width:
            p, t = child(queue.pop(0))
            running[p.pid] = (p, t)
        pid, status, usage = os.wait4(-1, 0)
        if pid not in running:
            continue
        p, t = running.pop(pid)
        wall = time.perf_counter() - t
        out, err = p.communicate()
        if os.waitstatus_to_exitcode(status) != 0:
            raise SystemExit(f"a child failed: {err.strip()[-800:]}")
        done.append({"peak_mib": usage.ru_maxrss / 1024.0, "wall_s": wall, "user_s": usage.ru_utime,
                     "sys_s": usage.ru_stime})
    return time.perf_counter() - t0, done


def engine_section(a, work):
    """Section 4: the campaign engine, local pool and Dask LocalCluster, one and two workers."""
    from distributed import LocalCluster

    from pyins import campaign
    camp = campaign.from_args("seed002_exp1", {"indexing.scheme": ["flexible"]}, seeds=a.runs, compare="drop",
                              random_constants="seed002",
                              overrides={"duration": f"{a.dask_hours} h", "record_every": "60 s",
                                         "outputs.plots": False, "outputs.csv": False},
                              name="bench_campaign")
    print(f"\n4. the campaign engine: {a.runs} draws of seed 002 exp. 1, flexible, {a.dask_hours:g} h each")
    rows = {}
    for kind in ("local", "dask"):
        for width in (1, 2):
            out = os.path.join(work, f"engine_{kind}_{width}")
            t0 = time.perf_counter()
            if kind == "local":
                campaign.run_campaign(camp, out, workers=width, plots=False)
            else:
                with LocalCluster(n_workers=width, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
                    t0 = time.perf_counter()       # the cluster's start-up is not a run's cost
                    campaign.run_campaign(camp, out, scheduler=cluster.scheduler_address, plots=False)
            wall = time.perf_counter() - t0
            rows[f"{kind}_{width}"] = {"wall_s": wall, "runs_per_s": a.runs / wall}
            print(f"   {kind:5s} {width} worker{'s' if width > 1 else ' '}: {wall:6.1f} s, "
                  f"{a.runs / wall:.3f} runs/s")
    for width in (1, 2):
        over = (rows[f"dask_{width}"]["wall_s"] - rows[f"local_{width}"]["wall_s"]) / a.runs * width
        rows[f"dask_overhead_per_run_s_{width}"] = over
        print(f"   Dask's cost per run with {width} worker{'s' if width > 1 else ''}: {over:+.2f} s")
    for kind in ("local", "dask"):
        r = rows[f"{kind}_2"]["runs_per_s"] / rows[f"{kind}_1"]["runs_per_s"]
        rows[f"{kind}_ratio_two_to_one"] = r
        print(f"   {kind}: two workers / one {r:.2f}x")
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hours", type=float, default=72.0, help="ship time of a run (default 72 h)")
    ap.add_argument("--runs", type=int, default=4, help="runs for sections 2 and 3 (default 4)")
    ap.add_argument("--json", default=os.path.join("runs", "bench", "campaign.json"))
    ap.add_argument("--skip-memory", action="store_true", help="skip sections 1 and 2")
    ap.add_argument("--dask", action="store_true", help="also section 4 (needs dask, the campaign extra)")
    ap.add_argument("--dask-hours", type=float, default=12.0, help="ship time of a section-4 run (default 12 h)")
    a = ap.parse_args(argv)
    if a.hours <= 0 or a.runs < 2:
        ap.error("--hours must be > 0 and --runs at least 2")
    work = tempfile.mkdtemp(prefix="pyins_bench_campaign_")
    fig = {"hours": a.hours, "runs": a.runs, "load_1min_before": os.getloadavg()[0]}
    print(f"seed 002 exp. 1, flexible scheme, seed 002 errors, {a.hours:g} h a run; load {fig['load_1min_before']:.2f}")
    if not a.skip_memory:
        print("\n1. peak memory of one run (a child process each)")
        print(f"   {'path':44s} {'records':>8s} {'peak MiB':>9s} {'wall s':>7s} {'CPU s':>6s}")
        for mode, every in (("run_fil", 1), ("run_fil", 60), ("execute", 1), ("execute", 60)):
            r = one([mode, a.hours, every, 0, os.path.join(work, f"{mode}_{every}")])
            label = {"run_fil": "pyins.fil.run_fil (records in memory)",
                     "execute": "run_scenario.execute (the campaign's path)"}[mode]
            print(f"   {label:44s} {f'{every} s':>8s} {r['peak_mib']:9.0f} {r['wall_s']:7.1f} "
                  f"{r['user_s'] + r['sys_s']:6.1f}")
            fig[f"peak_mib_{mode}_{every}s"] = r["peak_mib"]
        print(f"\n2. {a.runs} runs one after another in one process (the campaign's path, 60-s records)")
        r = one(["execute", a.hours, 60, 0, os.path.join(work, "flat"), a.runs])
        peaks = [float(x) for x in r["stdout"].split()]
        print("   peak after each run [MiB]: " + ", ".join(f"{p:.0f}" for p in peaks))
        fig["peak_mib_after_each_run"] = peaks
    print(f"\n3. the closed loop ({a.hours:g} h, records every 60 s, run_fil) x {a.runs}: one worker, then two;"
          f"\n   the noise drawn ahead on a helper thread (run_fil's default), then in the loop's thread")
    rows = {}
    for key, width, mode in ((1, 1, "run_fil"), (2, 2, "run_fil"), ("serial_1", 1, "run_fil_serial"),
                             ("serial_2", 2, "run_fil_serial")):
        jobs = [[mode, a.hours, 60, s, work] for s in range(a.runs)]
        wall, done = batch(jobs, width)
        cpu = [d["user_s"] + d["sys_s"] for d in done]
        per = [d["wall_s"] for d in done]
        rows[key] = {"wall_s": wall, "runs_per_s": a.runs / wall,
                     "run_wall_s_median": sorted(per)[len(per) // 2],
                     "run_cpu_s_median": sorted(cpu)[len(cpu) // 2],
                     "cpu_share_median": sorted(c / w for c, w in zip(cpu, per))[len(per) // 2]}
        how = "ahead " if mode == "run_fil" else "serial"
        print(f"   {how} {width} worker{'s' if width > 1 else ' '}: {wall:6.1f} s for {a.runs} runs, "
              f"{rows[key]['runs_per_s']:.3f} runs/s; a run: {rows[key]['run_wall_s_median']:.2f} s wall, "
              f"{rows[key]['run_cpu_s_median']:.2f} s CPU (CPU / wall {rows[key]['cpu_share_median']:.2f})")
    ratio = rows[2]["runs_per_s"] / rows[1]["runs_per_s"]
    allowed = 2.0 / max(1.0, rows[1]["cpu_share_median"])
    growth = rows[2]["run_cpu_s_median"] / rows[1]["run_cpu_s_median"]
    print(f"   two workers / one: {ratio:.2f}x the runs per second (target 1.8x); what one run's CPU share "
          f"alone allows: {allowed:.2f}x; a run's CPU time with two at once / alone: {growth:.2f}")
    serial = rows["serial_2"]["runs_per_s"] / rows["serial_1"]["runs_per_s"]
    print(f"   the noise in the loop's thread: two workers / one {serial:.2f}x (each run one core); two "
          f"such workers / one worker drawing ahead {rows['serial_2']['runs_per_s'] / rows[1]['runs_per_s']:.2f}x")
    fig.update({"serial_one_worker": rows["serial_1"], "serial_two_workers": rows["serial_2"],
                "serial_throughput_ratio": serial})
    fig.update({"one_worker": rows[1], "two_workers": rows[2], "throughput_ratio": ratio,
                "ratio_cpu_share_allows": allowed, "cpu_time_growth_two_at_once": growth,
                "load_1min_after": os.getloadavg()[0]})
    if a.dask:
        fig["engine"] = engine_section(a, work)
    os.makedirs(os.path.dirname(os.path.abspath(a.json)), exist_ok=True)
    with open(a.json, "w") as f:
        json.dump(fig, f, indent=2)
    print(f"figures written to {a.json}")
    subprocess.run(["rm", "-rf", work])
    return 0


if __name__ == "__main__":
    sys.exit(main())
