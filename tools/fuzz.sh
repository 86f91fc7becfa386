#!/usr/bin/env bash
# Fuzz the C ABI (tests/fuzz/fuzz_c_api.c) with libFuzzer + ASan + UBSan.
#
#   bash tools/fuzz.sh              # 60 s (what tools/test.sh runs)
#   bash tools/fuzz.sh 3600         # a longer hunt; the corpus in build-fuzz/corpus/ grows across runs
#   FUZZ_JOBS=2 bash tools/fuzz.sh 3600   # several processes (libFuzzer -fork)
#   bash tools/fuzz.sh --replay     # only replay tests/fuzz/corpus/ and tests/fuzz/regressions/
#   bash tools/fuzz.sh --merge      # add the inputs of build-fuzz/corpus/ that reach new
#                                   # coverage to tests/fuzz/corpus/ (then commit them)
#   PYINS_FUZZ_UNTRUSTED=1 bash tools/fuzz.sh 600   # also step states restored from fuzzed
#                                   # payloads with a valid CRC (a robustness probe outside the
#                                   # contract; findings go to build-fuzz/untrusted/)
#
# Configures build-fuzz/ with CC=clang CXX=clang++ -DPYINS_FUZZ=ON (the core
# with its usual determinism flags plus coverage, ASan and UBSan), writes the
# built-in seeds (valid configurations and operation sequences) into the
# working corpus build-fuzz/corpus/ next to tests/fuzz/corpus/, replays
# tests/fuzz/regressions/, then fuzzes for the given time. A crash, leak,
# timeout or out-of-memory input is copied into tests/fuzz/regressions/
# (from then on ctest replays it: fuzz_replay_checked, memcheck_fuzz_replay)
# and the script fails. Figures: runs/bench/fuzz.json.
# Needs clang and libclang-rt-14-dev (tools/setup.sh installs them).
set -euo pipefail
cd "$(dirname "$0")/.."

mode=fuzz
seconds=60
case "${1:-}" in
    --replay) mode=replay ;;
    --merge) mode=merge ;;
    "") ;;
    *) seconds="$1" ;;
esac
jobs="${FUZZ_JOBS:-1}"
build=build-fuzz
json="${FUZZ_JSON:-runs/bench/fuzz.json}"

if ! command -v clang >/dev/null || ! command -v clang++ >/dev/null; then
    echo "tools/fuzz.sh: clang is missing (apt-get install clang libclang-rt-14-dev)" >&2
    exit 1
fi
CC=clang CXX=clang++ cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DPYINS_FUZZ=ON \
    -DPYINS_BUILD_TESTS=OFF >/dev/null
cmake --build "$build" --target fuzz_c_api fuzz_c_api_replay

export ASAN_OPTIONS="${ASAN_OPTIONS:-abort_on_error=1:detect_leaks=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"

# every input found so far, without fuzzing
"$build/fuzz_c_api_replay" --seeds tests/fuzz/corpus tests/fuzz/regressions
[ "$mode" = replay ] && exit 0

mkdir -p "$build/corpus" "$build/artifacts"
"$build/fuzz_c_api_replay" --write-seeds "$build/corpus" >/dev/null

if [ "$mode" = merge ]; then
    "$build/fuzz_c_api" -merge=1 -max_len=4096 tests/fuzz/corpus "$build/corpus"
    echo "tests/fuzz/corpus: $(ls tests/fuzz/corpus | wc -l) inputs, $(du -sh tests/fuzz/corpus | cut -f1)"
    exit 0
fi

log="$build/fuzz.log"
rm -f "$build"/artifacts/*
opts=(-max_total_time="$seconds" -max_len=4096 -timeout=30 -rss_limit_mb=2048 -print_final_stats=1
      -artifact_prefix="$build/artifacts/")
if [ "$jobs" -gt 1 ]; then
    opts+=(-fork="$jobs")
fi
echo "fuzzing the C ABI for $seconds s ($jobs process(es)); log: $log"
set +e
"$build/fuzz_c_api" "${opts[@]}" "$build/corpus" tests/fuzz/corpus >"$log" 2>&1
rc=$?
set -e
tail -n 3 "$log" | sed 's/^/  /'

found=$(ls "$build"/artifacts/ 2>/dev/null | grep -E '^(crash|leak|timeout|oom|slow-unit)-' || true)
# PYINS_FUZZ_UNTRUSTED=1 (restored garbage states are stepped: outside the
# contract) keeps its findings apart: they are not regressions of the ABI
dest=tests/fuzz/regressions
if [ "${PYINS_FUZZ_UNTRUSTED:-0}" = 1 ]; then
    dest="$build/untrusted"
    mkdir -p "$dest"
fi
for f in $found; do
    cp "$build/artifacts/$f" "$dest/"
done

python3 - "$log" "$json" "$seconds" "$jobs" "$(ls "$build/corpus" | wc -l)" "$(echo "$found" | grep -c . || true)" <<'EOF'
import json, os, re, sys
log, out, seconds, jobs, corpus, found = sys.argv[1:]
text = open(log, errors="replace").read()
def stat(name):
    m = re.findall(r"stat::%s:\s*(\d+)" % name, text)
    return int(m[-1]) if m else None
cov = re.findall(r"cov: (\d+) ft: (\d+)", text)
runs = re.findall(r"Done (\d+) runs in (\d+) second", text)
execs, rate = stat("number_of_executed_units"), stat("average_exec_per_sec")
prog = re.findall(r"^#(\d+): cov: .* time: (\d+)s", text, re.M)
if int(jobs) > 1 and prog:
    # -fork: the stat:: lines are one job's; the progress lines count all
    execs = int(prog[-1][0])
    rate = execs // max(1, int(prog[-1][1]))
fig = {
    "fuzz_seconds_requested": int(seconds),
    "fuzz_processes": int(jobs),
    "fuzz_executions": execs or (int(runs[-1][0]) if runs else None),
    "fuzz_executions_per_second": rate,
    "fuzz_new_inputs": stat("new_units_added"),
    "fuzz_slowest_input_s": stat("slowest_unit_time_sec"),
    "fuzz_peak_rss_mb": stat("peak_rss_mb"),
    "fuzz_coverage_edges": int(cov[-1][0]) if cov else None,
    "fuzz_coverage_features": int(cov[-1][1]) if cov else None,
    "fuzz_corpus_inputs": int(corpus),
    "fuzz_findings": int(found),
}
if fig["fuzz_executions"] and runs and not fig["fuzz_executions_per_second"]:
    fig["fuzz_executions_per_second"] = fig["fuzz_executions"] // max(1, int(runs[-1][1]))
os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
with open(out, "w") as f:
    json.dump(fig, f, indent=2)
print("  " + ", ".join(f"{k} {v}" for k, v in fig.items()))
print(f"  figures: {out}")
EOF

if [ -n "$found" ] || [ "$rc" -ne 0 ]; then
    echo "tools/fuzz.sh: the fuzzer found a failing input (exit $rc): $(echo $found)" >&2
    echo "  copied to $dest/; reproduce: $build/fuzz_c_api $dest/<file>" >&2
    echo "  (log: $log)" >&2
    exit 1
fi
echo "fuzz: no failure in $seconds s"
