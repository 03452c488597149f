#!/usr/bin/env bash
# The friction model from the command line and the scene file: `mlcp run --friction cone
# --friction-directions 8` runs the slab of slide_diagonal on the cone's LCP in both engines,
# `--capture` writes that standard LCP (lo = 0, hi = inf, 1 + k + 1 unknowns per contact: ODE
# makes 4 contacts, Bullet's manifold of the sliding slab 1 to 4),
# which `mlcp solve` replays with lemke; bad settings exit 2 with one line naming the setting.
set -u
mlcp=$1 scenes=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
source "$(dirname "${BASH_SOURCE[0]}")/../cli/check.sh"
scene=$scenes/slide_diagonal.json
engines=$("$mlcp" run --help | grep -oE 'engine: [a-z, ]+' | head -1)
for engine in bullet ode; do
  case $engines in *$engine*) ;; *) continue ;; esac
  check "cone-$engine" 0 '' -- "$mlcp" run "$scene" --engine "$engine" --friction cone \
    --friction-directions 8 --steps 10 --time-budget 0 --csv "$tmp/$engine.csv"
  # Every step answered by lemke on the cone's LCP, within the island tolerance.
  check "cone-$engine-lemke" 0 '^10$' -- \
    awk -F, 'NR > 1 && $11 ~ /^lemke:/ && $7 < 1e-6 { n++ } END { print n + 0 }' "$tmp/$engine.csv"
  check "capture-$engine" 0 'captured step 3: 1' -- "$mlcp" run "$scene" --engine "$engine" \
    --friction cone --friction-directions 8 --steps 5 --capture 3 --capture-dir "$tmp/cap-$engine"
  for f in "$tmp/cap-$engine"/*.json; do
    check "capture-$engine-standard-lcp" 0 '^(10|20|30|40) standard$' -- python3 -c '
import json, sys
p = json.load(open(sys.argv[1]))
lo, hi = p.get("lo", [0] * p["n"]), p.get("hi", ["inf"] * p["n"])
standard = all(v == 0 for v in lo) and all(v == "inf" for v in hi)
print(p["n"], "standard" if standard else "mixed")' "$f"
    check "replay-$engine-lemke" 0 'status +converged' -- "$mlcp" solve "$f" --solver lemke --tol 1e-9
  done
done
check directions-low 2 'friction-directions' -- "$mlcp" run "$scene" --engine ode --friction cone --friction-directions 2
check directions-high 2 'friction-directions' -- "$mlcp" run "$scene" --engine ode --friction cone --friction-directions 65
check model-unknown 2 'friction' -- "$mlcp" run "$scene" --engine ode --friction pyramid
check cone-pgs 2 "friction 'cone'.*pgs" -- "$mlcp" run "$scene" --engine ode --friction cone --solver pgs --steps 1
check cone-stock-ode 2 "friction 'cone' needs a core solver" -- "$mlcp" run "$scene" --engine ode --friction cone --solver ode-world --steps 1
check cone-stock-bullet 2 "friction 'cone' needs a core solver" -- "$mlcp" run "$scene" --engine bullet --friction cone --solver bullet-si --steps 1
# The scene's own setting, and a bad one in the file.
sed 's/"settings": {"steps": 60}/"settings": {"steps": 60}, "solver": {"friction": "cone", "friction_directions": 4}/' \
  "$scene" > "$tmp/cone_scene.json"
check scene-cone 0 '' -- "$mlcp" run "$tmp/cone_scene.json" --engine ode --steps 3 --csv "$tmp/scene.csv"
check scene-cone-lemke 0 '^3$' -- awk -F, 'NR > 1 && $11 ~ /^lemke:/ { n++ } END { print n + 0 }' "$tmp/scene.csv"
sed 's/"friction_directions": 4/"friction_directions": 1/' "$tmp/cone_scene.json" > "$tmp/bad_scene.json"
check scene-bad-directions 2 'solver.friction_directions' -- "$mlcp" run "$tmp/bad_scene.json" --engine ode --steps 1
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
