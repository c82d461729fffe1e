#!/usr/bin/env bash
# coordinator_memory_test.sh VRL SCENE WORKDIR: a coordinator refuses work that
# cannot fit in its memory before light tracing starts. Its --max-vrls is raised
# to 2^32 so that only the memory estimate stands in the way; the job fails at
# once with the estimate and the machine's memory in its message.
set -u
vrl=$1; scene=$2; work=$3
rm -rf "$work"; mkdir -p "$work"
fail() { echo "coordinator_memory_test: FAIL: $*" >&2; kill "$coordinator" 2>/dev/null; exit 1; }
"$vrl" coordinator --listen 127.0.0.1:0 --port-file "$work/port" --state-dir "$work/state" --max-vrls 4294967296 \
  2>"$work/coordinator.log" &
coordinator=$!
for _ in $(seq 100); do [ -s "$work/port" ] && break; sleep 0.1; done
[ -s "$work/port" ] || fail "the coordinator did not start"
addr=127.0.0.1:$(cat "$work/port")
job=$("$vrl" submit "$scene" -o "$work/x.exr" --vrls 4294967296 --coordinator "$addr" --detach 2>"$work/submit.log") ||
  fail "submit: $(cat "$work/submit.log")"
for _ in $(seq 100); do
  listing=$("$vrl" jobs --coordinator "$addr")
  echo "$listing" | grep -q "$job *failed" && break
  sleep 0.1
done
echo "$listing"
echo "$listing" | grep -Eq "$job *failed .*the 4294967296 VRLs and their light structures need about [0-9]+ GiB, more than the coordinator's [0-9]+ GiB of memory" ||
  fail "the job did not fail with the memory estimate"
kill "$coordinator"; wait "$coordinator"
echo "coordinator_memory_test: ok"
