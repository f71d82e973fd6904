#!/usr/bin/env bash
# Regenerates docs/report.png, the README's picture of the HTML report: plans the face-down
# example, renders report.html in headless Chromium and keeps the top of the page.
# Needs a built `spar` (SPAR_BUILD_DIR, default build) and chromium (scripts/install-deps.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${SPAR_BUILD_DIR:-build}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$build/cli/spar" plan examples/peg_block_face_down.yaml --report "$work/report" --format html \
  >/dev/null
chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
  --disable-background-networking --disable-component-update --disable-sync --hide-scrollbars \
  --user-data-dir="$work/profile" --window-size=1200,1500 --screenshot="$work/report.png" \
  "file://$work/report/report.html" 2>/dev/null
mv "$work/report.png" docs/report.png
echo "wrote docs/report.png"
