#!/usr/bin/env bash
# health_test.sh VRL VRL_COORDINATOR VRL_WORKER: the real programs' grpc.health.v1
# endpoints. A worker started with --health-listen serves health checks (it used
# to exit 1 at start-up: gRPC's default health service cannot run on a server
# without other services) and answers NOT_SERVING until it is registered,
# SERVING while registered; the coordinator answers SERVING; both stop cleanly
# (exit 0) on SIGTERM, and a stopped worker's port answers no more.
set -u
vrl=$1 coordinator_bin=$2 worker_bin=$3
work=$(mktemp -d)
pids=()
cleanup() { for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null; done; rm -rf "$work"; }
trap cleanup EXIT
fail() { echo "health_test: FAIL: $*" >&2; for f in "$work"/*.log; do echo "--- $f"; cat "$f"; done; exit 1; }
free_port() { python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'; }
# health ADDRESS EXPECTED_EXIT SECONDS: polls `vrl health` until it exits with EXPECTED_EXIT.
health() {
  local deadline=$((SECONDS + $3)) out code
  while true; do
    out=$("$vrl" health --address "$1" 2>&1); code=$?
    if [ "$code" -eq "$2" ]; then echo "vrl health $1: exit $code: $out"; return 0; fi
    [ "$SECONDS" -ge "$deadline" ] && { echo "vrl health $1: exit $code (wanted $2): $out"; return 1; }
    sleep 0.2
  done
}

coordinator_port=$(free_port)
worker_health=127.0.0.1:$(free_port)
echo "test-token" > "$work/token"

# 1. A worker whose coordinator is not up yet: its health port serves, NOT_SERVING.
"$worker_bin" --coordinator "127.0.0.1:$coordinator_port" --token-file "$work/token" --threads 1 \
  --health-listen "$worker_health" --log-level info > "$work/worker.log" 2>&1 &
worker=$!; pids+=("$worker")
health "$worker_health" 1 20 || fail "the worker's health endpoint does not answer NOT_SERVING before registration"
"$vrl" health --address "$worker_health" 2>&1 | grep -q NOT_SERVING || fail "expected NOT_SERVING in the answer"

# 2. The coordinator comes up: SERVING on its port, and the worker registers and turns SERVING.
"$coordinator_bin" --listen "127.0.0.1:$coordinator_port" --state-dir "$work/state" --token-file "$work/token" \
  --threads 1 --log-level info > "$work/coordinator.log" 2>&1 &
coordinator=$!; pids+=("$coordinator")
health "127.0.0.1:$coordinator_port" 0 20 || fail "the coordinator does not answer SERVING"
health "$worker_health" 0 30 || fail "the registered worker does not answer SERVING"
kill -0 "$worker" || fail "the worker exited"

# 3. SIGTERM: both exit 0, and the worker's health port goes away with it.
kill -TERM "$worker"
wait "$worker"; code=$?
[ "$code" -eq 0 ] || fail "the worker exited $code on SIGTERM"
health "$worker_health" 1 10 | grep -q unreachable || fail "the stopped worker's health port still answers"
kill -TERM "$coordinator"
wait "$coordinator"; code=$?
[ "$code" -eq 0 ] || fail "the coordinator exited $code on SIGTERM"
echo "health_test: 1 passed, 0 failed"
