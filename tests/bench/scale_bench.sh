#!/usr/bin/env bash
# Time per step against island size: each (scene, engine, solver) runs through `mlcp run` for a
# few steps at tolerance 1e-6 (no fallback, so each status is the solver's own), each run bounded
# by a wall-clock limit and an address-space limit. Writes one CSV row per run:
#   scene,engine,solver,rows,islands,largest_island,steps_done,first_ms,median_ms,worst_residual,
#   converged_steps,limited,median_step_ms
# rows: the step's rows over all islands at step CAPTURE_STEP (captured once per scene and engine
# with pgs), islands and largest_island their count and the largest one's rows; first_ms /
# median_ms: the solver's time per step (solver_ms of `mlcp run`), median_step_ms the whole step;
# limited: 1 when the wall-clock limit ended the run (no step is reported then: `mlcp run` writes
# its CSV at the end), 2 when the run was skipped because a dense solver's n x n matrix would
# exceed DENSE_ROWS rows (Bullet's btMLCPSolver and ODE's dWorldStep build A dense), 3 when the
# run failed otherwise (an allocation refused by the memory limit, a crash: the exit code is
# not 0 or 1).
#
# Solvers: Bullet's btSequentialImpulseConstraintSolver (bullet-si), btMLCPSolver with its Dantzig
# and Lemke (bullet-mlcp-dantzig, bullet-mlcp-lemke); ODE's dWorldStep and dWorldQuickStep
# (ode-world, ode-quick); ours pgs, dantzig, newton with no time budget (each solve runs to its
# tolerance or its iteration limit) and auto with its default per-step budget (0.05 s), as an
# engine runs it.
#
# Usage: tests/bench/scale_bench.sh MLCP_BINARY OUT.csv [STEPS] [LIMIT_SECONDS] [SCENES...]
# Environment: ENGINES (default "bullet ode"), SOLVERS (ours, default "pgs dantzig newton auto"),
# STOCK (the engines' solvers to run, default all of the engine's above; "" for none),
# DENSE_ROWS (default 12000), MEMORY_KB (address-space limit of each run, default 8000000),
# CAPTURE_STEP (default 0), MLCP_RUN_ARGS (more `mlcp run` options for every run).
set -uo pipefail
mlcp=$1
out=$2
steps=${3:-20}
limit=${4:-120}
shift 4 2>/dev/null || shift $#
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=(pyramid_55 pyramid_210 pyramid_1000)
read -r -a engines <<< "${ENGINES:-bullet ode}"
read -r -a ours <<< "${SOLVERS:-pgs dantzig newton auto}"
dense_rows=${DENSE_ROWS:-12000}
memory_kb=${MEMORY_KB:-8000000}
capture_step=${CAPTURE_STEP:-0}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "scene,engine,solver,rows,islands,largest_island,steps_done,first_ms,median_ms,worst_residual,converged_steps,limited,median_step_ms" > "$out"

# rows,islands,largest of the captured folder $1.
island_sizes() {
  python3 -c 'import json,glob,sys
n = [json.load(open(f))["n"] for f in glob.glob(sys.argv[1] + "/*.json")]
print(f"{sum(n)},{len(n)},{max(n) if n else 0}")' "$1"
}

# steps_done,first_ms,median_ms,worst_residual,converged_steps,median_step_ms of an `mlcp run` CSV.
summarise() {
  python3 - "$1" <<'PY'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
ms = [float(r["solver_ms"]) for r in rows]
step = [float(r["step_ms"]) for r in rows]
res = [float(r["residual"]) for r in rows if r["residual"] not in ("", "nan")]
conv = sum(1 for r in rows if r["status"] == "converged")
worst = f"{max(res):.3g}" if res else "nan"
print(f"{len(rows)},{ms[0]:.3f},{statistics.median(ms):.3f},{worst},{conv},"
      f"{statistics.median(step):.3f}")
PY
}

for scene in "${scenes[@]}"; do
  file=$repo/scenes/$scene.json
  for engine in "${engines[@]}"; do
    cap=$work/cap-$scene-$engine
    "$mlcp" run "$file" --engine "$engine" --solver pgs --steps $((capture_step + 1)) \
      --capture "$capture_step" --capture-dir "$cap" > /dev/null 2>&1
    sizes=$(island_sizes "$cap")
    largest=${sizes##*,}
    if [ -n "${STOCK+set}" ]; then
      read -r -a stock <<< "$STOCK"
    elif [ "$engine" = bullet ]; then
      stock=(bullet-si bullet-mlcp-dantzig bullet-mlcp-lemke)
    else
      stock=(ode-world ode-quick)
    fi
    for solver in "${stock[@]}" "${ours[@]}"; do
      csv=$work/run.csv
      rm -f "$csv"
      budget=(--time-budget 0)
      [ "$solver" = auto ] && budget=()
      case $solver in bullet-mlcp-*|ode-world) dense=1 ;; *) dense=0 ;; esac
      if [ $dense -eq 1 ] && [ "$largest" -gt "$dense_rows" ]; then
        echo "$scene,$engine,$solver,$sizes,0,,,,0,2," | tee -a "$out"
        continue
      fi
      [[ $solver == bullet-* || $solver == ode-* ]] && budget=()
      (ulimit -v "$memory_kb"
       exec timeout "$limit" "$mlcp" run "$file" --engine "$engine" --solver "$solver" \
         --steps "$steps" --tol 1e-6 --fallback none "${budget[@]}" ${MLCP_RUN_ARGS:-} --csv "$csv") \
        > /dev/null 2>&1
      rc=$?
      limited=0
      [ $rc -eq 124 ] && limited=1
      [ $rc -gt 1 ] && [ $rc -ne 124 ] && limited=3
      if [ -s "$csv" ]; then
        summary=$(summarise "$csv")
        s=${summary%,*}
        echo "$scene,$engine,$solver,$sizes,$s,$limited,${summary##*,}" | tee -a "$out"
      else
        echo "$scene,$engine,$solver,$sizes,0,,,,0,$limited," | tee -a "$out"
      fi
    done
  done
done
