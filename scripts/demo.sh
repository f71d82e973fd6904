#!/usr/bin/env bash
# The README's main-job command: installs what is missing, builds `spar` and runs it on the
# built-in example.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh >/dev/null
build=${SPAR_BUILD_DIR:-build}
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j2 --target spar >/dev/null
exec "$build/cli/spar" demo "$@"
