#!/usr/bin/env bash
# The adapters' example programs as a user runs them: a few steps of a small scene file, exit 0
# and the per-step statistics; exit 2 naming an unknown solver. Arguments: the bullet_pyramid
# and ode_pile programs ("" when that engine is not built) and the scenes folder.
set -u
pyramid=$1 pile=$2 scenes=$3
source "$(dirname "${BASH_SOURCE[0]}")/../cli/check.sh"
stats='^step +3: islands [0-9]+ rows [0-9]+ iterations [0-9]+ residual [0-9.e+-]+ status '
if [ -n "$pyramid" ]; then
  check pyramid-dantzig 0 "$stats" -- \
    "$pyramid" --scene "$scenes/pyramid_15.json" --solver dantzig --steps 3 --every 1
  check pyramid-totals 0 '^totals over 3 steps: [0-9.]+ ms per step' -- \
    "$pyramid" --scene "$scenes/stack_10.json" --solver pgs --steps 3
  check pyramid-si 0 '^top body: height 4\.[0-9]+ m \(started at 4\.5' -- \
    "$pyramid" --scene "$scenes/pyramid_15.json" --solver si --steps 3
  check pyramid-unknown 2 "unknown solver 'nosuch'" -- "$pyramid" --solver nosuch --steps 1
fi
if [ -n "$pile" ]; then
  ode_stats='^step +3: contacts [0-9]+ islands [0-9]+ rows [1-9][0-9]* iterations [0-9]+ residual'
  check pile-dantzig 0 "$ode_stats" -- \
    "$pile" --scene "$scenes/stack_10.json" --solver dantzig --steps 3 --every 1
  check pile-dworldstep 0 '^step +3: contacts [1-9][0-9]* step [0-9.]+ ms' -- \
    "$pile" --scene "$scenes/stack_10.json" --solver dWorldStep --steps 3 --every 1
  check pile-totals 0 '^totals over 3 steps: [0-9.]+ ms per step, worst residual' -- \
    "$pile" --scene "$scenes/stack_10.json" --solver auto --steps 3
  check pile-unknown 2 "unknown solver 'nosuch'" -- "$pile" --solver nosuch --steps 1
fi
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ] && [ "$passed" -gt 0 ]
