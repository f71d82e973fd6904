#!/usr/bin/env bash
# Runs every command of README.md's ```sh blocks, in order, from the repository root, with the
# built `spar` first on PATH, and fails on the first that fails (exits otherwise than 0, or than
# the status a trailing "# exits N" documents): the README cannot rot. The
# exception is scripts/test.sh (it runs this script: it would recurse); it is checked by CI itself.
# Python lines are skipped, with a line saying so, in a build without the Python module.
# Files the tour writes go to a scratch folder (README commands write report/ and my_task.yaml,
# which are ignored by git; they are removed afterwards).
#   SPAR_BUILD_DIR  the build folder whose cli/spar is used (default build)
set -euo pipefail
cd "$(dirname "$0")/.."
build=$(cd "${SPAR_BUILD_DIR:-build}" && pwd)
[ -x "$build/cli/spar" ] || { echo "check-readme: no $build/cli/spar (build it first)" >&2; exit 1; }
export PATH="$build/cli:$PATH" SPAR_BUILD_DIR="$build"
commands=$(awk '/^```sh$/ {inside = 1; next} /^```$/ {inside = 0} inside' README.md)
[ -n "$commands" ] || { echo "check-readme: README.md has no \`\`\`sh block" >&2; exit 1; }
count=0
while IFS= read -r line; do
  case "$line" in "" | "#"* | *scripts/test.sh*) continue ;; esac
  # A sanitizer build has no Python module (python/ is not built there): its Release build runs
  # these lines.
  if [[ "$line" == *python3* ]] && grep -q "^SPAR_SANITIZE:BOOL=ON" "$build/CMakeCache.txt"; then
    echo "check-readme: skipped (no Python module in $build): $line"
    continue
  fi
  count=$((count + 1))
  echo "check-readme: \$ $line"
  # A line that documents its exit status ("# exits 3") must exit with it; every other, 0.
  expected=0
  if [[ "$line" =~ \#\ exits\ ([0-9]+) ]]; then expected=${BASH_REMATCH[1]}; fi
  status=0
  bash -euo pipefail -c "$line" >/tmp/check-readme.$$ 2>&1 </dev/null || status=$?
  if [ "$status" -ne "$expected" ]; then
    cat /tmp/check-readme.$$ >&2
    rm -f /tmp/check-readme.$$
    echo "check-readme: FAILED (exit status $status, expected $expected): $line" >&2
    exit 1
  fi
done <<<"$commands"
rm -f /tmp/check-readme.$$ my_task.yaml
echo "check-readme: all $count README commands ran"
