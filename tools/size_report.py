#!/usr/bin/env python3
"""Size report of the embedded builds (run after tools/embedded.sh built them).

    .venv/bin/python tools/size_report.py [--json runs/bench/size.json]

For Cortex-M7 and Cortex-M4F: text/data/bss of the core library (sum of its
objects) and of the demo image (arm-none-eabi-size), the firmware instance
size (pyins_core_size()), and the largest stack frame of any core function
(-fstack-usage; the call depth of the core is shallow: step -> module ->
math helper). Budgets: core text <= 64 KiB and instance <= 16 KiB on the M7.
"""
import argparse
import glob
import json
import os
import subprocess
import sys

from pyins import native


def size_of(path):
    out = subprocess.run(["arm-none-eabi-size", path], capture_output=True, text=True, check=True).stdout
    total = [0, 0, 0]
    for line in out.strip().splitlines()[1:]:
        parts = line.split()
        for i in range(3):
            total[i] += int(parts[i])
    return total


def max_frame(build):
    best = (0, "")
    for su in glob.glob(os.path.join(build, "CMakeFiles", "pyins_core_obj.dir", "**", "*.su"), recursive=True):
        for line in open(su):
            parts = line.rsplit(None, 2)
            if len(parts) == 3 and parts[1].isdigit() and int(parts[1]) > best[0]:
                best = (int(parts[1]), parts[0].split(":")[-1])
    return best


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", default=os.path.join("runs", "bench", "size.json"))
    args = ap.parse_args(argv)
    fig = {"instance_bytes_host": int(native.lib.pyins_core_size())}
    print(f"{'build':10s} {'core text':>10s} {'core data':>10s} {'core bss':>9s} "
          f"{'demo text':>10s} {'demo data':>10s} {'demo bss':>9s} {'max frame':>10s}")
    for cpu, build in (("cortex-m7", "build-m7"), ("cortex-m4f", "build-m4")):
        lib = os.path.join(build, "libpyins_core.a")
        elf = os.path.join(build, "demo.elf")
        if not (os.path.exists(lib) and os.path.exists(elf)):
            print(f"{cpu}: not built (run tools/embedded.sh)")
            continue
        core, demo = size_of(lib), size_of(elf)
        frame, fn = max_frame(build)
        print(f"{cpu:10s} {core[0]:10,d} {core[1]:10,d} {core[2]:9,d} {demo[0]:10,d} {demo[1]:10,d} "
              f"{demo[2]:9,d} {frame:10,d}  ({fn})")
        fig.update({f"{cpu}_core_text_bytes": core[0], f"{cpu}_core_data_bytes": core[1],
                    f"{cpu}_core_bss_bytes": core[2], f"{cpu}_demo_text_bytes": demo[0],
                    f"{cpu}_demo_data_bytes": demo[1], f"{cpu}_demo_bss_bytes": demo[2],
                    f"{cpu}_max_stack_frame_bytes": frame})
    print(f"firmware instance: {fig['instance_bytes_host']:,d} bytes (the same layout on every 32/64-bit "
          f"target: doubles and int32/int64 only)")
    m7 = fig.get("cortex-m7_core_text_bytes")
    if m7 is not None:
        print(f"budgets on the M7: core text {m7:,d} <= 65,536 -> {'met' if m7 <= 65536 else 'NOT met'}; "
              f"instance {fig['instance_bytes_host']:,d} <= 16,384 -> "
              f"{'met' if fig['instance_bytes_host'] <= 16384 else 'NOT met'}")
    os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
    with open(args.json, "w") as f:
        json.dump(fig, f, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
