#!/usr/bin/env bash
# The main job: set-up, build, then every solver on the seed's worked example and the Siconos
# LCP corpus, one line per (problem, solver).
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$repo/tools/setup.sh"
"$repo/tools/build.sh" "$repo/build" > /dev/null
siconos=${MLCP_SICONOS_DIR:-$repo/../shared/data/siconos}
"$repo/build/bin/mlcp" table "$repo/tests/data/seed_lemke.json" "$repo/tests/data/spd.json" \
  "$repo/tests/data/boxed.json" "$repo/tests/data/findex.json" "$siconos"/lcp/*.dat
