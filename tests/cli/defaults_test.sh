#!/usr/bin/env bash
# defaults_test.sh VRL SCENE WORKDIR: what a user gets without asking, and where
# the output goes.
#  - no --method: the headline method vrl-lightcuts (vrl.method in the EXR);
#  - jittered camera rays by default (vrl.jitter 1), --pixel-centres gives 0;
#  - the counter layers eval, inter, cut are single channels (eval.Y ...);
#  - VPL methods name VPLs as VPLs (summary and vrl.vpls, no vrl.vrls);
#  - --threads 0 means all cores; --seed takes 2^64-1 exactly;
#  - stdout stays empty (results are files, logs go to stderr); -q prints nothing
#    on a clean run; progress lines in a pipe carry an ETA.
set -u
vrl=$1; scene=$2; work=$3
rm -rf "$work"; mkdir -p "$work"
fail() { echo "defaults_test: FAIL: $*" >&2; exit 1; }
small=(--resolution 24x16 --spp 2 --vrls 1000)

"$vrl" render "$scene" -o "$work/default.exr" --resolution 128x64 --spp 1 --vrls 1000 --threads 0 >"$work/default.out" 2>"$work/default.err" ||
  fail "default render failed: $(cat "$work/default.err")"
cat "$work/default.err"
[ ! -s "$work/default.out" ] || fail "render wrote to stdout: $(cat "$work/default.out")"
grep -q "method vrl-lightcuts" "$work/default.err" || fail "the summary does not name vrl-lightcuts"
grep -Eq "rendering +[0-9]+% \(.*ETA" "$work/default.err" || fail "no progress line with an ETA"
"$vrl" info "$work/default.exr" >"$work/default.info" || fail "vrl info failed"
cat "$work/default.info"
grep -Eq '^vrl.method +vrl-lightcuts$' "$work/default.info" || fail "default method is not vrl-lightcuts"
grep -Eq '^vrl.jitter +1$' "$work/default.info" || fail "jitter is not on by default"
for counter in eval inter cut; do
  grep -Eq "^layer +$counter $counter.Y$" "$work/default.info" || fail "counter layer $counter is not one channel"
done
grep -Eq '^vrl.run.threads +[1-9]' "$work/default.info" || fail "--threads 0 did not run on all cores"

"$vrl" render "$scene" -o "$work/centres.exr" "${small[@]}" --pixel-centres -q >"$work/centres.out" 2>"$work/centres.err" ||
  fail "--pixel-centres render failed"
[ ! -s "$work/centres.out" ] && [ ! -s "$work/centres.err" ] || fail "-q printed: $(cat "$work/centres.out" "$work/centres.err")"
"$vrl" info "$work/centres.exr" | grep -Eq '^vrl.jitter +0$' || fail "--pixel-centres did not turn jitter off"

"$vrl" render "$scene" -o "$work/vpl.exr" "${small[@]}" --method vpl-lightcuts 2>"$work/vpl.err" || fail "vpl-lightcuts failed"
grep -Eq -- "-> [0-9]+ VPLs" "$work/vpl.err" || fail "the summary does not count VPLs"
"$vrl" info "$work/vpl.exr" >"$work/vpl.info"
grep -Eq '^vrl.vpls +[0-9]' "$work/vpl.info" || fail "no vrl.vpls in a VPL image"
! grep -Eq '^vrl.vrls ' "$work/vpl.info" || fail "a VPL image records vrl.vrls"

"$vrl" render "$scene" -o "$work/seed.exr" "${small[@]}" --seed 18446744073709551615 -q || fail "--seed 2^64-1 refused"
"$vrl" info "$work/seed.exr" | grep -Eq '^vrl.seed +18446744073709551615$' || fail "seed 2^64-1 not recorded exactly"
echo "defaults_test: ok"
