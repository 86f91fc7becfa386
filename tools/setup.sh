#!/usr/bin/env bash
# Set up pyins on a fresh Debian machine and run the main job.
#
#   bash tools/setup.sh            # install everything, then run the demo
#   bash tools/setup.sh --no-demo  # install only
#
# Installs the system packages (Eigen, compilers, CMake, Ninja, valgrind, the
# ARM bare-metal toolchain and QEMU for the Cortex-M builds, clang and its
# runtime libraries for the libFuzzer build of tools/fuzz.sh),
# makes a virtual environment in .venv and installs pyins into it (editable:
# Python edits take effect at once; after C++ edits run this script again,
# the C++ build is incremental under build/).
set -euo pipefail
cd "$(dirname "$0")/.."

sudo=""
if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends \
    libeigen3-dev g++ cmake ninja-build python3 python3-venv valgrind \
    gcc-arm-none-eabi libstdc++-arm-none-eabi-newlib libnewlib-arm-none-eabi qemu-system-arm \
    clang libclang-rt-14-dev chromium >/dev/null

python3 -m venv .venv
.venv/bin/python -m pip install -q --upgrade pip
.venv/bin/python -m pip install -q -e ".[test]"
echo "pyins installed in .venv ($(.venv/bin/python -c 'import pyins.native as n; print(n.LIBRARY_PATH)'))"

if [ "${1:-}" != "--no-demo" ]; then
    .venv/bin/python -m pyins demo
fi
