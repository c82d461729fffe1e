#!/usr/bin/env bash
# workers_interrupt_test.sh VRL SCENE: `vrl render --workers 2` interrupted.
#  - SIGINT 3 s in: the tiles finished so far are written as a partial EXR that
#    `vrl compare` reads, the message says where and how many tiles, exit 130,
#    and no $TMPDIR/vrl-local-* folder is left;
#  - `kill -9` of the client, or a second Ctrl-C (which quits at once): its
#    coordinator and workers stop (PR_SET_PDEATHSIG) and the folder is gone
#    within a few seconds.
set -u
vrl=$1 scene=$2
work=$(mktemp -d)
pids=()
cleanup() { for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null; done; rm -rf "$work"; }
trap cleanup EXIT
fail() { echo "workers_interrupt_test: FAIL: $*" >&2; for f in "$work"/*.err; do [ -f "$f" ] && { echo "--- $f"; cat "$f"; }; done; exit 1; }
export TMPDIR=$work/tmp
mkdir -p "$TMPDIR"
flags=(--workers 2 --threads 1 --method path --resolution 160x120 --spp 160 --tile-size 8 --seed 5)
left() { compgen -G "$TMPDIR/vrl-local-*" > /dev/null; }

# 1. SIGINT 3 s in.
"$vrl" render "$scene" -o "$work/partial.exr" "${flags[@]}" > "$work/render.out" 2> "$work/render.err" &
render=$!; pids+=("$render")
sleep 3
# On a loaded machine (or under sanitizers) the job may still be preparing at 3 s,
# and there is nothing to keep yet: wait for the rendering phase (at most 60 s more).
for _ in $(seq 300); do grep -q "^rendering" "$work/render.err" && break; sleep 0.2; done
left || fail "no vrl-local-* folder while rendering (is TMPDIR honoured?)"
kill -INT "$render"; wait "$render"; code=$?
[ "$code" -eq 130 ] || fail "SIGINT: exit $code, expected 130"
grep -Eq "partial image with [0-9]+ of [0-9]+ tiles written to $work/partial.exr" "$work/render.err" \
  || fail "no message saying where the partial image is and how many tiles it holds"
"$vrl" compare "$work/partial.exr" "$work/partial.exr" > "$work/compare.err" 2>&1 || fail "vrl compare cannot read the partial EXR"
left && fail "a vrl-local-* folder was left after SIGINT: $(ls "$TMPDIR")"
echo "workers_interrupt_test: ok: SIGINT: exit 130, $(grep -o 'partial image with [0-9]* of [0-9]* tiles' "$work/render.err"), no folder left"

# 2. kill -9 of the client.
"$vrl" render "$scene" -o "$work/killed.exr" "${flags[@]}" > /dev/null 2> "$work/killed.err" &
render=$!; pids+=("$render")
sleep 2
# As in 1: on a loaded machine the job may still be starting at 2 s (its folder not
# made yet; this test failed so once under a parallel ctest): wait for rendering.
for _ in $(seq 300); do grep -q "^rendering" "$work/killed.err" && break; sleep 0.2; done
left || fail "no vrl-local-* folder while rendering"
kill -9 "$render"; wait "$render" 2>/dev/null
deadline=$((SECONDS + 15))
while left; do
  [ "$SECONDS" -ge "$deadline" ] && fail "a vrl-local-* folder was left 15 s after kill -9: $(ls -R "$TMPDIR" | head)"
  sleep 0.2
done
echo "workers_interrupt_test: ok: kill -9: the folder was gone after $((SECONDS - deadline + 15)) s"

# 3. Two Ctrl-C in a row: the second quits at once (exit 130), and the folder still goes.
"$vrl" render "$scene" -o "$work/twice.exr" "${flags[@]}" > /dev/null 2> "$work/twice.err" &
render=$!; pids+=("$render")
sleep 2
# As in 1: under sanitizers the job may still be starting at 2 s (the sanitizer
# job saw exit 0 there once: a Ctrl-C during start-up is not yet an interrupt).
for _ in $(seq 300); do grep -q "^rendering" "$work/twice.err" && break; sleep 0.2; done
kill -INT "$render"; sleep 0.05; kill -INT "$render"; wait "$render"; code=$?
[ "$code" -eq 130 ] || fail "two Ctrl-C: exit $code, expected 130"
deadline=$((SECONDS + 15))
while left; do
  [ "$SECONDS" -ge "$deadline" ] && fail "a vrl-local-* folder was left 15 s after a second Ctrl-C"
  sleep 0.2
done
echo "workers_interrupt_test: ok: a second Ctrl-C: exit 130, no folder left"
echo "workers_interrupt_test: 3 passed, 0 failed"
