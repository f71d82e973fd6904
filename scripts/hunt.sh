#!/usr/bin/env bash
# CI that hunts (issue 12): the second stage of scripts/test.sh, after the Release build and its
# tests, so a failure here is a sanitizer or fuzzer finding, not an ordinary test failure.
# ONE build, with clang: everything (modules, CLI, tests, the libFuzzer targets of tests/fuzz)
# with AddressSanitizer + UndefinedBehaviorSanitizer and libFuzzer's coverage instrumentation
# (any report aborts); the tests' own sources are not instrumented (tests/CMakeLists.txt), the
# spar code they call is. Two separate builds (GCC for the tests, clang for the fuzz targets) cost
# ~8 of CI's minutes for nothing the one build misses.
#   1. The WHOLE test suite in that build, except the README tour (readme: it runs the same CLI
#      the CLI tests run here, serially, and the Release stage runs it), with every property's
#      case count divided by SPAR_PROPERTY_DIVISOR (default 4, tests/common/rapidcheck_seed.cpp):
#      the Release stage has just run them at the full count; this stage looks for memory and
#      undefined-behaviour errors on the same paths, at a quarter of the speed.
#   2. Each fuzz target for SPAR_FUZZ_SECONDS (default 45) from its seed corpus, SPAR_FUZZ_JOBS
#      targets at a time (default: the number of cores), with libFuzzer seed SPAR_FUZZ_SEED
#      (default fixed: reproducible; 0: random) (a scratch copy: the repository's corpus is
#      never written). Any crash, hang (> 10 s on one input), leak, out-of-memory or sanitizer
#      report fails the run; libFuzzer leaves the input that caused it in the build folder as
#      <target>-crash-... (or -timeout-, -leak-, -oom-).
# Build folder: $SPAR_HUNT_BUILD_DIR (default <Release build folder>/hunt).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${SPAR_HUNT_BUILD_DIR:-${SPAR_BUILD_DIR:-build}/hunt}
seconds=${SPAR_FUZZ_SECONDS:-45}
# libFuzzer's seed: fixed by default so that a CI run is reproducible (the same inputs, in the
# same order, as a local run of this script); SPAR_FUZZ_SEED=0 draws a random one (exploration).
seed=${SPAR_FUZZ_SEED:-20261201}

# -O1 with line tables: fast enough to build and run, and every report has file:line frames.
CC=clang CXX=clang++ cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -gline-tables-only" -DSPAR_SANITIZE=ON -DSPAR_FUZZ=ON \
  -DSPAR_BUILD_BENCH=OFF -DCMAKE_UNITY_BUILD=ON
cmake --build "$build" -j2

export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:check_initialization_order=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export SPAR_PROPERTY_DIVISOR=${SPAR_PROPERTY_DIVISOR:-4}
echo "hunt: the test suite under AddressSanitizer + UndefinedBehaviorSanitizer" \
  "(properties at 1/$SPAR_PROPERTY_DIVISOR of their cases; the README tour runs in Release)"
ctest --test-dir "$build" --output-on-failure -j2 -E '^readme$'

scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
# The targets run side by side, SPAR_FUZZ_JOBS at a time (default: one per core): each still fuzzes
# for its full time, the stage takes 1/jobs of it. Each target's output goes to its own log,
# printed when it ends: whole if it found something, its final statistics otherwise.
jobs=${SPAR_FUZZ_JOBS:-$(nproc)}
declare -A running=()  # pid -> target name
findings=0
finish_one() {
  local pid status=0
  wait -n -p pid "${!running[@]}" || status=$?
  local name=${running[$pid]}
  unset "running[$pid]"
  if [ "$status" = 0 ]; then
    echo "hunt: $name fuzzed for $seconds s, no findings:"
    grep '^stat::' "$scratch/$name.log" || true
  else
    cat "$scratch/$name.log"
    echo "hunt: $name FOUND SOMETHING (exit status $status; its input is in $build)"
    findings=$((findings + 1))
  fi
}
for corpus in tests/fuzz/corpus/*/; do
  name=$(basename "$corpus")
  dictionary=()
  [ -f "tests/fuzz/$name.dict" ] && dictionary=("-dict=tests/fuzz/$name.dict")
  mkdir -p "$scratch/$name"
  [ "${#running[@]}" -ge "$jobs" ] && finish_one
  echo "hunt: fuzzing $name for $seconds s"
  "$build/tests/fuzz/${name}_fuzz" -seed="$seed" -max_total_time="$seconds" -timeout=10 \
    -rss_limit_mb=2048 -max_len=4096 -print_final_stats=1 -artifact_prefix="$build/${name}_fuzz-" \
    "${dictionary[@]}" "$scratch/$name" "$corpus" >"$scratch/$name.log" 2>&1 &
  running[$!]=$name
done
while [ "${#running[@]}" -gt 0 ]; do finish_one; done
if [ "$findings" != 0 ]; then
  echo "hunt: $findings fuzz target(s) found something"
  exit 1
fi
echo "hunt: no findings"
