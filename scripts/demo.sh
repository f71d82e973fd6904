#!/usr/bin/env bash
# The README's first command: installs what is missing, builds `spar` and the Python module, plans the seed's
# peg-and-block task (the block face down: it is turned over twice before the peg goes in) and
# writes the uncertainty report to report/ (report.html, report.md, report.json). Extra arguments
# go to `spar plan` (e.g. --format html).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh >/dev/null
build=${SPAR_BUILD_DIR:-build}
# Configure only a new build folder (Release, unity build like scripts/test.sh, so the tests reuse
# what the demo built): an existing one keeps its configuration (CI's sanitizer build runs this
# through scripts/check-readme.sh); the build is incremental.
[ -f "$build/CMakeCache.txt" ] ||
  cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD=ON >/dev/null
cmake --build "$build" -j2 --target readme_tools >/dev/null  # spar and the Python module
exec "$build/cli/spar" plan examples/peg_block_face_down.yaml --report report "$@"
