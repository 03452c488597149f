#!/usr/bin/env bash
# The mlcp program as a user runs it: exit codes 0 (solved), 1 (not solved), 2 (invalid input),
# messages naming the file, JSON output. Prints "N passed, N failed".
set -u
mlcp=$1 data=$2 siconos=$3
source "$(dirname "${BASH_SOURCE[0]}")/check.sh"
check help 0 'pgs' -- "$mlcp" --help
check solve-help 0 'lemke|pgs' -- "$mlcp" solve --help
check spd 0 'converged' -- "$mlcp" solve "$data/spd.json" --solver pgs --tol 1e-9
check boxed 0 'converged' -- "$mlcp" solve "$data/boxed.json" --solver pgs --tol 1e-9
check findex 0 'converged' -- "$mlcp" solve "$data/findex.json" --solver pgs --tol 1e-9
check time-budget 0 'converged' -- "$mlcp" solve "$data/spd.json" --solver auto --time-budget 0.5
check time-budget-bad 2 'not in range' -- "$mlcp" solve "$data/spd.json" --solver pgs --time-budget -1
check siconos 0 'converged' -- "$mlcp" solve "$siconos/lcp/lcp_mmc.dat" --solver pgs --tol 1e-9
check seed-pgs-refuses 1 'positive diagonal' -- "$mlcp" solve "$data/seed_lemke.json" --solver pgs
check too-few-iterations 1 'max-iterations' -- "$mlcp" solve "$siconos/lcp/lcp_mmc.dat" --solver pgs --max-iter 3
check gs-bounded 1 'unsupported' -- "$mlcp" solve "$data/spd.json" --solver gs
check json 0 '"status": "converged"' -- "$mlcp" solve "$data/boxed.json" --solver pgs --json
json=$("$mlcp" solve "$data/findex.json" --solver pgs --json)
if python3 -c 'import json,sys; d=json.loads(sys.argv[1]); assert set(["solver","status","x","w","iterations","residual","seconds"]) <= set(d); assert len(d["x"]) == 3 and d["residual"] <= 1e-10' "$json"; then
  passed=$((passed + 1))
else
  failed=$((failed + 1)); echo "FAIL json-fields: $json"
fi
check json-not-solved 1 '"status": "failed"' -- "$mlcp" solve "$data/seed_lemke.json" --solver pgs --json
check guess 0 'converged' -- "$mlcp" solve "$data/spd.json" --solver pgs --guess "$data/spd_guess.json"
check missing-file 2 'nope.json: cannot open' -- "$mlcp" solve "$data/nope.json"
check truncated 2 'truncated.json: not valid JSON' -- "$mlcp" solve "$data/bad/truncated.json"
check lo-above-hi 2 'lo_above_hi.json: row 1: lo = 3 > hi = 2' -- "$mlcp" solve "$data/bad/lo_above_hi.json"
check findex-range 2 'findex\[1\] = 9 is out of range' -- "$mlcp" solve "$data/bad/findex_range.json"
check short-dat 2 'short.dat: file ends before' -- "$mlcp" solve "$data/bad/short.dat"
check unknown-solver 2 "unknown solver 'nosuch'" -- "$mlcp" solve "$data/spd.json" --solver nosuch
check bad-guess 2 'guess has 1 entries' -- "$mlcp" solve "$data/spd.json" --guess "$data/one.json"
check trace 0 'pivot 3: z1 enters, z0 leaves' -- "$mlcp" trace lemke "$data/seed_lemke.json"
check trace-final-table 0 'w3 +\| +32/19 +7/19 +1 +0 +0 +-110/19 +-58/19 +\| 12/19' -- "$mlcp" trace lemke "$data/seed_lemke.json"
check trace-boxed 2 'boxed.json' -- "$mlcp" trace lemke "$data/boxed.json"
check trace-method 2 "only 'lemke'" -- "$mlcp" trace simplex "$data/seed_lemke.json"
check seed-lemke 0 'converged' -- "$mlcp" solve "$data/seed_lemke.json" --solver lemke --tol 1e-12
check seed-auto 0 'converged' -- "$mlcp" solve "$data/seed_lemke.json" --solver auto
check chain 0 'converged' -- "$mlcp" solve "$data/seed_lemke.json" --solver 'pgs>lemke'
check table-markdown 0 '\| lcp_deudeu.dat \| 2 \|' -- "$mlcp" table --markdown "$siconos/lcp/lcp_deudeu.dat" --solvers pgs,lemke
check table 0 'lcp_deudeu.dat' -- "$mlcp" table "$siconos/lcp/lcp_deudeu.dat" --solvers pgs
# Bad input of any kind: exit 2 and one short line naming the file and what is wrong.
one_line() {  # one_line NAME WANT_CODE PATTERN -- command...
  local name=$1
  check "$@"
  shift 4
  local out
  out=$("$@" 2>&1)
  if [ "$(wc -l <<< "$out")" -eq 1 ] && [ "${#out}" -le 300 ]; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1)); echo "FAIL $name-one-line: ${#out} characters: ${out:0:300}"
  fi
}
one_line dev-zero 2 '/dev/zero: not a regular file' -- "$mlcp" solve /dev/zero
one_line directory 2 'not a regular file' -- "$mlcp" solve "$data"
one_line tol-denormal 2 "--tol: expected a number in \[1e-300, 1e300\], got '5e-324'" -- \
  "$mlcp" solve "$data/spd.json" --tol 5e-324
one_line tol-negative 2 "expected a number in \[1e-300, 1e300\]" -- "$mlcp" solve "$data/spd.json" --tol -1
one_line max-iter-negative 2 "--max-iter: expected a number in \[0, 1e300\]" -- \
  "$mlcp" solve "$data/spd.json" --max-iter -3
one_line fuzz-overflow 2 'problem_number_overflow_1e309.json: not valid JSON: number overflow' -- \
  "$mlcp" solve "$data/fuzz/problem_number_overflow_1e309.json"
one_line fuzz-nested 2 'problem_nested_5000.json: JSON nested deeper than 64 levels' -- \
  "$mlcp" solve "$data/fuzz/problem_nested_5000.json"
one_line fuzz-entry 2 'A\[0\]\[0\] = 1e\+300 is outside' -- "$mlcp" solve "$data/fuzz/problem_entry_1e300.json"
one_line fuzz-sparse-n 2 'problem_sparse_n_1e8.json' -- "$mlcp" solve "$data/fuzz/problem_sparse_n_1e8.json"
one_line fuzz-siconos-n 2 'n = 10000000 is out of range' -- "$mlcp" solve "$data/fuzz/problem_siconos_n_1e7.dat"
one_line fuzz-siconos-blocks 2 'out of range' -- "$mlcp" solve "$data/fuzz/problem_siconos_blocks_1e9.dat"
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
