#!/usr/bin/env bash
# The polyhedral cone on a pile with lemke against the box model's solvers, both engines, one
# run: per engine and configuration (lemke on the cone with k = 4 and 8 directions; auto and
# dantzig on the box), `mlcp run SCENE --time-budget 0` for STEPS steps, and one line with the
# mean and max solver ms per step and the steps converged.
# Usage: tests/bench/cone_pyramid.sh MLCP_BINARY [SCENE (default scenes/pyramid_55.json)] [STEPS (10)]
set -uo pipefail
mlcp=$1
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
scene=${2:-$repo/scenes/pyramid_55.json}
steps=${3:-10}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for engine in ode bullet; do
  for cfg in "lemke cone 4" "lemke cone 8" "auto box 4" "dantzig box 4"; do
    set -- $cfg
    csv=$work/$engine-$1-$2-$3.csv
    "$mlcp" run "$scene" --engine "$engine" --solver "$1" --friction "$2" \
      --friction-directions "$3" --time-budget 0 --steps "$steps" --csv "$csv" >/dev/null 2>&1
    tail -n +2 "$csv" | awk -F, -v label="$engine $cfg" '
      { s += $5; n++; if ($9 == "converged") c++; if ($5 > m) m = $5 }
      END { printf "%s: mean solver %.1f ms, max %.1f ms, converged %d/%d\n", label, s / n, m, c, n }'
  done
done
