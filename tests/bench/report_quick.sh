#!/bin/bash
# Runs `vrl_report --quick` (the report's small version) so the report never
# rots: it must finish, and write the CSVs, plots, false-colour images and a
# summary whose tables hold every method.
set -euo pipefail
report=$1
out=$2
rm -rf "$out"
start=$(date +%s)
# References are built in chunks and resumable: a run stopped at its time limit keeps
# its chunks (.partial.exr), and the next one goes on from there.
stopped=$("$report" --quick --references --reference-minutes 0.001 -o "$out" 2>&1) || { echo "$stopped"; exit 1; }
grep -q "stopped at the time limit after 1 of 8 chunks" <<<"$stopped" || { echo "$stopped"; echo "FAIL: no stop" >&2; exit 1; }
ls "$out"/cache/bathroom-reference-*.partial.exr >/dev/null 2>&1 || { echo "FAIL: no partial reference" >&2; exit 1; }
log=$("$report" --quick -o "$out" 2>&1) || { echo "$log"; exit 1; }
echo "$log"
grep -q "reference: resuming after 1 of 8 chunks" <<<"$log" || { echo "FAIL: the reference did not resume" >&2; exit 1; }
! ls "$out"/cache/*.partial.exr >/dev/null 2>&1 || { echo "FAIL: a partial reference was left" >&2; exit 1; }
elapsed=$(( $(date +%s) - start ))
echo "quick report: ${elapsed} s"
fail() { echo "FAIL: $*" >&2; exit 1; }
[ "$elapsed" -lt 180 ] || fail "--quick took ${elapsed} s (must stay under 3 minutes)"
for f in results.csv speedup.csv summary.md error-time-bathroom.png error-time-bathroom-d.png speedup.png \
         images/bathroom-reference.png images/bathroom-vrl-lightcuts-eval.png images/bathroom-vpl-lightcuts-inter.png; do
    [ -s "$out/$f" ] || fail "missing or empty $out/$f"
done
head -1 "$out/results.csv" | grep -q '^scene,method,setting,vrls,spp,error_threshold,seconds,rmse,rel_rmse,smape' \
    || fail "results.csv header"
for m in path vrl vrl-lightcuts vrl-stochastic vpl-lightcuts; do
    grep -q "^bathroom,$m," "$out/results.csv" || fail "no $m row in results.csv"
done
# Every row has 22 fields and finite, non-negative errors.
awk -F, 'NR > 1 { if (NF != 22) { print "bad field count: " $0; exit 1 }
                  for (i = 7; i <= 10; ++i) if ($i !~ /^[0-9.e+-]+$/ || $i < 0) { print "bad number: " $0; exit 1 }
                  for (i = 19; i <= 21; ++i) if ($i !~ /^[0-9.e+-]+$/ || $i < 0) { print "bad renders or range: " $0; exit 1 } }' \
    "$out/results.csv" || fail "results.csv rows"
head -1 "$out/results.csv" | grep -q ',cut_size,ref_noise_rmse,below_noise,part,renders,rmse_min,rmse_max,distance_samples$' \
    || fail "results.csv noise, renders and distance samples columns"
# VPL Lightcuts' distance samples per camera segment: 32 unless the label asks for
# fewer ("D=8": the quick sweep's cheaper part (d) point); 0 for the other methods.
awk -F, 'NR > 1 { want = ($2 != "vpl-lightcuts") ? 0 : ($3 ~ / D=8$/) ? 8 : 32
                  if ($22 != want) { print "distance samples: " $0; exit 1 }
                  if ($3 ~ / D=8$/) found = 1 }
         END { if (!found) { print "no D=8 row"; exit 1 } }' "$out/results.csv" || fail "distance_samples column"
# A point of several renders (the quick sweep's path tracer at 4 spp has 2): its RMSE is
# their root-mean-square, so it lies between their least and greatest, which differ
# (each render has its own seed); a point of one render has all three equal.
awk -F, 'NR > 1 && $2 == "path" && $3 == "4 spp" && $18 == "image" {
             found = 1
             if ($19 != 2 || !($20 < $21) || $8 < $20 || $8 > $21) { print "bad repeated point: " $0; exit 1 } }
         NR > 1 && $19 == 1 && ($20 != $8 || $21 != $8) { print "one render, three RMSEs: " $0; exit 1 }
         END { if (!found) { print "no path 4 spp row"; exit 1 } }' "$out/results.csv" \
    || fail "a point's renders"
grep -q 'path .*4 spp .*(2 renders, RMSE ' <<<"$log" || fail "the log does not show the point's renders"
# Stochastic runs at two cut sizes.
[ "$(awk -F, '$2 == "vrl-stochastic" { print $15 }' "$out/results.csv" | sort -u | wc -l)" -eq 2 ] \
    || fail "vrl-stochastic should run at two cut sizes"
# Part (d) alone: every virtual-light method, against its own reference (whose noise differs).
for m in vrl vrl-lightcuts vrl-stochastic vpl-lightcuts; do
    grep -q "^bathroom,$m,.*,multiple," "$out/results.csv" || fail "no part (d) $m row in results.csv"
done
grep -q "^bathroom,path,.*,multiple," "$out/results.csv" && fail "the path tracer has no part (d) row"
[ "$(awk -F, 'NR > 1 && $1 == "bathroom" { print $18 ":" $16 }' "$out/results.csv" | sort -u | wc -l)" -eq 2 ] \
    || fail "the two parts should each have one reference noise"
grep -q "Part (d) alone" "$out/summary.md" || fail "summary.md lacks the part (d) comparison"
# bathroom: both parts; bathroom-hg07: part (d) alone.
[ "$(grep -c '^\*\*Verdict for' "$out/summary.md")" -eq 3 ] || fail "summary.md should give a verdict per scene and part"
# The part (d) reference (plain VRLs over independent sets) agrees with stochastic VRL
# Lightcuts over 16 independent sets: the RMSE of their difference within 1.5x of what
# their noises predict (fixed seeds; measured 1.04).
grep -q "they agree within their noise" "$out/summary.md" || fail "the part (d) reference check failed"
ls "$out"/cache/bathroom-reference-d-*.exr >/dev/null 2>&1 || fail "no cached part (d) reference"
ls "$out"/cache/bathroom-reference-d-*.txt >/dev/null 2>&1 || fail "no note beside the part (d) reference"
# The noise rule: below_noise is 1 exactly where RMSE < 3 x the reference's noise RMSE,
# and the reference's noise is measured (positive).
awk -F, 'NR > 1 { if (!($16 > 0)) { print "no reference noise: " $0; exit 1 }
                  expect = ($8 < 3 * $16) ? 1 : 0
                  if ($17 != expect) { print "noise rule: " $0; exit 1 } }' "$out/results.csv" \
    || fail "below_noise does not follow the noise rule"
grep -q "Noise rule" "$out/summary.md" || fail "summary.md does not state the noise rule"
# A point below the noise floor has no ratio: in the tables whose header matches $1,
# where column $2 holds the point's label, every cell after its time is ‡.
no_ratio_below_noise() {
    awk -F'|' -v header="$1" -v label="$2" '$0 ~ header { table = 1; next }
           table && !/^\|/ { table = 0 }
           table && $label ~ /‡/ { for (i = label + 2; i < NF; ++i) if ($i !~ /^ *‡ *$/) { print "ratio below noise: " $0; exit 1 } }' \
        "$out/summary.md"
}
no_ratio_below_noise '^\\| VRL Lightcuts point' 2 || fail "a ratio was given for a run below the noise floor"
# The same ratios read at the other methods' points: one table per scene and part.
[ "$(grep -c "^The same ratios at the other methods' points" "$out/summary.md")" -eq 3 ] \
    || fail "summary.md should compare at the other methods' points per scene and part"
no_ratio_below_noise '^\\| method \\| point \\|' 3 || fail "a ratio was given at another method's point below the noise floor"
[ "$(grep -c '^bathroom,' "$out/speedup.csv")" -ge 6 ] || fail "speedup.csv rows"
# Figure 4 also has the stochastic cut, timed at the deterministic cut's error.
[ "$(grep -c '^bathroom,VRL-stochastic,' "$out/speedup.csv")" -eq 2 ] || fail "no stochastic speed-up rows"
awk -F, 'NR > 1 && $2 == "VRL-stochastic" { if (!($5 > 0) || !($9 > 0)) { print "bad stochastic row: " $0; exit 1 } }' \
    "$out/speedup.csv" || fail "stochastic speed-up rows need a time and an error"
# A scene measured on part (d) alone (bathroom-hg07): (d) rows only, no whole-image
# reference built, its previews and Table 1 from the (d) runs.
grep -q '^bathroom-hg07,.*,image,' "$out/results.csv" && fail "bathroom-hg07 has whole-image rows"
for m in vrl vrl-lightcuts vrl-stochastic vpl-lightcuts; do
    grep -q "^bathroom-hg07,$m,.*,multiple," "$out/results.csv" || fail "no part (d) $m row for bathroom-hg07"
done
ls "$out/cache" | grep -qE '^bathroom-hg07-reference-[0-9a-f]{16}\.exr$' && fail "a whole-image reference for bathroom-hg07"
ls "$out/cache" | grep -qE '^bathroom-hg07-reference-d-[0-9a-f]{16}\.exr$' || fail "no part (d) reference for bathroom-hg07"
grep -q '^| bathroom-hg07 |.*| none (part (d) alone) |' "$out/summary.md" || fail "scenes table: bathroom-hg07"
grep -q 'error-time-bathroom-hg07.png' "$out/summary.md" && fail "summary.md shows a whole-image plot for bathroom-hg07"
for f in error-time-bathroom-hg07-d.png images/bathroom-hg07-reference.png images/bathroom-hg07-vrl-lightcuts-eval.png; do
    [ -s "$out/$f" ] || fail "missing or empty $out/$f"
done
grep -E '^\| bathroom-hg07 \| 10000 \| [0-9]' "$out/summary.md" >/dev/null || fail "Table 1 row for bathroom-hg07"
# "What to use when": a winner at some time budget, and where each winning method won.
sed -n '/^## What to use when/,/^## Table 1/p' "$out/summary.md" | grep -qE '^\| bathroom \| whole image \|.*\*\*' \
    || fail "summary.md: no winner in 'What to use when'"
grep -qE '^- \*\*.*\*\* has the lowest error in [0-9]+ of [0-9]+ cells' "$out/summary.md" \
    || fail "summary.md: 'What to use when' does not say where each method won"
for heading in "## bathroom" "## Table 1" "## Figure 4" "Equal-time error ratios"; do
    grep -q "$heading" "$out/summary.md" || fail "summary.md lacks '$heading'"
done
# Table 1 has numbers for both Lightcuts.
grep -E '^\| bathroom \| 10000 \| [0-9]' "$out/summary.md" >/dev/null || fail "Table 1 row"
# ... and part (c)'s counts (the last two cells), with its false-colour images.
grep -E '^\| bathroom \| 10000 \|.*\| [0-9.e+]+ \| [0-9.e+]+ \|$' "$out/summary.md" >/dev/null || fail "Table 1: part (c)"
[ -s "$out/images/bathroom-vrl-lightcuts-medium-surface-eval.png" ] || fail "no part (c) #Eval image"
# A second run takes the reference from the cache.
second=$("$report" --quick --no-plots -o "$out" 2>&1) || fail "the second run failed: $second"
grep -q "reference from the cache" <<<"$second" || fail "the reference was not cached"
grep -q "part (d) reference from the cache" <<<"$second" || fail "the part (d) reference was not cached"
# The part (d) reference's check is stored beside it and read back; a stored check of
# other settings is said so and computed again (here by --references, which computes it too).
check=$(ls "$out"/cache/bathroom-reference-d-*.check.txt) || fail "no check stored beside the part (d) reference"
grep -q "part (d) reference check from the cache ($(basename "$check"))" <<<"$second" || fail "the check was not read back"
grep -q "they agree within their noise" "$out/summary.md" || fail "the stored check does not agree"
grep -q "The check is stored beside the reference (computed by commit" "$out/summary.md" || fail "summary: stored check"
sed -i 's/^key: .*/key: another check/' "$check"
third=$("$report" --quick --references --scenes bathroom -o "$out" 2>&1) || fail "--references failed: $third"
grep -q "$(basename "$check") is of other settings (key 'another check'" <<<"$third" || { echo "$third"; fail "a foreign check was used"; }
grep -q "part (d) reference check: stochastic VRL Lightcuts K=32 over 16 sets" <<<"$third" || fail "the check was not computed again"
grep -q "^key: stochastic VRL Lightcuts K=32 sets=16" "$check" || fail "the check was not stored again"
echo "PASS"
