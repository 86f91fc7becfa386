"""Peak memory and wall time of ``pyins simulate`` and ``pyins replay`` against
the length of the log (a long log was once held whole in memory): both
stream in blocks, so their peak should not grow with the log.

For each length (default 6 h and 24 h) it simulates a built-in scenario's
log (``demo``, binary, as a subprocess), then replays it (``--scenario``, so
the errors against the truth are computed too, and the report written), and
measures each child's peak resident set (``os.wait4``: the child's own
``ru_maxrss``, nothing of this script) and its wall time. It prints a table
with the ratio of the longest log's peak to the shortest's (the acceptance
line: within 20 %), plus, with ``--long 72``, a 72 h replay for the "under
60 s" line. It prints and never asserts: the figures are for a person.

    python tools/bench_memory.py                 # 6 h and 24 h, ~1.5 min
    python tools/bench_memory.py --long 72       # and a 72 h replay (~3 min more)
    python tools/bench_memory.py --hours 1 2     # quicker

Everything is written to a temporary directory, removed at the end
(``--keep DIR`` writes there and keeps it).
"""
import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time


def run(argv):
    """(peak RSS [MiB], wall [s], return code) of one child process."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    proc.returncode = os.waitstatus_to_exitcode(status)
    err = proc.stderr.read().decode(errors="replace")
    proc.stderr.close()
    if proc.returncode != 0:
        print(f"  {' '.join(argv)}: exit {proc.returncode}: {err.strip()[-500:]}", file=sys.stderr)
    return usage.ru_maxrss / 1024.0, wall, proc.returncode     # Linux: ru_maxrss in KiB


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hours", type=float, nargs="+", default=[6.0, 24.0],
                    help="log lengths [h] (default 6 24); the ratio is last/first")
    ap.add_argument("--long", type=float, default=None, metavar="H",
                    help="also simulate and replay a log of H hours (e.g. 72: the '< 60 s' line)")
    ap.add_argument("--scenario", default="demo", help="built-in scenario (default demo)")
    ap.add_argument("--format", default="binary", help="log format (default binary)")
    ap.add_argument("--keep", metavar="DIR", help="write into DIR and keep it")
    args = ap.parse_args(argv)
    ext = {"binary": ".bin", "text": ".txt", "csv": ".csv", "npz": ".npz"}[args.format]
    work = args.keep or tempfile.mkdtemp(prefix="pyins_bench_memory_")
    os.makedirs(work, exist_ok=True)
    pyins = [sys.executable, "-m", "pyins"]
    rows = []
    try:
        hours = list(args.hours) + ([args.long] if args.long else [])
        for h in hours:
            log = os.path.join(work, f"{args.scenario}_{h:g}h{ext}")
            print(f"  {h:g} h: simulate ...", file=sys.stderr, flush=True)
            rows.append(("simulate", h) + run(pyins + ["simulate", args.scenario, log, "--hours", str(h),
                                                       "--format", args.format, "--quiet"]))
            size = os.path.getsize(log) / 2**20 if os.path.exists(log) else float("nan")
            print(f"  {h:g} h: replay ({size:.0f} MiB log) ...", file=sys.stderr, flush=True)
            out = os.path.join(work, f"replay_{h:g}h")
            rows.append(("replay", h) + run(pyins + ["replay", log, "--scenario", args.scenario, "--out", out,
                                                     "--quiet"]))
            if os.path.exists(log) and not args.keep:
                os.remove(log)          # a 72 h binary log is 1.4 GB
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)
    first, last = args.hours[0], args.hours[-1]
    peak = {(c, h): m for c, h, m, _, _ in rows}
    print(f"\n{'command':<10} {'hours':>6} {'peak MiB':>9} {'wall s':>8}  {'exit':>4}  "
          f"ratio {last:g}h/{first:g}h")
    for command, h, mib, wall, rc in rows:
        ratio = ""
        if h == last and (command, first) in peak and last != first:
            ratio = f"{mib / peak[(command, first)]:.3f}"
        print(f"{command:<10} {h:>6g} {mib:>9.1f} {wall:>8.1f}  {rc:>4}  {ratio}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
