#!/usr/bin/env bash
# ODE 0.16.2's own demos, headless, with dWorldStep / dWorldQuickStep swapped for
# mlcp::ode::Stepper, against the stepping function each demo calls ("stock").
#
#   tools/ode-demos/run.sh          (from the project root, after building the target mlcp_ode)
#
# Environment: PROJECT (default: the current folder), BUILD (default $PROJECT/build), CACHE
# (default /tmp/ode-demos-cache: the harness build and the runs), DEMOS (space-separated subset),
# SOLVERS (default "stock auto"; any name mlcp::ode::Stepper accepts), FRAMES_SCALE (multiplies
# the frame counts), JOBS (build jobs, default 2), TIMEOUT (seconds per run, default 300),
# CALLGRIND=1 (each run under callgrind, counting the instructions inside the step calls: a
# measure the machine's load does not move; use FRAMES_SCALE=0.25 or so, callgrind is ~50x slower).
# Prints the table, writes $CACHE/runs/results.csv; exit 0 only if no library run crashes or
# produces NaN where the stock run does not.
set -uo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
PROJECT=$(cd "${PROJECT:-$PWD}" && pwd) || { echo "PROJECT not found" >&2; exit 2; }
BUILD=$(cd "${BUILD:-$PROJECT/build}" && pwd) || { echo "no build tree" >&2; exit 2; }
CACHE=${CACHE:-/tmp/ode-demos-cache}
SOLVERS=${SOLVERS:-"stock auto"}
FRAMES_SCALE=${FRAMES_SCALE:-1}
JOBS=${JOBS:-2}
TIMEOUT=${TIMEOUT:-300}
wrap=()
if [[ -n ${CALLGRIND:-} ]]; then
  wrap=(valgrind --tool=callgrind --callgrind-out-file=/dev/null
        "--toggle-collect=*::step(char const*, dxWorld*, double)")
  TIMEOUT=$((TIMEOUT * 20))
fi
log() { printf '[ode-demos] %s\n' "$*" >&2; }
mkdir -p "$CACHE"

# ------------------------------------------------------------------ the demos
# demo  frames  key script (ODE_DEMO_KEYS: frame:key ..., "-" for none)  why the keys
demo_table="
demo_I                  600  -
demo_basket             600  -
demo_boxstack           600  1:b 20:s 40:c 60:x 80:y 100:b 120:s 140:c 160:b 180:s   drops bodies on keys only
demo_buggy              600  -
demo_cards              300  -
demo_chain1             600  -
demo_chain2             600  -
demo_crash              300  -
demo_cyl                600  -
demo_cylvssphere        600  -
demo_dball              600  -
demo_dhinge             600  -
demo_feedback           600  -
demo_friction           600  -
demo_gyro2              600  -
demo_gyroscopic         600  -
demo_heightfield        600  1:b 20:s 40:c 60:x 80:y 100:b 120:s 140:c 160:b 180:s   drops bodies on keys only
demo_hinge              600  -
demo_jointPR            600  -
demo_jointPU            600  -
demo_joints             600  -
demo_kinematic          600  -
demo_motion             600  -
demo_motor              600  -
demo_moving_convex      600  1:b 20:s 40:c 60:v 80:b 100:s 120:c 140:b   drops bodies on keys only
demo_moving_trimesh     600  1:b 20:s 40:c 60:x 80:y 100:b 120:s 140:c 160:v   drops bodies on keys only
demo_piston             600  -
demo_plane2d            600  -
demo_rfriction          600  -
demo_slider             600  -
demo_step               600  -
demo_tracks             600  -
demo_transmission       600  -
demo_trimesh            600  1:b 20:s 40:c 60:x 80:y 100:b 120:s 140:c   drops bodies on keys only
"
# Not run, and why.
SKIPPED="demo_collision: collision tests only, never steps a world; demo_space: collision of a space only, never steps; demo_ode: ODE's unit tests, no simulation loop; demo_convex: ODE's own dWorldQuickStep aborts in its first frames (dNormalize4 assertion in dxStepBody) with Debian's double libode; demo_space_stress: 10000 spheres, one stock dWorldQuickStep takes about 60 s here"

# ------------------------------------------------------------------ ODE's source (demos, drawstuff.h)
ode_src=$(sed -n 's/^MLCP_ODE_SOURCE_DIR:PATH=//p' "$BUILD/CMakeCache.txt" 2>/dev/null)
[[ -f ${ode_src:-/nonexistent}/ode/demo/demo_boxstack.cpp ]] || ode_src=$PROJECT/.deps/ode-0.16.2
if [[ ! -f $ode_src/ode/demo/demo_boxstack.cpp ]]; then
  "$PROJECT/tools/fetch-ode-source.sh" >&2 || { echo "no ODE 0.16.2 source" >&2; exit 2; }
fi
[[ -f $BUILD/adapters/ode/libmlcp_ode.a ]] || {
  echo "no $BUILD/adapters/ode/libmlcp_ode.a: build it first (cmake --build build --target mlcp_ode)" >&2; exit 2; }

demos=()
while read -r demo _; do
  [[ -z ${demo:-} ]] && continue
  if [[ -n ${DEMOS:-} && " $DEMOS " != *" $demo "* ]]; then continue; fi
  demos+=("$demo")
done <<<"$demo_table"

# ------------------------------------------------------------------ the harness
hb=$CACHE/build
cmake -S "$here" -B "$hb" -G Ninja -DODE_SOURCE="$ode_src" -DMLCP_PROJECT="$PROJECT" -DMLCP_BUILD="$BUILD" \
  "-DDEMOS=$(IFS=';'; echo "${demos[*]}")" >"$CACHE/configure.log" 2>&1 || { tail -30 "$CACHE/configure.log" >&2; exit 2; }
nice cmake --build "$hb" -j "$JOBS" >"$CACHE/build.log" 2>&1 || { grep -E 'error|Error' "$CACHE/build.log" | head -20 >&2; exit 2; }
log "harness built in $hb (ODE source $ode_src, mlcp $BUILD at $(git -C "$PROJECT" rev-parse --short HEAD 2>/dev/null))"

# ------------------------------------------------------------------ the runs
runs=$CACHE/runs
rm -rf "$runs"; mkdir -p "$runs"
echo "$SKIPPED" >"$runs/skipped.txt"
while read -r demo frames keys why; do
  [[ -z ${demo:-} ]] && continue
  [[ " ${demos[*]} " == *" $demo "* ]] || continue
  frames=$(awk -v f="$frames" -v s="$FRAMES_SCALE" 'BEGIN{printf "%d", f*s}')
  [[ $keys == - ]] && keys=""
  for solver in $SOLVERS; do
    stem=$runs/$demo.$solver
    (cd "$ode_src/ode/demo" && ODE_DEMO_SOLVER=$solver ODE_DEMO_OUT=$stem.json ODE_DEMO_KEYS=$keys \
      nice timeout -k 5 "$TIMEOUT" "${wrap[@]}" "$hb/$demo" --frames "$frames" >"$stem.stdout" 2>"$stem.stderr" </dev/null)
    rc=$?
    printf 'rc=%s\nkeys=%s\ninstructions=%s\n' "$rc" "$keys" \
      "$(sed -n 's/.*Collected : \([0-9]*\).*/\1/p' "$stem.stderr" | tail -1)" >"$stem.meta"
    printf '  %-22s %-8s rc=%-3s %s\n' "$demo" "$solver" "$rc" "$(tail -1 "$stem.stdout" | cut -c1-110)" >&2
  done
done <<<"$demo_table"

python3 "$here/report.py" "$runs" "$runs/results.csv" $SOLVERS
