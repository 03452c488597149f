#!/usr/bin/env bash
# tools/report.sh [OUT]: the comparison report of the main job (tools/main.sh), into OUT
# (default build/report): a sweep of a few small scenes in both engines (articulated ones also
# in bullet-multibody) with stock and our solvers (sweep.csv), work-precision charts per scene
# (charts/), the stability map (stability.csv, stability/), the worked-example + Siconos solver
# table (table.md), summary.md and index.html. Needs a built mlcp and the chart venv; prints
# where the report is.
#
# Environment: MLCP (the mlcp program, default build/bin/mlcp), MLCP_PYTHON (default
# .venv/bin/python), MLCP_REPORT_QUICK=1 (a smoke run: 2 scenes, 5 steps; for the tests).
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out=${1:-$repo/build/report}
mlcp=${MLCP:-$repo/build/bin/mlcp}
py=${MLCP_PYTHON:-$repo/.venv/bin/python}
siconos=$repo/tests/data/siconos
export MLCP_PYTHON=$py  # `mlcp chart` uses the same interpreter

[ -x "$mlcp" ] || { echo "report: $mlcp is missing; build first (tools/build.sh)" >&2; exit 2; }
[ -x "$py" ] || { echo "report: $py is missing; run tools/setup.sh" >&2; exit 2; }

# The comparison. Small scenes that each stress something else: a tall stack, a box pyramid
# (contacts with friction), a chain with a 100:1 end mass (joints), a motor against limits, and
# a mass ratio of 4 per level, 216 frictionless spheres in a box. 300 steps of each scene's own
# time step: 5 s of simulated time at 1/60 s, 1.25 s for pendulum_chain at 1/240 s (pyramid_55
# is left out: stock btMLCPSolver takes ~0.5 s a step on it, which alone would take the whole
# budget of a few minutes). Iterative solvers run at several iteration counts (a curve per
# solver on the charts), pivoting ones at one (a point): their iteration limit only caps
# friction passes. No fallback: each solver alone. summary.md says per scene whether auto is on
# the Pareto front of these points (tools/report.py). Each run is repeated in 3 passes and each
# step keeps its shortest time (`mlcp sweep --repeat`): single runs of a few ms moved by 30%
# between runs on a shared 2-core machine, enough to flip the front between identical solvers.
scenes=(stack_10 pyramid_15 pendulum_chain hinge_motor_limits mass_ratio_stack sphere_pit)
# Articulated scenes run also in reduced coordinates (engine bullet-multibody: btMultiBody, the
# core solvers through the multibody drop-in): the arm pushing boxes and the chain holding its
# joint limits.
articulated=(arm_push limit_chain)
iterative=pgs,bullet-si,ode-quick
iterative_values=5,10,20,50,100
pivoting=dantzig,auto,bullet-mlcp-dantzig,ode-world
pivoting_values=50
steps=300
repeat=3
stability_args=()
if [ "${MLCP_REPORT_QUICK:-0}" = 1 ]; then
  scenes=(stack_10 pendulum_chain)
  articulated=(limit_chain)
  iterative=pgs,bullet-si,ode-quick
  iterative_values=5,20
  pivoting=dantzig,auto  # auto: the Pareto table has its row
  steps=5
  repeat=1
  stability_args=(--quick)
fi
scene_files=()
for s in "${scenes[@]}"; do scene_files+=("$repo/scenes/$s.json"); done
articulated_files=()
for s in "${articulated[@]}"; do articulated_files+=("$repo/scenes/$s.json"); done

mkdir -p "$out"
rm -rf "$out/charts" "$out/stability"
rm -f "$out"/{sweep.csv,stability.csv,table.md,summary.md,index.html,report.log}
start=$SECONDS
notes=()
# Progress and engine messages (ODE prints one per failed dWorldStep solve) go to report.log.
log=$out/report.log
step() {  # step TITLE command...: runs the command, its stderr into the log; exit 1 is data
  local title=$1 t0=$SECONDS code=0
  shift
  printf 'report: %s ... ' "$title"
  echo "== $title" >> "$log"
  "$@" 2>> "$log" > /dev/null || code=$?
  echo "$((SECONDS - t0)) s"
  # Exit 1 from sweep: some run blew up. A finding (summary.md flags it), not a failure here.
  if [ $code -gt 1 ]; then
    echo "report: '$*' failed (exit $code); the end of $log:" >&2
    tail -20 "$log" >&2
    exit $code
  fi
}

sweep() {  # sweep SOLVERS VALUES ENGINES SCENE_FILES... [--append]: into sweep.csv
  local solvers=$1 values=$2 engines=$3
  shift 3
  step "sweep: $solvers at iterations $values in $engines" "$mlcp" sweep "$@" \
    --engines "$engines" --solvers "$solvers" --setting iterations --values "$values" \
    --steps "$steps" --repeat "$repeat" --fallback none --csv "$out/sweep.csv"
}
echo "report: ${#scenes[@]} scenes (${scenes[*]}) in bullet and ode, ${#articulated[@]}" \
  "articulated (${articulated[*]}) also in bullet-multibody, $steps steps per run"
sweep "$iterative" "$iterative_values" bullet,ode "${scene_files[@]}"
sweep "$pivoting" "$pivoting_values" bullet,ode "${scene_files[@]}" --append
sweep "$iterative" "$iterative_values" bullet,bullet-multibody,ode "${articulated_files[@]}" --append
sweep "$pivoting" "$pivoting_values" bullet,bullet-multibody,ode "${articulated_files[@]}" --append
step "work-precision charts" "$mlcp" chart work-precision "$out/sweep.csv" -o "$out/charts"
# Stability map: `mlcp stability` (its grid and thresholds are its own defaults).
commands=$("$mlcp" --help)  # (not piped into grep -q: with pipefail, an early exit fails)
if grep -qE '^ +stability' <<< "$commands"; then
  step "stability map" "$mlcp" stability "${stability_args[@]}" --csv "$out/stability.csv"
  step "stability charts" "$mlcp" chart heatmap "$out/stability.csv" -o "$out/stability"
else
  notes+=("No stability map: this mlcp has no 'stability' command.")
fi

# The Siconos corpus is test data in the repository (tests/data/siconos).
printf 'report: seed and Siconos solver table ... '
t0=$SECONDS
"$mlcp" table --markdown "$repo/tests/data/seed_lemke.json" "$repo/tests/data/spd.json" \
  "$repo/tests/data/boxed.json" "$repo/tests/data/findex.json" "$siconos"/lcp/*.dat \
  --solvers pgs,lemke,dantzig,auto > "$out/table.md"
printf '\nSiconos MLCP files (free rows for the equalities), tolerance 1e-9:\n\n' >> "$out/table.md"
"$mlcp" table --markdown "$siconos"/mlcp/*.dat --solvers pgs,lemke,dantzig,auto --tol 1e-9 \
  >> "$out/table.md"
echo "$((SECONDS - t0)) s"

elapsed=$((SECONDS - start))
notes+=("Made by tools/report.sh in ${elapsed} s on $(nproc) cores, $(date -u '+%Y-%m-%d %H:%M UTC'), commit $(git -C "$repo" rev-parse --short HEAD 2> /dev/null || echo unknown).")
notes+=("Sweep: ${scenes[*]} in bullet and ode; ${articulated[*]} (articulated) in bullet, bullet-multibody (reduced coordinates) and ode; $steps steps of each scene's time step per run; iterations $iterative_values for $iterative, $pivoting_values for $pivoting; no fallback (--fallback none): each solver alone.")
note_args=()
for n in "${notes[@]}"; do note_args+=(--note "$n"); done
"$py" "$repo/tools/report.py" "$out" "${note_args[@]}" > /dev/null
grep -A3 "blew up" "$log" | sed 's/^/report: /' || true
echo "report: $out/index.html (summary.md, charts/, stability/, sweep.csv) in ${elapsed} s"
