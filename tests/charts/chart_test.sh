#!/usr/bin/env bash
# chart_test.sh REPO OUTDIR: tools/chart.py draws the sample sweep and stability CSVs into PNG and
# SVG files, and rejects bad CSVs with a message naming what is wrong. Skips (exit 77) when the
# venv is missing; tools/setup.sh (run by tools/test.sh) builds it.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/chart_test_setup.sh" "$1" "$2"
data="$repo/tests/data/charts"

check_files() {  # folder, stems...
  local dir=$1; shift
  for stem in "$@"; do
    local png="$dir/$stem.png" svg="$dir/$stem.svg"
    [ -s "$png" ] || fail "$png is missing or empty"
    [ -s "$svg" ] || fail "$svg is missing or empty"
    [ "$(head -c 8 "$png" | od -An -tx1 | tr -d ' \n')" = "89504e470d0a1a0a" ] || fail "$png is not a PNG"
    grep -q "<svg" "$svg" || fail "$svg is not an SVG"
  done
  local count
  count=$(find "$dir" -type f | wc -l)
  [ "$count" -eq $((2 * $#)) ] || fail "$dir holds $count files, expected $((2 * $#))"
}

MPLBACKEND= "$py" "$repo/tools/chart.py" work-precision "$data/sweep_sample.csv" -o "$out/wp" > "$out/wp.log"
check_files "$out/wp" stack_10 pendulum_chain
grep -q "stack_10.png" "$out/wp.log" || fail "written files are not listed"

"$py" "$repo/tools/chart.py" heatmap "$data/stability_sample.csv" -o "$out/hm" > /dev/null
check_files "$out/hm" stability_mass_ratio_stack

expect_error() {  # csv text, mode, expected message part
  printf '%s\n' "$1" > "$out/bad.csv"
  set +e
  "$py" "$repo/tools/chart.py" "$2" "$out/bad.csv" -o "$out/bad" 2> "$out/bad.err"
  local rc=$?
  set -e
  [ $rc -eq 2 ] || fail "exit code $rc for a bad CSV, expected 2"
  grep -qF "$3" "$out/bad.err" || fail "message '$(cat "$out/bad.err")' lacks '$3'"
}
expect_error "scene,engine,solver,setting,value,step,solver_ms,residual" work-precision \
  "missing column(s) iterations, status, fallbacks, max_penetration, joint_error"
expect_error "$(head -2 "$data/sweep_sample.csv" | sed '2s/max-iterations/maybe/')" work-precision \
  "line 2: column status: unknown status 'maybe'"
expect_error "$(head -2 "$data/sweep_sample.csv" | sed '2s/0.061943/fast/')" work-precision \
  "line 2: column solver_ms: expected a number, got 'fast'"
expect_error "$(head -2 "$data/stability_sample.csv" | sed '2s/,[a-z-]*$/,wobbly/')" heatmap \
  "line 2: column outcome: unknown outcome 'wobbly'"
expect_error "engine,solver,x_name,x_value,y_name,y_value,outcome" heatmap "no data rows"
echo "chart_test: ok"
