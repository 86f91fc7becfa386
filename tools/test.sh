#!/usr/bin/env bash
# Run the whole test suite (after tools/setup.sh): the C-level tests of the
# core through CMake/ctest (also sanitized, under valgrind, and the fuzz
# regressions), the Cortex-M builds under QEMU, a bounded libFuzzer run on
# the C ABI, then pytest (NumPy reference, C ABI, C++ vs NumPy cross-checks,
# simulator, scenarios) with the derandomised hypothesis profile. Extra
# arguments go to pytest.
set -euo pipefail
cd "$(dirname "$0")/.."

cmake -S . -B build/host -G Ninja -DCMAKE_BUILD_TYPE=Release -DPYINS_BUILD_TESTS=ON >/dev/null
cmake --build build/host
# also the fuzz inputs replayed under ASan/UBSan (fuzz_replay_checked) and
# every C-level test under valgrind memcheck (label memcheck, ~1 min)
ctest --test-dir build/host --output-on-failure -j2

# The same core on Cortex-M7 and M4F under QEMU, bit-identical to the host
# and to Python (skipped with a notice when the ARM toolchain is missing).
if command -v arm-none-eabi-gcc >/dev/null && command -v qemu-system-arm >/dev/null; then
    bash tools/embedded.sh
else
    echo "NOTICE: arm-none-eabi-gcc or qemu-system-arm missing: embedded builds not tested" >&2
fi

# libFuzzer on the C ABI (clang, ASan + UBSan), bounded: PYINS_FUZZ_SECONDS
# (default 60; 0 skips). Any failing input lands in tests/fuzz/regressions/.
fuzz_seconds="${PYINS_FUZZ_SECONDS:-60}"
if [ "$fuzz_seconds" -gt 0 ]; then
    if command -v clang >/dev/null; then
        bash tools/fuzz.sh "$fuzz_seconds"
    else
        echo "NOTICE: clang missing: the C ABI was not fuzzed (tools/setup.sh installs it)" >&2
    fi
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
