#!/usr/bin/env bash
# Smoke test of the Siconos peer benchmark (siconos_bench) on one small captured island (a
# 10-cube stack in ODE, 120 rows): every form and solver runs, and the answers that must be exact
# are, by our own residual. Exit 77 (skipped) when the build has no siconos_bench.
# Usage: siconos_bench_test.sh SICONOS_BENCH_BINARY ISLANDS_DIR WORK_DIR
set -uo pipefail
bench=$1
islands=$2
work=$3
if [ -z "$bench" ]; then
  echo "skipped: Siconos numerics is not installed (libsiconos-numerics-dev), no siconos_bench"
  exit 77
fi
mkdir -p "$work"
csv=$work/stack_10.csv
"$bench" --time-limit 10 --csv "$csv" "$islands/stack_10-ode-step5-island0.json" > "$work/out.txt"
rc=$?
[ $rc -eq 0 ] || { cat "$work/out.txt"; echo "FAIL: siconos_bench exited $rc"; exit 1; }
python3 - "$csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
got = {(r["form"], r["solver"]): r for r in rows}
fails = []
def expect(form, solver, status=None):
    r = got.get((form, solver))
    if r is None:
        fails.append(f"no row for {form} {solver}")
    elif status and r["status"] != status:
        fails.append(f"{form} {solver}: status {r['status']} (residual {r['residual']}), want {status}")
    return r
for solver in ("pgs", "dantzig", "newton", "lemke", "auto"):
    for form in ("findex", "lcp", "boxed"):
        expect(form, solver)
for solver in ("lcp_newton_FB", "lcp_newton_min", "lcp_newton_minFB", "lcp_pgs"):
    expect("lcp", solver)
expect("boxed", "relay_pgs")
expect("boxed", "relay_avi_caoferris")
# Pivoting answers are exact: a wrong sign or transposition of the hand-over shows here.
expect("lcp", "lcp_lexicolemke", "converged")
expect("boxed", "relay_lexicolemke", "converged")
expect("findex", "dantzig", "converged")
expect("boxed", "dantzig", "converged")
# The box's bounds come from a converged reference, so its exact answer solves the findex problem.
r = got.get(("boxed", "relay_lexicolemke"))
if r and not (r["findex_residual"] and float(r["findex_residual"]) <= 1e-6):
    fails.append(f"boxed relay_lexicolemke: findex residual {r['findex_residual']}, want <= 1e-6")
lcp_rows = {r["rows"] for r in rows if r["form"] == "lcp"}
if lcp_rows != {"40"}:
    fails.append(f"lcp form rows {lcp_rows}, want 40 (the stack's contact rows)")
for f in fails:
    print("FAIL:", f)
print(f"{len(rows)} rows checked" if not fails else "")
sys.exit(1 if fails else 0)
PY
