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
  # --engine-iterations: pgs runs exactly --iterations sweeps per island (the drop-in's default).
  "$mlcp" run "$scenes/stack_10.json" --engine "$engine" --solver pgs --steps 5 --iterations 7 \
    --engine-iterations --csv "$tmp/$engine-fixed.csv" > /dev/null 2>&1
  if awk -F, 'NR > 1 { n = split($11, c, /[: ]/); islands = 0
                       for (i = 2; i <= n; i += 2) islands += c[i]
                       if ($8 != 7 * islands || $10 != 0) bad = 1 }
              END { exit bad || NR != 6 }' "$tmp/$engine-fixed.csv"; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "FAIL engine-iterations-$engine:"; head -4 "$tmp/$engine-fixed.csv" | sed 's/^/    /'
  fi
  check "time-budget-$engine" 0 'stack_10 in '"$engine"' with auto: 5 steps' -- \
    "$mlcp" run "$scenes/stack_10.json" --engine "$engine" --solver auto --steps 5 --time-budget 0.2
  check "time-budget-bad-$engine" 2 'time-budget' -- \
    "$mlcp" run "$scenes/stack_10.json" --engine "$engine" --steps 1 --time-budget -0.5
done
check stock-bullet 0 'with bullet-si: 3 steps' -- \
  "$mlcp" run "$scenes/resting_box.json" --engine bullet --solver bullet-si --steps 3 --iterations 10
printf '{"format": "mlcp-scene/1", "bodies": [{"name": "b", "shape": {"type": "box", "size": [1, -1, 1]}, "mass": 1}]}' > "$tmp/bad.json"
check bad-scene 2 'bad.json: bodies\[0\].shape.size' -- "$mlcp" run "$tmp/bad.json" --engine ode --steps 1
check missing-scene 2 'nope.json' -- "$mlcp" run "$tmp/nope.json" --engine bullet --steps 1
if "$mlcp" run --help | grep -q ode; then
  check unsupported-six-dof-ode 2 'unsupported in ODE: six_dof joint hanger' -- \
    "$mlcp" run "$scenes/six_dof_spring.json" --engine ode --steps 1
  # Two cylinders falling onto each other: this ODE build has no cylinder-cylinder collider.
  printf '%s' '{"format": "mlcp-scene/1", "bodies": [
    {"name": "a", "shape": {"type": "cylinder", "radius": 0.5, "length": 0.2}, "mass": 1, "position": [0, 0, 0]},
    {"name": "b", "shape": {"type": "cylinder", "radius": 0.5, "length": 0.2}, "mass": 1, "position": [0, 0, 0.25]}]}' > "$tmp/cylinders.json"
  if ! "$mlcp" run "$tmp/cylinders.json" --engine ode --steps 30 > "$tmp/cyl.out" 2>&1 &&
     grep -q 'unsupported in ODE: contacts between cylinder and cylinder' "$tmp/cyl.out"; then
    check unsupported-cylinders-ode 2 'unsupported in ODE: contacts between cylinder and cylinder' -- \
      "$mlcp" run "$tmp/cylinders.json" --engine ode --steps 30
  else  # an ODE built with libccd collides them
    check cylinders-ode 0 'steps' -- "$mlcp" run "$tmp/cylinders.json" --engine ode --steps 30
  fi
fi
check unknown-engine 2 "unknown engine 'physx'" -- "$mlcp" run "$scenes/stack_10.json" --engine physx --steps 1

# Scene files that once crashed the loader or ODE (tests/data/fuzz), and inputs that are not files.
fuzz=$scenes/../tests/data/fuzz
check dev-urandom 2 '/dev/urandom: not a regular file' -- "$mlcp" run /dev/urandom --engine ode --steps 1
check fuzz-overflow 2 'scene_number_overflow_1e309.json: not valid JSON: number overflow' -- \
  "$mlcp" run "$fuzz/scene_number_overflow_1e309.json" --engine ode --steps 1
check fuzz-box-size 2 'body "box": shape.size: 1e\+300 is outside' -- \
  "$mlcp" run "$fuzz/scene_box_size_1e308.json" --engine ode --steps 1
check fuzz-nested 2 'JSON nested deeper than 64 levels' -- \
  "$mlcp" run "$fuzz/scene_nested_5000.json" --engine bullet --steps 1
for engine in bullet ode; do
  if ! "$mlcp" run --help | grep -q "$engine"; then continue; fi
  check "fuzz-hinge-axis-$engine" 0 'with auto: 20 steps' -- \
    "$mlcp" run "$fuzz/scene_hinge_axis_1e308.json" --engine "$engine" --steps 20
done

# A run cut short (killed) leaves whole CSV rows: every line of 17 fields, the last one ended.
"$mlcp" run "$scenes/pyramid_55.json" --engine ode --solver pgs --steps 1000000 --csv "$tmp/killed.csv" \
  > /dev/null 2>&1 &
pid=$!
sleep 1.5
kill -9 "$pid" 2> /dev/null
wait "$pid" 2> /dev/null
if [ "$(wc -l < "$tmp/killed.csv")" -gt 2 ] && [ "$(tail -c 1 "$tmp/killed.csv" | od -An -c | tr -d ' ')" = '\n' ] &&
   awk -F, 'NF != 17 { bad = 1 } END { exit bad }' "$tmp/killed.csv"; then
  passed=$((passed + 1))
else
  failed=$((failed + 1)); echo "FAIL killed-run-csv: $(wc -l < "$tmp/killed.csv") lines, last: $(tail -c 80 "$tmp/killed.csv")"
fi
# --pivoting-steps reaches newton on the islands: without its pivoting phase the Bullet pyramid's
# resting steps end short of 1e-6 (no budget: the same answers on any machine), with it none does.
if "$mlcp" run --help | grep -q bullet; then
  for steps in 0 120; do
    expect=$([ "$steps" = 0 ] && echo ' [1-9][0-9]* steps not converged' || echo ' 0 steps not converged')
    check "pivoting-steps-$steps" 0 "$expect" -- "$mlcp" run "$scenes/pyramid_55.json" \
      --engine bullet --solver newton --steps 12 --fallback none --time-budget 0 --pivoting-steps "$steps"
  done
  check pivoting-steps-bad 2 'not in range' -- \
    "$mlcp" run "$scenes/stack_10.json" --engine bullet --steps 1 --pivoting-steps -1
fi
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
