#!/usr/bin/env bash
# The README's test command: installs what is missing, configures, builds and runs every test.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
build=${SPAR_BUILD_DIR:-build}
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build "$build" -j2
ctest --test-dir "$build" --output-on-failure -j2
# Second stage, after the Release tests so their failures come first: sanitizers and fuzzing.
# SPAR_HUNT=0 skips it (a quick local check); CI always runs it.
if [ "${SPAR_HUNT:-1}" != 0 ]; then scripts/hunt.sh; fi
