#!/usr/bin/env bash
# What each friction model costs and buys (mlcp::FrictionModel): the box (auto: dantzig) against
# the polyhedral cone (auto: lemke) with k = 4, 8 directions (and 16 on slide_diagonal), in both engines, through
# `mlcp run` without a time budget. Writes one CSV row per (scene, engine, model):
#   scene,engine,model,k,steps,mean_solver_ms,max_solver_ms,worst_residual,box_answers,stop_x,stop_y,heading_deg,heading_error_deg,distance_error
# mean/max_solver_ms: solver time per step; worst_residual: the worst step's (for the cone its
# LCP's); box_answers: steps whose answer came from box friction (a rejected cone answer's box
# fallback, or the box model itself). slide_diagonal only: where the slab stops against the
# closed form of isotropic Coulomb friction (0.794, 0.459), heading 30 degrees, 0.917 m.
# steps: the steps done within the wall-clock limit of each run (LIMIT_SECONDS, default 120).
# Usage: tests/bench/friction_models.sh MLCP_BINARY OUT.csv [LIMIT_SECONDS] [SCENES...]
set -uo pipefail
mlcp=$1
out=$2
limit=${3:-120}
shift 3 2>/dev/null || shift $#
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=(slide_diagonal stack_10 pyramid_15)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "scene,engine,model,k,steps,mean_solver_ms,max_solver_ms,worst_residual,box_answers,stop_x,stop_y,heading_deg,heading_error_deg,distance_error" > "$out"
for scene in "${scenes[@]}"; do
  for engine in bullet ode; do
    for model in "box 4" "cone 4" "cone 8" "cone 16"; do
      set -- $model
      # k = 16 on the slab only: lemke's dense tableau makes it seconds a step on a pyramid.
      [ "$scene" != slide_diagonal ] && [ "$2" = 16 ] && continue
      steps=$([ "$scene" = slide_diagonal ] && echo 60 || echo 100)
      timeout "$limit" "$mlcp" run "$repo/scenes/$scene.json" --engine "$engine" --friction "$1" \
        --friction-directions "$2" --steps "$steps" --time-budget 0 \
        --csv "$work/run.csv" --trajectory "$work/traj.csv" > /dev/null 2>&1
      python3 - "$scene" "$engine" "$1" "$2" "$work/run.csv" "$work/traj.csv" >> "$out" <<'EOF'
import csv, math, sys
scene, engine, model, k, run, traj = sys.argv[1:]
rows = list(csv.DictReader(open(run)))
if not rows:
    print(",".join([scene, engine, model, k, "0"] + [""] * 9))
    sys.exit()
ms = [float(r["solver_ms"]) for r in rows]
res = max(float(r["residual"]) for r in rows)
# A step answered by the box: the model is the box, or some island's answer came from pgs (the
# cone's box fallback; the cone's own answers come from lemke or dantzig).
box = sum(1 for r in rows if model == "box" or "pgs" in r["choice"])
stop = ["", "", "", "", ""]
if scene == "slide_diagonal":
    last = list(csv.DictReader(open(traj)))[-1]
    x, y = float(last["x"]), float(last["y"])
    heading = math.degrees(math.atan2(y, x))
    stop = [f"{x:.3f}", f"{y:.3f}", f"{heading:.1f}", f"{heading - 30:.1f}",
            f"{math.hypot(x, y) / 0.9174 - 1:+.2f}"]
print(",".join([scene, engine, model, k if model == "cone" else "", str(len(rows)),
                f"{sum(ms) / len(ms):.3f}", f"{max(ms):.3f}", f"{res:.1e}", str(box)] + stop))
EOF
    done
  done
done
