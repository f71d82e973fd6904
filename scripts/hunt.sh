#!/usr/bin/env bash
# CI that hunts (issue 12): the second stage of scripts/test.sh, after the Release build and its
# tests, so a failure here is a sanitizer or fuzzer finding, not an ordinary test failure.
#   1. Build everything with AddressSanitizer + UndefinedBehaviorSanitizer (GCC, like the Release
#      build; any report aborts) and run the WHOLE test suite in that build.
#   2. Build the libFuzzer targets of tests/fuzz with clang (ASan + UBSan + fuzzer coverage; only
#      the modules they fuzz) and run each for SPAR_FUZZ_SECONDS (default 45) from its seed corpus,
#      with libFuzzer seed SPAR_FUZZ_SEED (default fixed: reproducible; 0: random)
#      (a scratch copy: the repository's corpus is never written). Any crash, hang (> 10 s on one
#      input), leak, out-of-memory or sanitizer report fails the run; libFuzzer leaves the input
#      that caused it in the fuzz build folder as <target>-crash-... (or -timeout-, -leak-, -oom-).
# Build folders: $SPAR_HUNT_BUILD_DIR (default <Release build folder>/hunt) and its fuzz/.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${SPAR_HUNT_BUILD_DIR:-${SPAR_BUILD_DIR:-build}/hunt}
seconds=${SPAR_FUZZ_SECONDS:-45}
# libFuzzer's seed: fixed by default so that a CI run is reproducible (the same inputs, in the
# same order, as a local run of this script); SPAR_FUZZ_SEED=0 draws a random one (exploration).
seed=${SPAR_FUZZ_SEED:-20261201}

# -O1 with line tables: fast enough to build and run, and every report has file:line frames.
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1" -DSPAR_SANITIZE=ON -DSPAR_BUILD_BENCH=OFF
cmake --build "$build" -j2

export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:check_initialization_order=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
echo "hunt: the whole test suite under AddressSanitizer + UndefinedBehaviorSanitizer"
ctest --test-dir "$build" --output-on-failure -j2

fuzz_build="$build/fuzz"
fuzz_modules="symbolic;bounds;kinematics;geometry;sensing;planner;qr;reports"  # what the fuzz targets link
targets=()
for corpus in tests/fuzz/corpus/*/; do targets+=("$(basename "$corpus")_fuzz"); done
CC=clang CXX=clang++ cmake -S . -B "$fuzz_build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -gline-tables-only" -DSPAR_SANITIZE=ON -DSPAR_FUZZ=ON \
  "-DSPAR_MODULES=$fuzz_modules"
cmake --build "$fuzz_build" -j2 --target "${targets[@]}"

scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
for corpus in tests/fuzz/corpus/*/; do
  name=$(basename "$corpus")
  dictionary=()
  [ -f "tests/fuzz/$name.dict" ] && dictionary=("-dict=tests/fuzz/$name.dict")
  mkdir -p "$scratch/$name"
  echo "hunt: fuzzing $name for $seconds s"
  "$fuzz_build/tests/fuzz/${name}_fuzz" -seed="$seed" -max_total_time="$seconds" -timeout=10 \
    -rss_limit_mb=2048 -max_len=4096 -print_final_stats=1 -artifact_prefix="$fuzz_build/${name}_fuzz-" \
    "${dictionary[@]}" "$scratch/$name" "$corpus"
done
echo "hunt: no findings"
