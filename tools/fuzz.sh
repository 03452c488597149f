#!/usr/bin/env bash
# Fuzzes the readers and the solvers with libFuzzer (clang, ASan + UBSan):
#   tools/fuzz.sh DURATION [TARGET...]
# DURATION: seconds per target (tools/test.sh runs 20 s each; a longer run: tools/fuzz.sh 3600).
# Targets (default all): problem_reader_fuzz (mlcp-problem/1 JSON and Siconos .dat),
# scene_parser_fuzz (mlcp-scene/1), solver_fuzz (every solver on small decoded problems).
# Builds build-fuzz/ (MLCP_FUZZ=ON: the core and scene libraries and the targets only), seeds
# each corpus in build-fuzz/corpus/TARGET from tests/data and scenes/ (kept between runs, so
# long runs build on earlier ones), and writes any crashing input to build-fuzz/crashes/TARGET/.
# Prints each target's executions; exit 1 when a target found a crash.
# Env: MLCP_FUZZ_BUILD, the build tree (default build-fuzz).
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
duration=${1:?usage: tools/fuzz.sh DURATION [TARGET...]}
shift
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(problem_reader_fuzz scene_parser_fuzz solver_fuzz)
build=${MLCP_FUZZ_BUILD:-$repo/build-fuzz}
jobs=$(nproc 2>/dev/null || echo 2)

CC=clang CXX=clang++ cmake -S "$repo" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DMLCP_FUZZ=ON > /dev/null
cmake --build "$build" -j "$jobs" --target "${targets[@]}"

seed() {  # seed TARGET: the files its corpus starts from
  case $1 in
    problem_reader_fuzz) ls "$repo"/tests/data/*.json "$repo"/tests/data/bad/* "$repo"/tests/data/fuzz/problem_* \
      "$repo"/tests/data/siconos/lcp/*.dat 2>/dev/null || true ;;
    scene_parser_fuzz) ls "$repo"/scenes/*.json "$repo"/tests/data/fuzz/scene_* 2>/dev/null || true ;;
    solver_fuzz) ls "$repo"/tests/data/*.json "$repo"/tests/data/fuzz/solver_* 2>/dev/null || true ;;
  esac
}

found=0
for t in "${targets[@]}"; do
  corpus=$build/corpus/$t crashes=$build/crashes/$t
  mkdir -p "$corpus" "$crashes"
  seed "$t" | while read -r f; do if [ -f "$f" ]; then cp -n "$f" "$corpus/"; fi; done
  log=$build/$t.log
  set +e
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
    "$build/fuzz/$t" "$corpus" -max_total_time="$duration" -timeout=10 -rss_limit_mb=2048 \
    -max_len=65536 -print_final_stats=1 -artifact_prefix="$crashes/" > "$log" 2>&1
  rc=$?
  set -e
  runs=$(grep -oE 'stat::number_of_executed_units: *[0-9]+' "$log" | grep -oE '[0-9]+$' |
         awk '{s += $1} END {print s + 0}')
  if [ $rc -ne 0 ]; then
    found=1
    echo "fuzz: $t: FOUND A CRASH after $runs executions (log $log, input in $crashes/):"
    grep -E "ERROR|fuzz check failed|SUMMARY|Test unit written" "$log" | head -8 | sed 's/^/  /'
  else
    echo "fuzz: $t: $runs executions in ${duration} s, no crash (corpus $(ls "$corpus" | wc -l) files)"
  fi
done
exit $found
