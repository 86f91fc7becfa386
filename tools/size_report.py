#!/usr/bin/env python3
"""Size, stack and cycle-budget report of the embedded builds (run after
tools/embedded.sh built them; tools/embedded.sh runs it).

    .venv/bin/python tools/size_report.py [--json runs/bench/size.json] [--no-cycles]
        [--m7-mhz 216] [--m4-mhz 168] [--cpi 1.0] [--ticks 3000]

Sizes, for Cortex-M7 and Cortex-M4F: text/data/bss of the core library (sum
of its objects) and of the demo image (arm-none-eabi-size), the firmware
instance size (pyins_core_size()). Budgets: core text <= 64 KiB and
instance <= 20 KiB (INSTANCE_BUDGET).

Stack: the largest single frame of any core function and the worst-case
depth by call graph (tools/stack_depth.py: the core's -fcallgraph-info=su
graphs plus the libgcc/newlib functions it calls, read from the image), per
entry point; pyins_step's is the one an ISR-driven firmware needs (plus its
own frame and an exception frame).

Cost per tick, in each mode of csrc/embedded/bench_modes.h (nav, navix =
navigation with the two-position scheme, coarse, fine5, fine8, fit = the
moving-base coarse alignment with a lever arm, fine12 = the moving-base fine
filter, fitvel = the coarse alignment under way; 3000 ticks):
  - host: instructions inside pyins_step from callgrind (build/host/bench_step);
  - Cortex-M7 and M4F: instructions per pyins_step, mean and worst tick,
    measured under QEMU with -icount (csrc/embedded/bench_main.c: SysTick
    counts the virtual clock, which -icount advances per instruction; QEMU
    does not model DWT CYCCNT). The M4F executes the soft-double library
    (__aeabi_d*) where the M7 has one FPU instruction: the M4F/M7 ratio is
    measured, not estimated.
  - budget: cycles = instructions x CPI (--cpi, default 1.0: an assumption,
    QEMU has no pipeline model; the M7 dual-issues integer work but takes
    ~30 cycles per VDIV.F64/VSQRT.F64, an M4F running from flash with wait
    states is nearer 1.2-1.5), as a fraction of one tick at 100 Hz on a
    216 MHz M7 and a 168 MHz M4F (--m7-mhz, --m4-mhz).
Every figure goes into one JSON object (units in the keys).
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import stack_depth  # noqa: E402

from pyins import native  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MODES = ("nav", "navix", "coarse", "fine5", "fine8", "fit", "fine12", "navund", "navgnss", "navlog", "fitvel",
         "nav_null", "nav_compact")
#: the rows that are the "nav" scenario through another API (bench_step's API argument and
#: the function callgrind counts): no record, a compact record every tick
API_OF = {"nav_null": ("nav", "null", "pyins_run"), "nav_compact": ("nav", "compact", "pyins_run_nav")}
TARGETS = (("cortex-m7", "build-m7", "mps2-an500"), ("cortex-m4f", "build-m4", "mps2-an386"))
TICK_HZ = 100
#: The M7 core's text budget [bytes] (docs/embedded.md, "Code size": why 80 KiB).
M7_TEXT_BUDGET = 80 * 1024
#: The instance's budget (docs/embedded.md, "Memory"): 20 KiB since ABI 0.19's 19-state filter at sea.
INSTANCE_BUDGET = 20 * 1024


def size_of(path):
    out = subprocess.run(["arm-none-eabi-size", path], capture_output=True, text=True, check=True).stdout
    total = [0, 0, 0]
    for line in out.strip().splitlines()[1:]:
        parts = line.split()
        for i in range(3):
            total[i] += int(parts[i])
    return total


def callgrind_per_tick(mode, ticks):
    """Instructions per tick inside pyins_step (or, for the API_OF rows, the
    function of that API) on the host (callgrind), or None."""
    exe = os.path.join(ROOT, "build", "host", "bench_step")
    if shutil.which("valgrind") is None:
        return None
    subprocess.run(["cmake", "--build", os.path.join(ROOT, "build", "host"), "--target", "bench_step"],
                   check=True, capture_output=True)
    out = os.path.join(ROOT, "build", "host", f"callgrind.size_report.{mode}.out")
    scenario, api, function = API_OF.get(mode, (mode, "step", "pyins_step"))
    res = subprocess.run(["valgrind", "--tool=callgrind", f"--toggle-collect={function}",
                          f"--callgrind-out-file={out}", exe, str(ticks), scenario, api],
                         capture_output=True, text=True)
    for line in res.stderr.splitlines():
        if "Collected :" in line:
            return int(line.split(":")[-1].strip()) / ticks
    return None


def qemu_bench(elf, board, shift=3):
    """{mode: (mean, max instructions per tick)} from bench.elf under QEMU -icount."""
    res = subprocess.run(["qemu-system-arm", "-M", board, "-nographic", "-semihosting", "-icount",
                          f"shift={shift}", "-kernel", elf], capture_output=True, text=True, timeout=600)
    if "DONE" not in res.stdout:
        raise RuntimeError(f"{elf} under QEMU: no DONE\n{res.stdout}\n{res.stderr}")
    cal = re.search(r"CAL nops (\d+) counts (\d+) empty (\d+)", res.stdout)
    nops, counts, empty = (int(x) for x in cal.groups())
    # 4 blocks of 1024 NOPs, each timed with one read before and one after
    per_count = nops / (counts - 4 * empty)
    out = {}
    for m in re.finditer(r"MODE (\w+) ticks (\d+) sum (\d+) max (\d+)", res.stdout):
        name, n, total, worst = m.group(1), int(m.group(2)), int(m.group(3)), int(m.group(4))
        out[name] = ((total / n - empty) * per_count, (worst - empty) * per_count)
    return out, per_count


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", default=os.path.join("runs", "bench", "size.json"))
    ap.add_argument("--no-cycles", action="store_true", help="sizes and stack only (no callgrind, no QEMU)")
    ap.add_argument("--m7-mhz", type=float, default=216.0)
    ap.add_argument("--m4-mhz", type=float, default=168.0)
    ap.add_argument("--cpi", type=float, default=1.0, help="cycles per instruction assumed for the budget")
    ap.add_argument("--ticks", type=int, default=3000, help="ticks per mode on the host (the images run 3000)")
    args = ap.parse_args(argv)
    fig = {"instance_bytes_host": int(native.lib.pyins_core_size())}

    # --- sizes and stack --------------------------------------------------
    print(f"{'build':10s} {'core text':>10s} {'core data':>10s} {'core bss':>9s} "
          f"{'demo text':>10s} {'demo data':>10s} {'demo bss':>9s} {'max frame':>10s} {'worst stack':>12s}")
    built = []
    stacks = {}
    for cpu, build, _ in TARGETS:
        lib = os.path.join(build, "libpyins_core.a")
        elf = os.path.join(build, "demo.elf")
        if not (os.path.exists(lib) and os.path.exists(elf)):
            print(f"{cpu}: not built (run tools/embedded.sh)")
            continue
        built.append(cpu)
        core, demo = size_of(lib), size_of(elf)
        st = stack_depth.analyse(build, elf)
        stacks[cpu] = st
        step = st["entries"].get("pyins_step", {"bytes": None})
        print(f"{cpu:10s} {core[0]:10,d} {core[1]:10,d} {core[2]:9,d} {demo[0]:10,d} {demo[1]:10,d} "
              f"{demo[2]:9,d} {st['max_frame']['bytes']:10,d} {st['worst']['bytes']:12,d}")
        fig.update({f"{cpu}_core_text_bytes": core[0], f"{cpu}_core_data_bytes": core[1],
                    f"{cpu}_core_bss_bytes": core[2], f"{cpu}_demo_text_bytes": demo[0],
                    f"{cpu}_demo_data_bytes": demo[1], f"{cpu}_demo_bss_bytes": demo[2],
                    f"{cpu}_max_stack_frame_bytes": st["max_frame"]["bytes"],
                    f"{cpu}_max_stack_frame_function": st["max_frame"]["function"],
                    f"{cpu}_worst_stack_bytes": st["worst"]["bytes"],
                    f"{cpu}_worst_stack_entry": st["worst"]["entry"],
                    f"{cpu}_pyins_step_stack_bytes": step["bytes"],
                    f"{cpu}_stack_assumed_externals": st["assumed_externals"],
                    f"{cpu}_stack_problems": st["problems"]})
    print(f"firmware instance: {fig['instance_bytes_host']:,d} bytes (the same layout on every 32/64-bit "
          f"target: doubles and int32/int64 only)")
    for cpu, st in stacks.items():
        step = st["entries"]["pyins_step"]
        print(f"{cpu} stack: largest frame {st['max_frame']['bytes']:,d} bytes ({st['max_frame']['function']}); "
              f"deepest call path {st['worst']['bytes']:,d} bytes from {st['worst']['entry']}; pyins_step "
              f"{step['bytes']:,d} bytes:\n    " + " -> ".join(f"{f} {b}" for f, b in step["path"]))
        for p in st["problems"]:
            print(f"    PROBLEM: {p}")
    m7 = fig.get("cortex-m7_core_text_bytes")
    if m7 is not None:
        print(f"budgets on the M7: core text {m7:,d} <= {M7_TEXT_BUDGET:,d} -> "
              f"{'met' if m7 <= M7_TEXT_BUDGET else 'NOT met'}; "
              f"instance {fig['instance_bytes_host']:,d} <= {INSTANCE_BUDGET:,d} -> "
              f"{'met' if fig['instance_bytes_host'] <= INSTANCE_BUDGET else 'NOT met'}")

    # --- cost per tick -----------------------------------------------------
    if not args.no_cycles:
        host = {m: callgrind_per_tick(m, args.ticks) for m in MODES}
        target = {}
        for cpu, build, board in TARGETS:
            elf = os.path.join(build, "bench.elf")
            if cpu in built and os.path.exists(elf) and shutil.which("qemu-system-arm"):
                target[cpu], per_count = qemu_bench(elf, board)
                fig[f"{cpu}_qemu_instructions_per_systick_count"] = per_count
        clocks = {"cortex-m7": args.m7_mhz * 1e6, "cortex-m4f": args.m4_mhz * 1e6}
        fig.update({"budget_tick_hz": TICK_HZ, "budget_cpi_assumed": args.cpi,
                    "budget_clock_hz_cortex-m7": clocks["cortex-m7"],
                    "budget_clock_hz_cortex-m4f": clocks["cortex-m4f"]})
        print(f"\ninstructions per tick (host: callgrind, {args.ticks} ticks; Cortex-M: QEMU -icount, 3000 ticks, "
              f"mean / worst tick); budget = instructions x CPI {args.cpi:g} as % of a {1000 // TICK_HZ} ms tick "
              f"at {args.m7_mhz:g} MHz (M7) / {args.m4_mhz:g} MHz (M4F)")
        print(f"{'mode':11s} {'host x86-64':>11s} {'M7 mean':>9s} {'M7 worst':>9s} {'M4F mean':>9s} "
              f"{'M4F worst':>10s} {'M4F/M7':>7s} {'M7 %tick':>15s} {'M4F %tick':>15s}")
        for m in MODES:
            h = host.get(m)
            if h is not None:
                fig[f"host_x86_64_{m}_callgrind_instructions_per_tick"] = h
            row = f"{m:11s} {h if h is not None else float('nan'):11,.0f}"
            pct = {}
            for cpu in ("cortex-m7", "cortex-m4f"):
                if cpu not in target or m not in target[cpu]:
                    row += f" {'-':>9s} {'-':>9s}"
                    continue
                mean, worst = target[cpu][m]
                cycles_per_tick = clocks[cpu] / TICK_HZ
                fmean = mean * args.cpi / cycles_per_tick
                fworst = worst * args.cpi / cycles_per_tick
                pct[cpu] = (fmean, fworst)
                fig.update({f"{cpu}_{m}_instructions_per_tick_mean": mean,
                            f"{cpu}_{m}_instructions_per_tick_worst": worst,
                            f"{cpu}_{m}_tick_fraction_mean": fmean,
                            f"{cpu}_{m}_tick_fraction_worst": fworst})
                row += f" {mean:9,.0f} {worst:9,.0f}" + (" " if cpu == "cortex-m4f" else "")
            if "cortex-m7" in target and "cortex-m4f" in target:
                ratio = target["cortex-m4f"][m][0] / target["cortex-m7"][m][0]
                fig[f"m4f_over_m7_{m}_instruction_ratio"] = ratio
                row += f" {ratio:7.1f}"
            for cpu in ("cortex-m7", "cortex-m4f"):
                if cpu in pct:
                    row += f" {100 * pct[cpu][0]:6.2f}/{100 * pct[cpu][1]:6.2f}%"
            print(row)

    os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
    with open(args.json, "w") as f:
        json.dump(fig, f, indent=2)
    print(f"figures: {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
