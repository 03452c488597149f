#!/usr/bin/env bash
# Time per step against island size: each (scene, engine, solver) runs through `mlcp run` for a
# few steps at tolerance 1e-6 (no fallback, so each status is the solver's own), each run bounded
# by a wall-clock limit. Writes one CSV row per run:
#   scene,engine,solver,rows,steps_done,first_ms,median_ms,worst_residual,converged_steps,limited
# rows: the island's rows at step 0 (captured once per scene and engine with pgs); limited: 1 when
# the wall-clock limit ended the run (first_ms / median_ms then cover the steps that finished).
# Usage: tests/bench/scale_bench.sh MLCP_BINARY OUT.csv [STEPS] [LIMIT_SECONDS] [SCENES...]
# MLCP_RUN_ARGS (environment): more `mlcp run` options for every run, e.g. "--time-budget 0".
set -uo pipefail
mlcp=$1
out=$2
steps=${3:-20}
limit=${4:-120}
shift 4 2>/dev/null || shift $#
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=(pyramid_55 pyramid_210 pyramid_1000)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "scene,engine,solver,rows,steps_done,first_ms,median_ms,worst_residual,converged_steps,limited" > "$out"
for scene in "${scenes[@]}"; do
  file=$repo/scenes/$scene.json
  for engine in bullet ode; do
    rows=$("$mlcp" run "$file" --engine "$engine" --solver pgs --steps 1 --capture 0 \
             --capture-dir "$work/cap-$scene-$engine" > /dev/null 2>&1 &&
           python3 -c 'import json,glob,sys
print(sum(json.load(open(f))["n"] for f in glob.glob(sys.argv[1] + "/*.json")))' \
             "$work/cap-$scene-$engine")
    if [ "$engine" = bullet ]; then stock=(bullet-si bullet-mlcp-dantzig); else stock=(ode-world ode-quick); fi
    for solver in "${stock[@]}" pgs dantzig newton; do
      csv=$work/run.csv
      rm -f "$csv"
      timeout "$limit" "$mlcp" run "$file" --engine "$engine" --solver "$solver" --steps "$steps" \
        --tol 1e-6 --fallback none ${MLCP_RUN_ARGS:-} --csv "$csv" > /dev/null 2>&1
      rc=$?
      limited=0
      [ $rc -eq 124 ] && limited=1
      # mlcp run writes its CSV at the end: a run cut by the limit has none.
      if [ -s "$csv" ]; then
        summary=$(python3 - "$csv" <<'PY'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
ms = [float(r["solver_ms"]) for r in rows]
res = [float(r["residual"]) for r in rows if r["residual"] not in ("", "nan")]
conv = sum(1 for r in rows if r["status"] == "converged")
print(f"{len(rows)},{ms[0]:.2f},{statistics.median(ms):.2f},{max(res) if res else float('nan'):.3g},{conv}")
PY
)
      else
        summary="0,,,,0"
      fi
      echo "$scene,$engine,$solver,$rows,$summary,$limited" | tee -a "$out"
    done
  done
done
