#!/usr/bin/env bash
# scaling_chart_test.sh REPO OUTDIR: tools/scaling_chart.py draws the sample CSVs of
# tools/scaling_report.sh into a PNG and writes its section into a document twice: the second run
# replaces the section in place and keeps the text around it. Skips (exit 77) without the venv.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/chart_test_setup.sh" "$1" "$2"
doc=$out/doc.md
printf '# Title\n\nbefore\n' > "$doc"
for run in 1 2; do
  "$py" "$repo/tools/scaling_chart.py" --dir "$repo/tests/data/charts/scaling" \
    --png "$out/scaling.png" --doc "$doc" > /dev/null || fail "run $run exited $?"
  [ $run -eq 1 ] && printf '\nafter\n' >> "$doc"
done
[ "$(head -c 8 "$out/scaling.png" | od -An -tx1 | tr -d ' \n')" = "89504e470d0a1a0a" ] ||
  fail "no PNG"
[ "$(grep -c 'scaling_report.sh: begin' "$doc")" -eq 1 ] || fail "the section is not there once"
grep -q '^before$' "$doc" && grep -q '^after$' "$doc" || fail "the text around the section is lost"
# 13 engine runs, and the three island tables with 2 islands each.
[ "$(grep -c '^| pyramid_15 |' "$doc")" -eq 13 ] || fail "engine table rows"
[ "$(grep -c '^| stack_10-ode-step5 |' "$doc")" -eq 3 ] || fail "island table rows"
grep -q 'lcp_lexicolemke' "$doc" || fail "no Siconos column"
echo "scaling chart and section written"
