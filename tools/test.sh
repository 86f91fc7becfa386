#!/usr/bin/env bash
# Run the whole test suite (after tools/setup.sh): the C-level tests of the
# core through CMake/ctest, then pytest (NumPy reference, C ABI, C++ vs
# NumPy cross-checks, simulator, scenarios) with the derandomised
# hypothesis profile. Extra arguments go to pytest.
set -euo pipefail
cd "$(dirname "$0")/.."

cmake -S . -B build/host -G Ninja -DCMAKE_BUILD_TYPE=Release -DPYINS_BUILD_TESTS=ON >/dev/null
cmake --build build/host
ctest --test-dir build/host --output-on-failure

# The same core on Cortex-M7 and M4F under QEMU, bit-identical to the host
# and to Python (skipped with a notice when the ARM toolchain is missing).
if command -v arm-none-eabi-gcc >/dev/null && command -v qemu-system-arm >/dev/null; then
    bash tools/embedded.sh
else
    echo "NOTICE: arm-none-eabi-gcc or qemu-system-arm missing: embedded builds not tested" >&2
fi

# Plain `pytest` (not `python -m pytest`): the repo root must not shadow the
# installed package, whose directory holds the built library.
set +e
.venv/bin/pytest tests --hypothesis-profile=ci -q "$@"
rc=$?
set -e
if [ "$rc" -eq 5 ]; then
    echo "pytest collected no tests: that is a failure here" >&2
    exit 1
fi
exit "$rc"
