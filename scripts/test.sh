#!/usr/bin/env bash
# The README's test command: installs what is missing, configures, builds and runs every test.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
build=${SPAR_BUILD_DIR:-build}
# A unity build (CMake joins a target's sources in groups of 8): half the compile time of
# separate sources, each group parses the heavy headers (Eigen, CGAL, gtest) once. It needs file-
# local helpers of one target to have distinct names (CONTRIBUTING.md).
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD=ON
cmake --build "$build" -j2
ctest --test-dir "$build" --output-on-failure -j2
# Second stage, after the Release tests so their failures come first: sanitizers and fuzzing.
# SPAR_HUNT=0 skips it (a quick local check); CI always runs it.
if [ "${SPAR_HUNT:-1}" != 0 ]; then scripts/hunt.sh; fi
