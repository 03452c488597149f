#!/usr/bin/env bash
# `mlcp diff`, `mlcp run --trajectory` and `mlcp stability --quick` as a user runs them: diff's
# exit codes (0 equal, 1 past the tolerance, 2 bad input) in scene and file mode, errors that
# name file and line, and a stability CSV with the chart script's columns and only valid
# outcomes. Prints "N passed, N failed".
set -u
mlcp=$1 scenes=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
source "$(dirname "${BASH_SOURCE[0]}")/../cli/check.sh"
ok() { passed=$((passed + 1)); }
bad() { failed=$((failed + 1)); echo "FAIL $1"; }
stack=$scenes/stack_10.json
engines=$("$mlcp" run --help | grep -oE 'engine: [a-z, ]+' | head -1)
for engine in bullet ode; do
  case $engines in *$engine*) ;; *) continue ;; esac
  # Scene mode: one solver twice is the same trajectory; 2 PGS sweeps against a pivoting
  # solver is not, at 1e-6 m.
  check "same-$engine" 0 'within tolerance' -- \
    "$mlcp" diff "$stack" --engine "$engine" --solvers pgs,pgs --steps 40 --tol 1e-12 --csv "$tmp/same.csv"
  check "different-$engine" 1 'first step past tolerance +[0-9]+ \(box\.[0-9]' -- \
    "$mlcp" diff "$stack" --engine "$engine" --solvers pgs,dantzig --iterations 2,50 --steps 40 --tol 1e-6
  check "loose-$engine" 0 'within tolerance' -- \
    "$mlcp" diff "$stack" --engine "$engine" --solvers pgs,dantzig --iterations 2,50 --steps 40 --tol 10 --angle-tol 4
  if [ "$(head -1 "$tmp/same.csv")" = "step,body,position_deviation,orientation_deviation" ] &&
     [ "$(wc -l < "$tmp/same.csv")" -eq 401 ] &&
     awk -F, 'NR > 1 && ($3 != 0 || $4 != 0) { bad = 1 } END { exit bad }' "$tmp/same.csv"; then ok
  else bad "diff-csv-$engine: $(head -3 "$tmp/same.csv")"; fi
  check "unknown-solver-$engine" 2 "unknown solver 'nosuch'" -- \
    "$mlcp" diff "$stack" --engine "$engine" --solvers pgs,nosuch --steps 2
done
check one-solver 2 'two solvers' -- "$mlcp" diff "$stack" --engine ode --solvers pgs --steps 2
check no-engine 2 'needs --engine' -- "$mlcp" diff "$stack" --solvers pgs,dantzig --steps 2
check bad-scene 2 'nope.json' -- "$mlcp" diff "$tmp/nope.json" --engine ode --solvers pgs,pgs

# File mode: trajectories of mlcp run.
engine=$(grep -oE 'bullet|ode' <<< "$engines" | head -1)
check traj-a 0 "wrote $tmp/a.csv" -- "$mlcp" run "$stack" --engine "$engine" --solver pgs --iterations 2 --steps 30 --trajectory "$tmp/a.csv"
check traj-b 0 "wrote $tmp/b.csv" -- "$mlcp" run "$stack" --engine "$engine" --solver dantzig --steps 30 --trajectory "$tmp/b.csv"
if [ "$(head -1 "$tmp/a.csv")" = "scene,engine,solver,step,body,x,y,z,qw,qx,qy,qz" ] &&
   [ "$(wc -l < "$tmp/a.csv")" -eq 301 ] &&
   awk -F, -v e="$engine" 'NR > 1 { if ($1 != "stack_10" || $2 != e || $3 != "pgs" || $4 != int((NR - 2) / 10) || $5 != "box." (NR - 2) % 10 || NF != 12) bad = 1
                                     q = $9 * $9 + $10 * $10 + $11 * $11 + $12 * $12; if (q < 0.999999 || q > 1.000001) bad = 1 }
                           END { exit bad }' "$tmp/a.csv"; then ok
else bad "trajectory-csv: $(sed -n 1,3p "$tmp/a.csv")"; fi
check files-equal 0 'within tolerance' -- "$mlcp" diff "$tmp/a.csv" "$tmp/a.csv" --tol 0
check files-different 1 'first step past tolerance' -- "$mlcp" diff "$tmp/a.csv" "$tmp/b.csv" --tol 1e-6
head -101 "$tmp/b.csv" > "$tmp/short.csv"
check files-short 2 'short.csv: ends after step 9, .*a.csv goes on to step 29' -- "$mlcp" diff "$tmp/a.csv" "$tmp/short.csv"
sed 's/,box\.1,/,box.x,/' "$tmp/b.csv" > "$tmp/renamed.csv"
check files-renamed 2 "renamed.csv: line 3: the bodies differ from .*a.csv's: body 2 is 'box.x' here, 'box.1' there" -- \
  "$mlcp" diff "$tmp/a.csv" "$tmp/renamed.csv"
sed '3s/,box\.1,/,box.x,/' "$tmp/b.csv" > "$tmp/inconsistent.csv"
check file-inconsistent 2 "inconsistent.csv: line 13: body 'box.1' where the first step has 'box.x'" -- \
  "$mlcp" diff "$tmp/inconsistent.csv" "$tmp/a.csv"
sed '5s/,0\.[0-9]*,/,oops,/' "$tmp/b.csv" > "$tmp/garbled.csv"
check files-garbled 2 'garbled.csv: line 5: column [0-9]+: not a number' -- "$mlcp" diff "$tmp/a.csv" "$tmp/garbled.csv"
"$mlcp" run "$stack" --engine "$engine" --steps 2 --csv "$tmp/steps.csv" > /dev/null
check files-not-trajectory 2 'steps.csv: line 1: expected the trajectory header' -- "$mlcp" diff "$tmp/a.csv" "$tmp/steps.csv"
check files-and-solvers 2 'take no --engine' -- "$mlcp" diff "$tmp/a.csv" "$tmp/b.csv" --solvers pgs,pgs

# Stability: --quick grid, the chart script's columns, valid outcomes, a row per cell.
check stability-quick 0 'stack_time_step [a-z]+/pgs  iterations 20: [SDCEF]{2} \| 3: [SDCEF]{2}  \(time_step' -- \
  "$mlcp" stability --quick --solvers pgs,dantzig,bullet-si,ode-quick --csv "$tmp/stab.csv"
n_engines=$(grep -oE 'bullet|ode' <<< "$engines" | wc -l)
want_rows=$((n_engines * 3 * 8))
if head -1 "$tmp/stab.csv" | grep -q '^engine,solver,x_name,x_value,y_name,y_value,outcome,scene,' &&
   [ "$(($(wc -l < "$tmp/stab.csv") - 1))" -eq "$want_rows" ] &&
   awk -F, 'NR > 1 { if ($7 !~ /^(stable|drifting|collapsed|exploded|solver-failure)$/) bad = 1
                     if (!(($3 == "mass_ratio" && $5 == "height" && $8 == "stack_mass_ratio") ||
                           ($3 == "time_step" && $5 == "iterations" && $8 == "stack_time_step"))) bad = 1
                     if ($4 !~ /^[0-9.e+-]+$/ || $6 !~ /^[0-9.e+-]+$/) bad = 1
                     if ($1 == "ode" && $2 ~ /^bullet-/ || $1 == "bullet" && $2 ~ /^ode-/) bad = 1 }
                   END { exit bad }' "$tmp/stab.csv"; then ok
else bad "stability-csv (want $want_rows rows): $(head -3 "$tmp/stab.csv")"; fi
# The 1000:1 stack of 16 holds with the exact methods in every engine built (top box within 2 cm
# over 4 s): with the scenes' cfm 1e-5 it sank 10 cm, the contact spring's deflection under 2.7 t.
check stability-mass-ratio-1000-height-16 0 'stability: [0-9]+ cells: stable [0-9]+;' -- \
  "$mlcp" stability --grids mass --ratios 1000 --heights 16 --seconds 4 --solvers auto,dantzig \
  --csv "$tmp/heavy.csv"
if [ "$(grep -c ',stable,' "$tmp/heavy.csv")" -eq $((n_engines * 2)) ]; then ok
else bad "stability-mass-ratio-1000-height-16: $(cut -d, -f1,2,7,12 "$tmp/heavy.csv" | tr '\n' ' ')"; fi
check stability-bad-cfm 2 'cfm' -- "$mlcp" stability --cfm -1
check stability-bad-grid 2 'must name mass, step' -- "$mlcp" stability --grids none
check stability-bad-solver 2 "unknown solver 'nosuch'" -- "$mlcp" stability --quick --solvers nosuch
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
