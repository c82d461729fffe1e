#!/bin/bash
# Runs `vrl_report --quick` (the report's small version) so the report never
# rots: it must finish, and write the CSVs, plots, false-colour images and a
# summary whose tables hold every method.
set -euo pipefail
report=$1
out=$2
rm -rf "$out"
start=$(date +%s)
"$report" --quick -o "$out"
elapsed=$(( $(date +%s) - start ))
echo "quick report: ${elapsed} s"
fail() { echo "FAIL: $*" >&2; exit 1; }
[ "$elapsed" -lt 180 ] || fail "--quick took ${elapsed} s (must stay under 3 minutes)"
for f in results.csv speedup.csv summary.md error-time-bathroom.png speedup.png \
         images/bathroom-reference.png images/bathroom-vrl-lightcuts-eval.png images/bathroom-vpl-lightcuts-inter.png; do
    [ -s "$out/$f" ] || fail "missing or empty $out/$f"
done
head -1 "$out/results.csv" | grep -q '^scene,method,setting,vrls,spp,error_threshold,seconds,rmse,rel_rmse,smape' \
    || fail "results.csv header"
for m in path vrl vrl-lightcuts vpl-lightcuts; do
    grep -q "^bathroom,$m," "$out/results.csv" || fail "no $m row in results.csv"
done
# Every row has 14 fields and finite, non-negative errors.
awk -F, 'NR > 1 { if (NF != 14) { print "bad field count: " $0; exit 1 }
                  for (i = 7; i <= 10; ++i) if ($i !~ /^[0-9.e+-]+$/ || $i < 0) { print "bad number: " $0; exit 1 } }' \
    "$out/results.csv" || fail "results.csv rows"
[ "$(grep -c '^bathroom,' "$out/speedup.csv")" -ge 4 ] || fail "speedup.csv rows"
for heading in "## bathroom" "## Table 1" "## Figure 4" "Equal-time error ratios"; do
    grep -q "$heading" "$out/summary.md" || fail "summary.md lacks '$heading'"
done
# Table 1 has numbers for both Lightcuts.
grep -E '^\| bathroom \| 10000 \| [0-9]' "$out/summary.md" >/dev/null || fail "Table 1 row"
# A second run takes the reference from the cache.
second=$("$report" --quick --no-plots -o "$out" 2>&1) || fail "the second run failed: $second"
grep -q "reference from the cache" <<<"$second" || fail "the reference was not cached"
echo "PASS"
