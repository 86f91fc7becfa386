#!/usr/bin/env bash
# Build the firmware core for Cortex-M7 and Cortex-M4F, run the demo image
# under QEMU and the symbol allow-list check (ctest in each build), print a
# size report, and compare the output bit for bit with the host and Python.
#   bash tools/embedded.sh
# Needs gcc-arm-none-eabi, libstdc++-arm-none-eabi-newlib,
# libnewlib-arm-none-eabi and qemu-system-arm (tools/setup.sh installs them).
set -euo pipefail
cd "$(dirname "$0")/.."
for cpu in cortex-m7 cortex-m4; do
    dir="build-${cpu#cortex-}"
    cmake -S . -B "$dir" -G Ninja -DCMAKE_TOOLCHAIN_FILE=cmake/arm-none-eabi.cmake \
        -DPYINS_TARGET_CPU="$cpu" -DCMAKE_BUILD_TYPE=Release >/dev/null
    cmake --build "$dir"
    ctest --test-dir "$dir" --output-on-failure
done
cmake --build build/host --target demo_host >/dev/null
.venv/bin/python tools/size_report.py
.venv/bin/python tools/compare_embedded.py
