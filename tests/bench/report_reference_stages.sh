#!/bin/bash
# A part (d) reference longer than 8 chunks per half is built in a second stage
# from the stored 8-chunk one (vrl_report --part-reference-chunks): it resumes
# like every reference, gives the same pixels as a build from nothing, is less
# noisy, and a report run uses it once stored (the 8-chunk one until then, saying so).
set -euo pipefail
report=$1
vrl=$2
out=$3
rm -rf "$out"
fail() { echo "FAIL: $*" >&2; exit 1; }
run() { "$report" --quick --scenes bathroom-hg07 --no-plots "$@" 2>&1 || { echo "FAIL: vrl_report $*" >&2; exit 1; }; }
start=$(date +%s)

# 1. The 8-chunk reference (the first stage), then 10 chunks stopped at the time limit after the 9th.
run --references -o "$out/a" >/dev/null
first=$(ls "$out"/a/cache/bathroom-hg07-reference-d-*.exr)
log=$(run --references --part-reference-chunks 10 --reference-minutes 0.0001 -o "$out/a")
echo "$log"
grep -q "from the cache" <<<"$log" || fail "the 8-chunk reference was not read from the cache"
grep -q "extending $(basename "$first") from 8 to 10 chunks per half" <<<"$log" || fail "no extension from 8 chunks"
grep -q "stopped at the time limit after 9 of 10 chunks" <<<"$log" || fail "no stop after chunk 9"
log=$(run --references --part-reference-chunks 10 -o "$out/a")
echo "$log"
grep -q "resuming after 9 of 10 chunks" <<<"$log" || fail "the extension did not resume"
second=$(ls "$out"/a/cache/bathroom-hg07-reference-d-*.exr | grep -v "$(basename "$first")")
[ "$(wc -l <<<"$second")" -eq 1 ] || fail "expected one 10-chunk reference beside the 8-chunk one"
[ -f "$first" ] || fail "the 8-chunk reference was removed"
note=${second%.exr}.txt
grep -q "plain VRLs over 80 independent VRL sets" "$note" || fail "the note does not count 80 sets (4 x 10 x 2)"
grep -q "^extends: $(basename "$first")" "$note" || fail "the note does not name the reference it extends"

# 2. From nothing (no stop) in another folder: the same pixels, bit for bit, in the image and both halves.
run --references --part-reference-chunks 10 -o "$out/b" >/dev/null
cmp=$("$vrl" compare --exact "$out/b/cache/$(basename "$second")" "$second" 2>&1) ||
    { echo "$cmp"; fail "a build from nothing differs from the resumed extension"; }
echo "$cmp"

# 3. Less noise: 10 chunks against 8 (fixed seeds; expected ratio sqrt(8/10) = 0.89).
noise() { awk -F': ' '/^noise \(RMSE/ { print $2 }' "$1"; }
awk -v a="$(noise "$note")" -v b="$(noise "${first%.exr}.txt")" 'BEGIN { print "noise 10 chunks " a ", 8 chunks " b
    exit !(a < b) }' || fail "the longer reference is not less noisy"

# 4. A report run uses the longer reference once stored, and the 8-chunk one until then (and says so).
log=$(run --part-reference-chunks 12 -o "$out/a")
grep -q "has 8 of the 12 chunks per half the scene asks for" <<<"$log" || { echo "$log"; fail "no short-reference line"; }
grep -q "(short: the scene asks for 96 sets" "$out/a/summary.md" || fail "summary.md does not say the reference is short"
log=$(run --part-reference-chunks 10 -o "$out/a")
grep -q "part (d) reference from the cache ($(basename "$second"))" <<<"$log" || { echo "$log"; fail "the 10-chunk reference was not used"; }
grep -q "short: the scene asks" "$out/a/summary.md" && fail "summary.md calls a stored 10-chunk reference short"
echo "reference stages: $(( $(date +%s) - start )) s"
