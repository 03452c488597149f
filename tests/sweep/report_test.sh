#!/usr/bin/env bash
# report_test.sh MLCP REPO OUT: the main job's report pipeline (tools/report.sh) in its quick mode
# (MLCP_REPORT_QUICK=1: 2 scenes, 5 steps) writes every file of the report folder. Skips (exit
# 77) when the chart venv is missing; tools/setup.sh builds it.
set -euo pipefail
mlcp=$1 repo=$2 out=$3
if [ ! -x "$repo/.venv/bin/python" ]; then
  echo "SKIP: $repo/.venv/bin/python is missing; run tools/setup.sh to build the chart venv"
  exit 77
fi
fail() { echo "FAIL: $*"; exit 1; }
rm -rf "$out"
MLCP="$mlcp" MLCP_REPORT_QUICK=1 "$repo/tools/report.sh" "$out" > "$out.log" 2>&1 ||
  { cat "$out.log"; fail "tools/report.sh exited non-zero"; }
grep -q "report: $out/index.html" "$out.log" || fail "the report's place is not printed"
for f in sweep.csv summary.md index.html charts/stack_10.png charts/stack_10.svg \
         charts/pendulum_chain.png charts/pendulum_chain.svg; do
  [ -s "$out/$f" ] || fail "$out/$f is missing or empty"
done
# The sweep: 2 scenes, 5 steps each run; both scenes have a summary table and a chart on the page.
[ "$(awk -F, 'NR > 1 && $7 == 4' "$out/sweep.csv" | wc -l)" -gt 0 ] || fail "no step 4 rows in sweep.csv"
for s in stack_10 pendulum_chain; do
  grep -q "^## $s" "$out/summary.md" || fail "summary.md has no table for $s"
  grep -q "src='charts/$s.png'" "$out/index.html" || fail "index.html does not show charts/$s.png"
done
grep -q "^| engine | solver | iterations |" "$out/summary.md" || fail "summary.md lacks the table header"
# The Pareto table: a row per scene x engine with auto's time and a yes/no verdict.
grep -q "^| scene | engine | auto ms/step | auto residual | most accurate other |" \
  "$out/summary.md" || fail "summary.md lacks the Pareto table"
for s in stack_10 pendulum_chain; do
  for e in bullet ode; do
    grep -qE "^\| $s \| $e \| [0-9][^|]* \| [0-9][^|]* \|.* \| (yes|yes, as .*|no, dominated by .*) \|\$" \
      "$out/summary.md" || fail "the Pareto table has no row with auto's numbers for $s / $e"
  done
done
grep -q "id='pareto'" "$out/index.html" || fail "index.html lacks the Pareto table"
grep -q "^| problem | n | pgs | lemke | dantzig | auto |" "$out/table.md" || fail "table.md lacks the solver table"
grep -q "^| lcp_mmc.dat |" "$out/table.md" || fail "table.md lacks the Siconos rows"
grep -q "id='siconos'" "$out/index.html" || fail "index.html lacks the Siconos table"
if grep -qE '^ +stability' <<< "$("$mlcp" --help)"; then
  [ -s "$out/stability.csv" ] || fail "stability.csv is missing"
  ls "$out"/stability/*.png > /dev/null 2>&1 || fail "no stability heat map"
  grep -q "src='stability/" "$out/index.html" || fail "index.html does not show the stability map"
fi
# The verdict on synthetic sweeps: auto dominated only by its sole choice at the same residual is
# "yes, as" it; dominated by another solver, by its choice when it also chose another, or by its
# choice beyond the margin (5%), "no".
verdicts=$(cd "$repo/tools" && "$repo/.venv/bin/python" - "$out/v.csv" <<'PY'
import sys
from chart import SWEEP_COLUMNS, read_rows
from report import fronts, verdict
head = ("setting,value,setting_applies,scene,engine,solver,step,solver_ms,step_ms,residual,"
        "iterations,status,fallbacks,choice,contacts,max_penetration,joint_error,energy,"
        "momentum,max_speed")
def row(scene, solver, ms, choice, step=0):
    return (f"iterations,50,1,{scene},ode,{solver},{step},{ms},{ms},1e-16,1,converged,0,"
            f"{choice},0,0,0,0,0,0")
lines = [head,
         row("a", "dantzig", 1.00, "dantzig:1"), row("a", "auto", 1.02, "dantzig:1 none:2"),
         row("b", "ode-world", 1.00, ""), row("b", "auto", 1.02, "dantzig:1"),
         row("c", "dantzig", 1.00, "dantzig:1"), row("c", "auto", 1.02, "dantzig:1"),
         row("c", "auto", 1.02, "ldlt:1", step=1),
         row("d", "dantzig", 1.00, "dantzig:1"), row("d", "auto", 1.10, "dantzig:1")]
open(sys.argv[1], "w").write("\n".join(lines) + "\n")
for e in fronts(sys.argv[1], read_rows(sys.argv[1], SWEEP_COLUMNS)):
    print(e["scene"], verdict(e))
PY
)
grep -q "^a yes, as dantzig" <<< "$verdicts" || fail "auto behind its sole choice is not 'yes, as': $verdicts"
grep -q "^b no, dominated by ode-world" <<< "$verdicts" || fail "auto behind another solver is not 'no': $verdicts"
grep -q "^c no, dominated by dantzig" <<< "$verdicts" || fail "auto with two choices is 'yes, as': $verdicts"
grep -q "^d no, dominated by dantzig" <<< "$verdicts" || fail "auto 10% behind its choice is 'yes, as': $verdicts"
echo "report_test: ok"
