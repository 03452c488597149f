#!/usr/bin/env bash
# `mlcp sweep` and `mlcp chart` as a user runs them: the tidy CSV's header, rows and columns;
# stock solvers that ignore the swept setting run once; --jobs gives the serial sweep's rows;
# exit 2 with a clear message on bad arguments; charts drawn from the sweep when the venv
# exists. Prints "N passed, N failed".
#   sweep_cli_test.sh MLCP SCENES_DIR REPO
set -u
mlcp=$1 scenes=$2 repo=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
source "$(dirname "${BASH_SOURCE[0]}")/../cli/check.sh"
header='setting,value,setting_applies,scene,engine,solver,step,solver_ms,step_ms,residual,iterations,status,fallbacks,choice,contacts,max_penetration,joint_error,energy,momentum,max_speed'
engines=$("$mlcp" sweep --help | sed -n 's/.*default: \([a-z, ]*\)).*/\1/p' | head -1 | tr -d ' ')
n_engines=$(tr ',' '\n' <<< "$engines" | grep -c .)

# sweep_ok NAME FILE ROWS AWK_CHECK: header, row count, 20 fields per row, numeric columns, and
# an awk condition on each row ($1 setting, $2 value, $3 applies, $5 engine, $6 solver, $7 step).
sweep_ok() {
  local name=$1 file=$2 rows=$3 cond=$4
  if [ "$(head -1 "$file")" = "$header" ] &&
     awk -F, -v n="$rows" '
       NR > 1 { if (NF != 20 || $4 != "resting_box" || !('"$cond"')) bad = 1
                for (i = 8; i <= 20; ++i) if (i != 12 && i != 14 && $i !~ /^-?([0-9.e+-]+|nan)$/) bad = 1 }
       END { exit bad || NR != n + 1 }' "$file"; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "FAIL $name: $file ($(($(wc -l < "$file") - 1)) rows, want $rows):"; head -3 "$file" | sed 's/^/    /'
  fi
}

# 2 solvers x 2 values x 3 steps in every engine built.
check sweep-runs 0 "wrote $tmp/a.csv: $((4 * n_engines)) runs, $((12 * n_engines)) rows" -- \
  "$mlcp" sweep "$scenes/resting_box.json" --solvers pgs,dantzig --setting iterations \
  --values 5,10 --steps 3 --csv "$tmp/a.csv"
sweep_ok sweep-csv "$tmp/a.csv" $((12 * n_engines)) \
  '$1 == "iterations" && ($2 == 5 || $2 == 10) && $3 == 1 && ($6 == "pgs" || $6 == "dantzig") && $7 >= 0 && $7 <= 2'
# Each (engine, solver, value) has steps 0, 1, 2.
if [ "$(cut -d, -f2,5,6,7 "$tmp/a.csv" | sort -u | wc -l)" -eq $((12 * n_engines + 1)) ]; then
  passed=$((passed + 1))
else
  failed=$((failed + 1)); echo "FAIL sweep-distinct: repeated (value, engine, solver, step) rows"
fi

# --repeat: the same rows (the runs are deterministic), times the minimum over the passes.
check sweep-repeat 0 "wrote $tmp/r.csv: $((4 * n_engines)) runs x 3 passes, $((12 * n_engines)) rows" -- \
  "$mlcp" sweep "$scenes/resting_box.json" --solvers pgs,dantzig --setting iterations \
  --values 5,10 --steps 3 --repeat 3 --csv "$tmp/r.csv"
if diff <(cut -d, -f1-7,10- "$tmp/a.csv") <(cut -d, -f1-7,10- "$tmp/r.csv") > /dev/null; then
  passed=$((passed + 1))
else
  failed=$((failed + 1)); echo "FAIL sweep-repeat-rows: --repeat 3 changed columns other than the times"
fi

if [ "$engines" = "bullet,ode" ]; then
  # Stock solvers ignore the tolerance: one run each, marked; the other engine's are skipped.
  check sweep-stock-skipped 0 'skipped \(not a solver of that engine\): bullet-si in ode, ode-world in bullet' -- \
    "$mlcp" sweep "$scenes/resting_box.json" --solvers bullet-si,ode-world --setting tolerance \
    --values 1e-3,1e-6 --steps 3 --csv "$tmp/b.csv"
  sweep_ok sweep-stock-csv "$tmp/b.csv" 6 '$1 == "tolerance" && $2 == 0.001 && $3 == 0'
  # ode-quick takes the iteration count: one run per value.
  check sweep-stock-iterations 0 "wrote $tmp/c.csv: 2 runs, 4 rows" -- \
    "$mlcp" sweep "$scenes/resting_box.json" --solvers ode-quick --values 3,7 --steps 2 --csv "$tmp/c.csv"
fi

# --append adds rows under the same header; a file of another kind is refused.
check sweep-append 0 "appended to $tmp/a.csv: $((2 * n_engines)) runs" -- \
  "$mlcp" sweep "$scenes/resting_box.json" --solvers pgs --values 7,8 --steps 3 --append --csv "$tmp/a.csv"
sweep_ok sweep-append-csv "$tmp/a.csv" $((18 * n_engines)) '$3 == 1 && $7 <= 2'
printf 'scene,engine\n' > "$tmp/other.csv"
check sweep-append-other 2 "other.csv is not a sweep CSV" -- \
  "$mlcp" sweep "$scenes/resting_box.json" --values 5 --steps 1 --append --csv "$tmp/other.csv"

# --jobs: every run in a worker process of its own; the rows, their order and every column but
# the times (solver_ms, step_ms: fields 8 and 9) are the serial sweep's, repeats and stock
# solvers (run once, skipped in the other engine) included.
same_rows() {  # same_rows NAME SERIAL_CSV JOBS_CSV
  if [ -s "$2" ] && diff <(cut -d, -f1-7,10- "$2") <(cut -d, -f1-7,10- "$3") > "$tmp/rows.diff"; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1)); echo "FAIL $1: --jobs changed the rows:"; head -5 "$tmp/rows.diff" | sed 's/^/    /'
  fi
}
jobs_sweep=("$scenes/resting_box.json" "$scenes/stack_10.json" --solvers pgs,dantzig,bullet-si,ode-quick
            --values 3,8 --steps 4)
check sweep-jobs-serial 0 'wrote' -- "$mlcp" sweep "${jobs_sweep[@]}" --csv "$tmp/j1.csv"
check sweep-jobs-2 0 'wrote' -- "$mlcp" sweep "${jobs_sweep[@]}" --jobs 2 --csv "$tmp/j2.csv"
same_rows sweep-jobs-2-rows "$tmp/j1.csv" "$tmp/j2.csv"
check sweep-jobs-all-cores 0 'wrote' -- "$mlcp" sweep "${jobs_sweep[@]}" --jobs 0 --csv "$tmp/j0.csv"
same_rows sweep-jobs-0-rows "$tmp/j1.csv" "$tmp/j0.csv"
check sweep-jobs-repeat 0 "x 3 passes" -- "$mlcp" sweep "$scenes/resting_box.json" --solvers pgs,dantzig \
  --setting iterations --values 5,10 --steps 3 --repeat 3 --jobs 3 --csv "$tmp/rj.csv"
same_rows sweep-jobs-repeat-rows "$tmp/r.csv" "$tmp/rj.csv"
if tr ',' '\n' <<< "$engines" | grep -qx ode; then
  # A run that throws in a worker (this ODE may have no cylinder-cylinder collider): the serial
  # sweep's exit code, message and rows up to it, whichever it is.
  printf '%s' '{"format": "mlcp-scene/1", "bodies": [
    {"name": "a", "shape": {"type": "cylinder", "radius": 0.5, "length": 0.2}, "mass": 1, "position": [0, 0, 0]},
    {"name": "b", "shape": {"type": "cylinder", "radius": 0.5, "length": 0.2}, "mass": 1, "position": [0, 0, 0.25]}]}' > "$tmp/cylinders.json"
  throwing=("$scenes/resting_box.json" "$tmp/cylinders.json" "$scenes/stack_10.json" --engines ode
            --solvers pgs,dantzig --values 5 --steps 30)
  "$mlcp" sweep "${throwing[@]}" --csv "$tmp/e1.csv" > /dev/null 2> "$tmp/e1.err"; e1=$?
  "$mlcp" sweep "${throwing[@]}" --jobs 2 --csv "$tmp/e2.csv" > /dev/null 2> "$tmp/e2.err"; e2=$?
  if [ "$e1" -eq "$e2" ] && [ "$(grep '^mlcp' "$tmp/e1.err")" = "$(grep '^mlcp' "$tmp/e2.err")" ]; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1)); echo "FAIL sweep-jobs-error: exit $e1 / $e2:"; grep -h '^mlcp' "$tmp/e1.err" "$tmp/e2.err"
  fi
  same_rows sweep-jobs-error-rows "$tmp/e1.csv" "$tmp/e2.csv"
fi

bad() {  # bad NAME PATTERN sweep-arguments...
  local name=$1 pattern=$2; shift 2
  check "$name" 2 "$pattern" -- "$mlcp" sweep "$scenes/resting_box.json" --steps 1 --csv "$tmp/bad.csv" "$@"
}
bad unknown-solver "unknown solver 'nosuch'" --solvers pgs,nosuch --values 5
bad unknown-engine "unknown engine 'physx'" --engines physx --values 5
bad unknown-setting "--setting: .*relaxation" --setting relaxation --values 5
bad empty-values "--values: an empty value" --values ""
bad fractional-iterations "'2.5' is not a whole number of iterations" --values 5,2.5
bad negative-tolerance "'-1e-6' is not a positive tolerance" --setting tolerance --values -1e-6
bad missing-values "--values is required" --solvers pgs
bad repeat-zero "--repeat: Value 0 not in range" --values 5 --repeat 0
bad jobs-negative "--jobs: Value -1 not in range" --values 5 --jobs -1
check missing-scene 2 'nope.json' -- "$mlcp" sweep "$tmp/nope.json" --values 5 --csv "$tmp/bad.csv"

# mlcp chart: a clear message without Python; bad CSVs pass through as exit 2; charts drawn.
check chart-no-python 1 'run tools/setup.sh' -- env MLCP_PYTHON="$tmp/no-python" \
  "$mlcp" chart work-precision "$tmp/a.csv" -o "$tmp/charts"
check chart-no-mode 2 'give a mode' -- "$mlcp" chart
if [ -x "$repo/.venv/bin/python" ]; then
  check chart-work-precision 0 "resting_box.png" -- \
    "$mlcp" chart work-precision "$tmp/a.csv" -o "$tmp/charts"
  for f in "$tmp/charts/resting_box.png" "$tmp/charts/resting_box.svg"; do
    if [ -s "$f" ]; then passed=$((passed + 1)); else failed=$((failed + 1)); echo "FAIL chart-file: $f missing"; fi
  done
  printf 'scene,engine\nx,y\n' > "$tmp/bad-sweep.csv"
  check chart-bad-csv 2 'missing column\(s\) solver' -- \
    "$mlcp" chart work-precision "$tmp/bad-sweep.csv" -o "$tmp/charts"
else
  echo "SKIP chart drawing: $repo/.venv/bin/python is missing (run tools/setup.sh)"
fi
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
