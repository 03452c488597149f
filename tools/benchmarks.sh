#!/usr/bin/env bash
# Runs the benchmark programs and rewrites the tables of docs/benchmarks.md from their output.
#   tools/benchmarks.sh [--full] [BUILD_DIR]      (default build/; ~10 minutes on 2 loaded cores)
# --full adds the long Bullet runs (a demo's first 300 steps, its steady state, 210 boxes:
# about 10 more minutes, mostly the stock btMLCPSolver's Dantzig). Each table in the file is
# replaced only when its benchmark ran, and carries the commit and date of its own run. The raw
# outputs stay in BUILD_DIR/benchmarks/. The Siconos table reads the corpus in tests/data/siconos.
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
full=0
if [[ ${1:-} == --full ]]; then
  full=1
  shift
fi
build=${1:-$repo/build}
mkdir -p "$build/benchmarks"
build=$(cd "$build" && pwd)
out=$build/benchmarks
rm -f "$out"/*.txt "$out"/*.cmd
# The code measured: HEAD, and whether files other than these documents differ from it.
{
  git -C "$repo" rev-parse --short HEAD
  git -C "$repo" status --porcelain --untracked-files=no -- . ':!docs' ':!README.md' \
    ':!tools/benchmarks.sh' ':!tools/benchmarks.py' | grep -q . && echo "+ uncommitted changes"
  date -u '+%Y-%m-%d %H:%M UTC'
} > "$out/run" || true
siconos=$repo/tests/data/siconos

cmake --build "$build" --target mlcp core_bench bullet_bench ode_bench ode_pgs_bench > /dev/null

# run NAME COMMAND...: the command's stdout to $out/NAME.txt, the command line to NAME.cmd.
run() {
  local name=$1
  shift
  echo "benchmarks: $name" >&2
  local line="" a
  for a in "$@"; do
    [[ $a == *[[:space:]]* ]] && a="\"$a\""
    line+="${line:+ }$a"
  done
  printf '%s\n' "$line" > "$out/$name.cmd"
  (cd "$repo" && "$@") > "$out/$name.txt"
}
bench=$build/bench
bin=$build/bin
dz="ours dantzig,ours newton,MLCP-Dantzig"
run core "$bench/core_bench" --benchmark_min_time=0.2 --benchmark_format=json
run bullet-switch-15 "$bin/bullet_bench" --sizes 15 --steps 10
run bullet-switch-55 "$bin/bullet_bench" --sizes 55 --steps 10 --only "SI,ours pgs,MLCP-PGS,$dz"
run bullet-rest-55 "$bin/bullet_bench" --sizes 55 --steps 10 --settle 60 --only "$dz"
if ((full)); then
  run bullet-demo-55 "$bin/bullet_bench" --sizes 55 --warmup 0 --steps 300 --only "$dz"
  run bullet-steady-55 "$bin/bullet_bench" --sizes 55 --warmup 0 --settle 300 --steps 10 \
    --only "$dz"
  run bullet-switch-210 "$bin/bullet_bench" --sizes 210 --steps 10 --only "SI,ours pgs,$dz"
fi
run pgs-vs-si "$bin/bullet_bench" --pgs-vs-si --steps 300 --sweeps 10,20,50
run pgs-vs-si-baseline env MLCP_CPU_PATH=baseline "$bin/bullet_bench" --pgs-vs-si --steps 300 \
  --sweeps 10
run ode-dantzig "$bench/ode_bench" 10 5
run ode-pgs "$bench/ode_pgs_bench" 100 40 20
run siconos "$bin/mlcp" table --markdown "$siconos"/lcp/*.dat --solvers pgs,lemke,dantzig,auto

cut -d' ' -f1 /proc/loadavg > "$out/load"
python3 "$repo/tools/benchmarks.py" "$out" "$repo/docs/benchmarks.md"
echo "benchmarks: docs/benchmarks.md rewritten from $out" >&2
