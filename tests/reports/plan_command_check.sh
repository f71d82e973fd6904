#!/usr/bin/env bash
# `spar plan`'s report files and batches, end to end (ctest reports_plan_command):
#   a malformed scenario writes nothing (not even the folder); --format writes only those files
#   and no temporary is left; a batch gives one line per scenario in input order, an error record
#   for a bad one, goes on, and exits with the highest status of its scenarios; --format without
#   --report is a usage error; `spar plan -` reads standard input, meshes from the working folder.
# usage: plan_command_check.sh SPAR SOURCE_DIR
set -euo pipefail
spar=$1
source_dir=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

printf 'name: broken\nobjects: [\n' >"$work/broken.yaml"
if "$spar" plan "$work/broken.yaml" --report "$work/out" 2>"$work/err"; then fail "broken scenario planned"; fi
grep -q "broken.yaml:3:1" "$work/err" || fail "no file:line:col message: $(cat "$work/err")"
[ ! -e "$work/out" ] || fail "a malformed scenario left $(ls -A "$work/out")"

"$spar" plan "$source_dir/examples/peg_block_face_up.yaml" --report "$work/out" --format md \
  >"$work/summary"
# The Markdown and the drawings of the cell it links to (cell-0.svg, ...), nothing else.
[ "$(ls -A "$work/out" | grep -v '^cell-[0-9]*\.svg$')" = "report.md" ] ||
  fail "--format md wrote: $(ls -A "$work/out")"
[ -f "$work/out/cell-0.svg" ] || fail "--format md wrote no drawing: $(ls -A "$work/out")"
grep -q "^report: $work/out/report.md$" "$work/summary" || fail "summary: $(cat "$work/summary")"
grep -q "^plan peg_block_face_up: planned" "$work/summary" || fail "summary: $(cat "$work/summary")"

mkdir "$work/batch"
cp "$source_dir/examples/peg_block_face_up.yaml" "$work/batch/a.yaml"
cp "$work/broken.yaml" "$work/batch/b.yaml"
cp "$source_dir/examples/peg_block_on_sides.yaml" "$work/batch/c.yaml"
if "$spar" plan --batch "$work/batch" --jobs 2 >"$work/lines" 2>"$work/err"; then
  fail "a batch with a bad scenario exited 0"
fi
[ "$(wc -l <"$work/lines")" -eq 3 ] || fail "batch printed $(wc -l <"$work/lines") lines"
sed -n 1p "$work/lines" | grep -q "^{\"file\":\"[^\"]*a.yaml\",\"report\":{\"schema\":\"spar-report/1\"" ||
  fail "line 1: $(sed -n 1p "$work/lines" | cut -c1-120)"
sed -n 2p "$work/lines" | grep -q "^{\"file\":\"[^\"]*b.yaml\",\"error\":\"[^\"]*b.yaml:3:1" ||
  fail "line 2: $(sed -n 2p "$work/lines")"
sed -n 3p "$work/lines" | grep -q "\"scenario\":\"peg_block_on_sides\"" || fail "line 3 out of order"
grep -q "1 of 3 scenarios failed" "$work/err" || fail "batch error: $(cat "$work/err")"
[ "$(wc -l <"$work/err")" -eq 1 ] || fail "batch stderr: $(cat "$work/err")"

# A batch exits with the highest status of its scenarios: 0 (proved) and 3 (errors) give 3.
mkdir "$work/mixed"
cp "$source_dir/examples/peg_block_face_up.yaml" "$work/mixed/a.yaml"
cp "$source_dir/examples/peg_block_on_back.yaml" "$work/mixed/b.yaml"
status=0
"$spar" plan --batch "$work/mixed" --jobs 2 --samples 0 >"$work/lines" 2>"$work/err" || status=$?
[ "$status" -eq 3 ] || fail "a batch of a proved and an erroneous plan exited $status, not 3"
[ ! -s "$work/err" ] || fail "batch stderr: $(cat "$work/err")"

# `spar plan -` reads the scenario from standard input; mesh paths are relative to the working
# directory (the scenario has no folder of its own).
mkdir -p "$work/stdin/parts"
cp "$source_dir/examples/objects/block.off" "$work/stdin/parts/block.off"
sed 's|builtin: block|mesh: parts/block.off|' "$source_dir/examples/peg_block_face_up.yaml" \
  >"$work/stdin/cell.yaml"
grep -q "mesh: parts/block.off" "$work/stdin/cell.yaml" || fail "the scenario has no block mesh"
(cd "$work/stdin" && "$spar" plan - --samples 0 --report out <cell.yaml >summary) ||
  fail "spar plan - exited $?"
grep -q "^plan peg_block_face_up: planned" "$work/stdin/summary" ||
  fail "spar plan -: $(cat "$work/stdin/summary")"
[ -f "$work/stdin/out/report.json" ] || fail "spar plan -: no report"
if (cd "$work" && "$spar" plan - --samples 0 <stdin/cell.yaml >/dev/null 2>"$work/err"); then
  fail "spar plan - found parts/block.off outside the working directory"
fi
grep -q "^spar: error: <stdin>:" "$work/err" || fail "spar plan - error: $(cat "$work/err")"

if "$spar" plan "$source_dir/examples/peg_block_face_up.yaml" --format md 2>"$work/err"; then
  fail "--format without --report accepted"
fi
grep -q -- "--format needs --report DIR" "$work/err" || fail "$(cat "$work/err")"
echo "plan_command_check: all checks passed"
