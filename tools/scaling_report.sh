#!/usr/bin/env bash
# Time per step and per solve against island size, ours against the engines' own solvers and
# Siconos numerics', in one command: regenerates docs/scaling.png and the section "Scaling against
# the stock solvers and Siconos" of docs/benchmarks.md.
#
#   tools/scaling_report.sh [--quick] [--chart-only] [BUILD_DIR]
#
# 1. tests/bench/scale_bench.sh: every scene below in Bullet and ODE, each stock solver and ours
#    (pgs, dantzig, newton without a budget; auto with its default budget), SCALE_STEPS steps
#    (3 on the 1000-box scenes, 40 on boxes_3000 so that its falling block meets the pile), each
#    run cut at SCALE_LIMIT s.
# 2. Captures each scene's largest island at step CAPTURE_STEP (after the first steps' settling)
#    in both engines and runs build/bench/siconos_bench on them (when it was built: Siconos
#    numerics installed), each solve cut at SOLVE_LIMIT s.
# 3. tools/scaling_chart.py draws the chart and writes the section (command, commit, machine,
#    load average, tables).
# --quick: two small scenes, 3 steps, 10 s limits (checks the pipeline in about a minute); its
#          CSVs, chart and section go to BUILD_DIR/scaling-quick only.
# --chart-only: step 3 on the CSVs left in BUILD_DIR/scaling by an earlier run.
# Environment: SCALE_STEPS (10), SCALE_LIMIT (40), SOLVE_LIMIT (20), CAPTURE_STEP (5).
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
quick=0
chart_only=0
build=$repo/build
for a in "$@"; do
  case $a in
    --quick) quick=1 ;;
    --chart-only) chart_only=1 ;;
    -h|--help) sed -n 2,20p "${BASH_SOURCE[0]}"; exit 0 ;;
    *) build=$(cd "$a" && pwd) ;;
  esac
done
mlcp=$build/bin/mlcp
bench=$build/bench/siconos_bench
out=$build/scaling
python=$repo/.venv/bin/python
[ -x "$python" ] || { echo "scaling_report: no $python (run tools/setup.sh)"; exit 1; }
[ -x "$mlcp" ] || { echo "scaling_report: no $mlcp (run tools/build.sh $build)"; exit 1; }

steps=${SCALE_STEPS:-10}
limit=${SCALE_LIMIT:-40}
solve_limit=${SOLVE_LIMIT:-20}
capture_step=${CAPTURE_STEP:-5}
small=(pyramid_15 stack_10 pyramid_55 wall_120 pyramid_210)
large=(pyramid_1000 stack_1000)
boxes=(boxes_3000)
island_scenes=(stack_10 pyramid_15 pyramid_55 wall_120 pyramid_210)
if [ $quick -eq 1 ]; then
  out=$build/scaling-quick
  steps=3; limit=10; solve_limit=10
  small=(stack_10 pyramid_15); large=(); boxes=(); island_scenes=(stack_10 pyramid_15)
fi

if [ $chart_only -eq 0 ]; then
  rm -rf "$out"
  mkdir -p "$out/islands"
  uptime > "$out/load_start.txt"
  # Step 2 first: its islands are small and quick; step 1 holds the long runs.
  if [ -x "$bench" ]; then
    for scene in "${island_scenes[@]}"; do
      for engine in bullet ode; do
        cap=$out/capture/$scene-$engine
        "$mlcp" run "$repo/scenes/$scene.json" --engine "$engine" --solver pgs \
          --steps $((capture_step + 1)) --capture "$capture_step" --capture-dir "$cap" > /dev/null ||
          true
        largest=$(python3 -c 'import json,glob,sys
files = glob.glob(sys.argv[1] + "/*.json")
print(max(files, key=lambda f: json.load(open(f))["n"]))' "$cap")
        cp "$largest" "$out/islands/"
      done
    done
    "$bench" --time-limit "$solve_limit" --csv "$out/islands.csv" "$out"/islands/*.json \
      | tee "$out/islands.log"
  else
    echo "scaling_report: no $bench (Siconos numerics not installed): island table left out"
  fi
  bench_scale() {  # CSV STEPS SCENES...
    local csv=$1 n=$2
    shift 2
    [ $# -gt 0 ] || return 0
    "$repo/tests/bench/scale_bench.sh" "$mlcp" "$out/$csv" "$n" "$limit" "$@" | tee -a "$out/scale.log"
  }
  bench_scale scale_small.csv "$steps" "${small[@]}"
  bench_scale scale_large.csv 3 "${large[@]}"
  bench_scale scale_boxes.csv 40 "${boxes[@]}"
  uptime > "$out/load_end.txt"
  {
    echo "commit $(git -C "$repo" rev-parse --short HEAD)$(git -C "$repo" diff --quiet HEAD -- core || echo ' (core modified)')"
    echo "cpu $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'), $(nproc) cores"
    echo "steps $steps limit $limit solve_limit $solve_limit capture_step $capture_step quick $quick"
  } > "$out/machine.txt"
fi

# A quick run checks the pipeline: its chart and section stay in BUILD_DIR/scaling-quick.
if [ $quick -eq 1 ]; then
  "$python" "$repo/tools/scaling_chart.py" --dir "$out" --png "$out/scaling.png" --doc "$out/section.md"
else
  "$python" "$repo/tools/scaling_chart.py" --dir "$out" --png "$repo/docs/scaling.png" \
    --doc "$repo/docs/benchmarks.md"
fi
