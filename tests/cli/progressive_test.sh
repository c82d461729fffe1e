#!/usr/bin/env bash
# progressive_test.sh VRL SCENE WORKDIR [WORKERS]: `vrl render --time-limit` end to end
# (with WORKERS > 0: through `--workers WORKERS`). Nothing here asserts timing:
#  1. A short time limit (3 s, retried at 12 and 48 s if the first pass did not fit:
#     then a partial image, exit 0): exit 0, vrl.progressive.passes >= 1 and vrl.spp = 2^passes - 1
#     in the EXR and the summary, and the image equals the fixed render of that
#     spp bit for bit (every layer).
#  2. --spp caps a time-limited render: 6 samples per pixel, 3 passes, equal to --spp 6.
#  3. SIGINT once the second pass has started: exit 130, the completed passes
#     written as a whole image (no vrl.partial), equal to the fixed render of their spp.
set -u
vrl=$1; scene=$2; work=$3; workers=${4:-0}
rm -rf "$work"; mkdir -p "$work"
fail() { echo "progressive_test: FAIL: $*" >&2; exit 1; }
flags=(--method vrl-lightcuts --vrls 1500 --resolution 24x16 --seed 3)
[ "$workers" -gt 0 ] && flags+=(--workers "$workers" --tile-size 8)
meta() { "$vrl" info "$1" | awk -v key="$2" '$1 == key { print $2 }'; }
same_as_fixed() {  # IMAGE SPP: the fixed render of SPP samples equals IMAGE bit for bit
  "$vrl" render "$scene" -o "$work/fixed-$2.exr" "${flags[@]}" --spp "$2" -q || fail "fixed render of $2 spp"
  "$vrl" compare --exact "$1" "$work/fixed-$2.exr" >"$work/compare-$2.log" 2>&1
  grep -q "identical *yes" "$work/compare-$2.log" || { cat "$work/compare-$2.log"; fail "$1 differs from --spp $2"; }
}

# 1. A time limit: 3 s, or longer where the first pass does not fit in it (a slow
#    machine, the sanitizer build: then the render is a partial first pass, exit 0,
#    or, when not one tile was done, a job refused naming the limit).
for limit in 3 12 48; do
  "$vrl" render "$scene" -o "$work/limited.exr" "${flags[@]}" --time-limit "$limit" 2>"$work/limited.log"; code=$?
  cat "$work/limited.log"
  passes=""
  if [ "$code" -ne 0 ]; then  # not even one tile in time: refused by name, then a longer limit
    grep -q "ran out before any tile was rendered" "$work/limited.log" || fail "--time-limit $limit: exit $code"
    echo "progressive_test: no tile rendered in $limit s; trying a longer limit"
    continue
  fi
  passes=$(meta "$work/limited.exr" vrl.progressive.passes); spp=$(meta "$work/limited.exr" vrl.spp)
  [ -n "$passes" ] && [ "$passes" -ge 1 ] && break
  [ -n "$(meta "$work/limited.exr" vrl.partial)" ] || fail "--time-limit $limit: no pass completed, yet not marked partial"
  echo "progressive_test: no pass completed in $limit s; trying a longer limit"
done
[ -n "$passes" ] && [ "$passes" -ge 1 ] || fail "vrl.progressive.passes '$passes' even at 48 s, expected >= 1 (is the machine that slow?)"
[ "$spp" -eq $(( (1 << passes) - 1 )) ] || fail "vrl.spp $spp after $passes passes"
[ -z "$(meta "$work/limited.exr" vrl.partial)" ] || fail "a time-limited render with whole passes is marked partial"
grep -Eq "progressive: $passes passes.*-> $spp spp" "$work/limited.log" || fail "the summary does not give the passes and spp"
same_as_fixed "$work/limited.exr" "$spp"

# 2. --spp caps it.
"$vrl" render "$scene" -o "$work/capped.exr" "${flags[@]}" --time-limit 600 --spp 6 -q || fail "--spp 6 --time-limit 600"
[ "$(meta "$work/capped.exr" vrl.spp)" = 6 ] || fail "capped: vrl.spp $(meta "$work/capped.exr" vrl.spp), expected 6"
[ "$(meta "$work/capped.exr" vrl.progressive.passes)" = 3 ] || fail "capped: expected 3 passes"
same_as_fixed "$work/capped.exr" 6

# 3. Ctrl-C in the second pass or later keeps the completed passes.
out="$work/interrupted.exr"
"$vrl" render "$scene" -o "$out" "${flags[@]}" --time-limit 600 2>"$work/int.log" &
pid=$!
# The progress display samples the job's state, so a short pass may never be shown: any pass
# from the second on will do. A render that ends by itself before then is a failure with its log.
second_pass() { grep -Eq "rendering pass ([2-9]|[1-9][0-9]+) " "$work/int.log"; }
for _ in $(seq 600); do second_pass && break; kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
if ! second_pass; then
  if kill -0 "$pid" 2>/dev/null; then
    kill -9 "$pid"; wait "$pid"; cat "$work/int.log"; fail "the second pass did not start in 60 s"
  fi
  wait "$pid"; code=$?
  cat "$work/int.log"; fail "the render ended (exit $code) before its second pass, without an interrupt"
fi
kill -INT "$pid"
wait "$pid"; code=$?
cat "$work/int.log"
[ "$code" -eq 130 ] || fail "SIGINT: exit $code, expected 130"
grep -Eq "wrote the [0-9]+ completed passes" "$work/int.log" || fail "SIGINT: no message about the completed passes"
[ -z "$(meta "$out" vrl.partial)" ] || fail "SIGINT after a whole pass: the image is marked partial"
passes=$(meta "$out" vrl.progressive.passes); spp=$(meta "$out" vrl.spp)
[ "$passes" -ge 1 ] && [ "$spp" -eq $(( (1 << passes) - 1 )) ] || fail "SIGINT: $passes passes, $spp spp"
same_as_fixed "$out" "$spp"
echo "progressive_test: ok ($workers workers)"
