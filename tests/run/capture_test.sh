#!/usr/bin/env bash
# Capture and replay: `mlcp run --capture 5` writes each island's MLCP of step 5 of stack_10 as
# mlcp-problem/1 files in both engines, and `mlcp solve` replays every file: pgs converges to
# 1e-4, dantzig and the verified chain `auto` to 1e-8 (so the captured problem is the solvable
# MLCP the engine's solver saw). A world that cannot capture must say so (exit 2).
# Exit 77 (skipped) when no engine of this build can capture yet.
set -u
mlcp=$1 scenes=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
source "$(dirname "${BASH_SOURCE[0]}")/../cli/check.sh"
engines=$("$mlcp" run --help | grep -oE 'engine: [a-z, ]+' | head -1)
captured=0
for engine in bullet ode; do
  case $engines in *$engine*) ;; *) continue ;; esac
  dir=$tmp/$engine
  out=$("$mlcp" run "$scenes/stack_10.json" --engine "$engine" --solver dantzig --steps 8 \
          --capture 5 --capture-dir "$dir" 2>&1)
  code=$?
  if [ "$code" -eq 2 ] && grep -q 'cannot capture' <<< "$out"; then
    echo "SKIP $engine: $out"
    continue
  fi
  captured=$((captured + 1))
  files=$(ls "$dir"/*.json 2>/dev/null)
  if [ "$code" -eq 0 ] && grep -q 'captured step 5: [1-9]' <<< "$out" && [ -n "$files" ] &&
     ! ls "$dir" | grep -qv 'step5'; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1)); echo "FAIL capture-$engine: exit $code: $out"; ls "$dir"
  fi
  for f in $files; do
    grep -q '"mlcp-problem/1"' "$f" || { failed=$((failed + 1)); echo "FAIL format: $f"; }
    check "replay-dantzig-$(basename "$f")" 0 'status +converged' -- \
      "$mlcp" solve "$f" --solver dantzig --tol 1e-8
    check "replay-pgs-$(basename "$f")" 0 'status +converged' -- \
      "$mlcp" solve "$f" --solver pgs --tol 1e-4 --max-iter 20000
    check "replay-auto-$(basename "$f")" 0 'status +converged' -- \
      "$mlcp" solve "$f" --solver auto --tol 1e-8
  done
done
check stock-cannot 2 'this engine/solver cannot capture' -- \
  "$mlcp" run "$scenes/stack_10.json" --engine bullet --solver bullet-si --steps 8 --capture 5 --capture-dir "$tmp/stock"
check step-out-of-range 2 'capture 9 is not one of the 8 steps' -- \
  "$mlcp" run "$scenes/stack_10.json" --engine ode --solver pgs --steps 8 --capture 9 --capture-dir "$tmp/x"
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ] || exit 1
if [ "$captured" -eq 0 ]; then echo "no engine can capture yet: skipped"; exit 77; fi
