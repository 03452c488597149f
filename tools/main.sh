#!/usr/bin/env bash
# The main job: set-up, build, then the comparison report (tools/report.sh): a few small scenes
# in Bullet and ODE with stock and our solvers, work-precision charts per scene, the stability
# map, the worked-example + Siconos solver table, summary.md and index.html. Prints where the report is.
#   tools/main.sh [REPORT_DIR]     (default build/report)
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$repo/tools/setup.sh"
"$repo/tools/build.sh" "$repo/build" > /dev/null
MLCP="$repo/build/bin/mlcp" "$repo/tools/report.sh" "${1:-$repo/build/report}"
