#!/usr/bin/env bash
# `mlcp run` as a user runs it: a CSV with the documented header and one row per step, exit 2
# on a bad scene file, an unknown engine or solver. Prints "N passed, N failed".
set -u
mlcp=$1 scenes=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
source "$(dirname "${BASH_SOURCE[0]}")/../cli/check.sh"
header='scene,engine,solver,step,solver_ms,step_ms,residual,iterations,status,fallbacks,choice,contacts,max_penetration,joint_error,energy,momentum,max_speed'
csv_ok() {  # csv_ok NAME FILE ROWS ENGINE SOLVER
  local name=$1 file=$2 rows=$3 engine=$4 solver=$5
  if [ "$(head -1 "$file")" = "$header" ] && [ "$(($(wc -l < "$file") - 1))" -eq "$rows" ] &&
     awk -F, -v e="$engine" -v s="$solver" -v n="$rows" '
       NR > 1 { if ($1 != "stack_10" || $2 != e || $3 != s || $4 != NR - 2 || NF != 17) bad = 1
                for (i = 5; i <= 17; ++i) if (i != 9 && i != 7 && i != 11 && $i !~ /^-?[0-9.e+-]+$/) bad = 1 }
       END { exit bad || NR != n + 1 }' "$file"; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "FAIL $name: $file:"; head -3 "$file" | sed 's/^/    /'
  fi
}
for engine in bullet ode; do
  if ! "$mlcp" run --help | grep -q "$engine"; then continue; fi
  check "run-$engine" 0 'stack_10 in '"$engine"' with pgs: 7 steps' -- \
    "$mlcp" run "$scenes/stack_10.json" --engine "$engine" --solver pgs --steps 7 --csv "$tmp/$engine.csv"
  csv_ok "csv-$engine" "$tmp/$engine.csv" 7 "$engine" pgs
  check "unknown-solver-$engine" 2 "unknown solver 'nosuch'" -- \
    "$mlcp" run "$scenes/stack_10.json" --engine "$engine" --solver nosuch --steps 1
  check "time-budget-$engine" 0 'stack_10 in '"$engine"' with auto: 5 steps' -- \
    "$mlcp" run "$scenes/stack_10.json" --engine "$engine" --solver auto --steps 5 --time-budget 0.2
  check "time-budget-bad-$engine" 2 'not in range' -- \
    "$mlcp" run "$scenes/stack_10.json" --engine "$engine" --steps 1 --time-budget -0.5
done
check stock-bullet 0 'with bullet-si: 3 steps' -- \
  "$mlcp" run "$scenes/resting_box.json" --engine bullet --solver bullet-si --steps 3 --iterations 10
printf '{"format": "mlcp-scene/1", "bodies": [{"name": "b", "shape": {"type": "box", "size": [1, -1, 1]}, "mass": 1}]}' > "$tmp/bad.json"
check bad-scene 2 'bad.json: bodies\[0\].shape.size' -- "$mlcp" run "$tmp/bad.json" --engine ode --steps 1
check missing-scene 2 'nope.json' -- "$mlcp" run "$tmp/nope.json" --engine bullet --steps 1
check unknown-engine 2 "unknown engine 'physx'" -- "$mlcp" run "$scenes/stack_10.json" --engine physx --steps 1
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
