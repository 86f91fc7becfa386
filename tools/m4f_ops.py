#!/usr/bin/env python3
"""Where the Cortex-M4F's instructions go in a navigation tick (soft doubles).

    .venv/bin/python tools/m4f_ops.py [--build build-m4]

Builds build-m4/ops.elf (csrc/embedded/ops_main.c; the cortex-m4 build
must be configured, as tools/embedded.sh does), runs it under QEMU with
-icount, and prints, for each double routine (libgcc's __aeabi_dmul,
__aeabi_dadd, __aeabi_dsub, __aeabi_ddiv, the comparisons, newlib's sqrt),
its cost per call on typical operands, how many calls one navigation tick
without a record makes (pyins_run with outputs NULL, the "nav" scenario of
csrc/embedded/bench_modes.h), and their product beside the tick's measured
total. Instruction counts (QEMU has no pipeline model), not cycles: the
lever of the M4F line of the cost is which operations a tick makes.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHIFT = 3      # as tools/size_report.py: the virtual clock's ns per instruction is 2^SHIFT
OP_REPEAT = 1000
OPS = ("dmul", "dadd", "dsub", "ddiv", "sqrt", "dcmp")


def run(build):
    subprocess.run(["cmake", "--build", build, "--target", "ops.elf"], check=True, cwd=ROOT,
                   stdout=subprocess.DEVNULL)
    if shutil.which("qemu-system-arm") is None:
        raise SystemExit("m4f_ops: qemu-system-arm is missing (tools/setup.sh installs it)")
    res = subprocess.run(["qemu-system-arm", "-M", "mps2-an386", "-nographic", "-semihosting", "-icount",
                          f"shift={SHIFT}", "-kernel", os.path.join(build, "ops.elf")],
                         capture_output=True, text=True, timeout=600)
    if res.returncode != 0 or "DONE" not in res.stdout:
        raise SystemExit(f"m4f_ops: ops.elf failed ({res.returncode}):\n{res.stdout}\n{res.stderr}")
    return res.stdout


def parse(text):
    cal = re.search(r"CAL nops (\d+) counts (\d+)", text)
    per_count = int(cal.group(1)) / int(cal.group(2))          # instructions per SysTick count
    op = {m.group(1): int(m.group(2)) for m in re.finditer(r"OP (\w+) counts (\d+)", text)}
    cost = {k: (op[k] - op["loop"]) * per_count / OP_REPEAT for k in OPS}
    nav = re.search(r"NAV ticks (\d+) counts (\d+)", text)
    ticks = int(nav.group(1))
    per_tick = int(nav.group(2)) * per_count / ticks
    calls_line = re.search(r"CALLS (.*)", text).group(1).split()
    calls = {calls_line[i]: int(calls_line[i + 1]) / ticks for i in range(0, len(calls_line), 2)}
    calls["dsub"] = calls.get("dsub", 0.0) + calls.pop("drsub", 0.0)
    return cost, calls, per_tick


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default=os.path.join(ROOT, "build-m4"))
    args = ap.parse_args(argv)
    cost, calls, per_tick = parse(run(args.build))
    print(f"Cortex-M4F, navigation tick without a record (pyins_run, outputs NULL): "
          f"{per_tick:,.0f} instructions")
    print(f"{'routine':10s} {'per call':>9s} {'calls/tick':>11s} {'per tick':>9s} {'share':>6s}")
    total = 0.0
    for k in OPS:
        t = cost[k] * calls[k]
        total += t
        print(f"{k:10s} {cost[k]:9.0f} {calls[k]:11.1f} {t:9,.0f} {100 * t / per_tick:5.1f}%")
    print(f"{'sum':10s} {'':9s} {'':11s} {total:9,.0f} {100 * total / per_tick:5.1f}%  "
          f"(the per-call costs are on fixed operands, not the tick's: the sum is an estimate)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
