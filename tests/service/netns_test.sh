#!/usr/bin/env bash
# netns_test.sh BUILD_DIR SOURCE_DIR
#
# End-to-end test of vrl-coordinator and vrl-worker across real network
# interfaces: three Linux network namespaces (one coordinator, two workers),
# each worker namespace joined to the coordinator namespace by its own veth
# pair, so no traffic between them can go over loopback.
#
#   coordinator ns  <-- veth 10.201.N.1/30 : 10.201.N.2/30 -->  worker-1 ns
#                   <-- veth 10.201.N.5/30 : 10.201.N.6/30 -->  worker-2 ns
#   (N = 20 + $$ % 200; the veths are created directly inside the namespaces,
#    so neither their names nor their addresses ever appear on the host)
#
# Steps: start the coordinator (listening on 0.0.0.0:0, port read from
# --port-file), check `vrl health` from each worker namespace over its veth,
# start one single-threaded worker per worker namespace, submit a small
# vrl-lightcuts job from inside the coordinator namespace, render the same job
# embedded, require `vrl compare --exact` to pass, and require each worker's
# veth to have transmitted more than VRL_NETNS_MIN_TX_BYTES (default 10000)
# bytes during the job (the tile results), which shows that both workers took
# part and that their traffic crossed the veths. Workers and coordinator are
# stopped with SIGTERM (SIGKILL after a timeout); namespaces, veths,
# processes and the temporary directory are always removed by an EXIT trap.
#
# Exit status: 0 pass, 1 fail, 77 skip (register with SKIP_RETURN_CODE 77).
# It skips, printing "SKIP: <reason>", when it is not run as root, when the
# `ip` command is missing, or when `ip netns add`, `ip netns exec` or a veth
# pair cannot be created.
#
# Environment knobs:
#   VRL_NETNS_FORCE_SKIP=1     act as if network namespaces cannot be created
#                              (exercises the skip path; exits 77)
#   VRL_NETNS_MIN_TX_BYTES=N   bytes each worker's veth must send during the
#                              job (default 10000)
#   VRL_NETNS_KEEP_TMP=1       keep the temporary directory (logs, images)
#   VRL_NETNS_TIME_LIMIT=S     overall watchdog in seconds (default 240, below
#                              a ctest TIMEOUT of 300 so cleanup always runs)
set -u

if [ $# -ne 2 ]; then
  echo "usage: $0 BUILD_DIR SOURCE_DIR" >&2
  exit 1
fi
BUILD_DIR=$(cd "$1" 2>/dev/null && pwd) || { echo "FAIL: build dir '$1' not found"; exit 1; }
SOURCE_DIR=$(cd "$2" 2>/dev/null && pwd) || { echo "FAIL: source dir '$2' not found"; exit 1; }

COORD_BIN=$BUILD_DIR/server/vrl-coordinator
WORKER_BIN=$BUILD_DIR/worker/vrl-worker
VRL_BIN=$BUILD_DIR/client/vrl
SCENE=$SOURCE_DIR/scenes/smoke-room.xml
MIN_TX=${VRL_NETNS_MIN_TX_BYTES:-10000}
TIME_LIMIT=${VRL_NETNS_TIME_LIMIT:-240}
RENDER_FLAGS=(--resolution 48x36 --spp 2 --method vrl-lightcuts --vrls 3000 --tile-size 8)

skip() { echo "SKIP: $*"; exit 77; }

# ---- state used by the EXIT trap -------------------------------------------
TMP=""
CREATED_NS=()          # namespaces this run created
STARTED_PIDS=()        # processes this run started
WATCHDOG_PID=""
cleanup() {
  local rc=$? pid ns p
  trap - EXIT INT TERM HUP USR1
  # No `wait` in here: bash can block in a wait nested inside a trap that
  # interrupted another wait. Exited children are reaped by init afterwards.
  [ -n "$WATCHDOG_PID" ] && kill -TERM "$WATCHDOG_PID" 2>/dev/null
  # Processes first: a namespace with live processes outlives `ip netns del`.
  for pid in ${STARTED_PIDS[@]+"${STARTED_PIDS[@]}"}; do
    if proc_alive "$pid"; then kill -TERM "$pid" 2>/dev/null; fi
  done
  for pid in ${STARTED_PIDS[@]+"${STARTED_PIDS[@]}"}; do
    wait_gone "$pid" 5 || { kill -KILL "$pid" 2>/dev/null; wait_gone "$pid" 5; }
  done
  for ns in ${CREATED_NS[@]+"${CREATED_NS[@]}"}; do
    # Anything else still inside our own namespace was started by this run.
    for p in $(ip netns pids "$ns" 2>/dev/null); do kill -KILL "$p" 2>/dev/null; done
    ip netns del "$ns" 2>/dev/null || echo "warning: could not delete namespace $ns" >&2
  done
  if [ -n "$TMP" ] && [ -d "$TMP" ]; then
    if [ "${VRL_NETNS_KEEP_TMP:-0}" = 1 ]; then echo "kept temporary directory $TMP"
    else rm -rf -- "$TMP"; fi
  fi
  exit "$rc"
}
trap cleanup EXIT
trap 'echo "FAIL: interrupted by a signal"; exit 1' INT TERM HUP
trap 'echo "FAIL: overall time limit of ${TIME_LIMIT} s exceeded"; [ -n "$TMP" ] && dump_logs; exit 1' USR1

# forget_pid PID: reaped, so the EXIT trap must not signal it (its id may be reused)
forget_pid() {
  local keep=() p
  for p in ${STARTED_PIDS[@]+"${STARTED_PIDS[@]}"}; do [ "$p" = "$1" ] || keep+=("$p"); done
  STARTED_PIDS=(${keep[@]+"${keep[@]}"})
}
# run_fg LOG CMD...: run CMD in the background, its output to LOG, and wait for
# it, so that a signal (or the watchdog) interrupts the wait at once; the EXIT
# trap then stops CMD. (The redirection is on CMD alone, never on the call, so
# that messages from a trap still reach this script's stdout.)
run_fg() {
  local p rc log=$1
  shift
  "$@" >"$log" 2>&1 &
  p=$!
  STARTED_PIDS+=("$p")
  wait "$p"; rc=$?
  forget_pid "$p"
  return "$rc"
}
# proc_alive PID: running (not a zombie)
proc_alive() {
  local st
  [ -r "/proc/$1/stat" ] || return 1
  st=$(sed 's/.*) //' "/proc/$1/stat" 2>/dev/null | cut -d' ' -f1)
  [ -n "$st" ] && [ "$st" != Z ] && [ "$st" != X ]
}
# wait_gone PID SECONDS: 0 once the process has exited, 1 on timeout
wait_gone() {
  local deadline=$((SECONDS + $2))
  while proc_alive "$1"; do
    [ "$SECONDS" -ge "$deadline" ] && return 1
    sleep 0.1
  done
  return 0
}

dump_logs() {
  local f
  for f in "$TMP"/*.log; do
    [ -s "$f" ] || continue
    echo "---- tail of $(basename "$f") ----"
    tail -n 30 "$f"
  done
}
fail() {
  echo "FAIL: $*"
  [ -n "$TMP" ] && dump_logs
  exit 1
}

# ---- can we make namespaces? -------------------------------------------------
if [ "${VRL_NETNS_FORCE_SKIP:-0}" = 1 ]; then
  skip "VRL_NETNS_FORCE_SKIP=1 set: acting as if network namespaces cannot be created"
fi
if [ "$EUID" -ne 0 ]; then
  skip "creating network namespaces needs root (running as uid $EUID)"
fi
if ! command -v ip >/dev/null 2>&1; then
  skip "the 'ip' command (iproute2) is not installed"
fi

for f in "$COORD_BIN" "$WORKER_BIN" "$VRL_BIN"; do
  [ -x "$f" ] || fail "binary $f not found or not executable"
done
[ -r "$SCENE" ] || fail "scene $SCENE not found"

# Watchdog: SIGUSR1 to this script after TIME_LIMIT s (a loop of short sleeps,
# so that nothing outlives the script by more than a second).
(
  trap - EXIT INT TERM HUP USR1
  n=0
  while [ "$n" -lt "$TIME_LIMIT" ]; do sleep 1; n=$((n + 1)); kill -0 $$ 2>/dev/null || exit 0; done
  kill -USR1 $$ 2>/dev/null
) </dev/null >/dev/null 2>&1 &
WATCHDOG_PID=$!

TMP=$(mktemp -d "${TMPDIR:-/tmp}/vrl-netns.XXXXXX") || fail "mktemp -d failed"
cd "$TMP" || fail "cannot cd to $TMP"

TAG="vrlnt$$r$RANDOM"
NS_C=$TAG-coord
NS_W=("$TAG-w1" "$TAG-w2")
OCT=$((20 + $$ % 200))
COORD_ADDR=("10.201.$OCT.1" "10.201.$OCT.5")
WORKER_ADDR=("10.201.$OCT.2" "10.201.$OCT.6")
C_DEV=(vrlc1 vrlc2)     # coordinator-side veth ends (inside NS_C)
W_DEV=(vrlw1 vrlw2)     # worker-side veth ends (inside NS_W[i])

for ns in "$NS_C" "${NS_W[@]}"; do
  if ! err=$(ip netns add "$ns" 2>&1); then
    skip "'ip netns add $ns' failed: ${err:-unknown error}"
  fi
  CREATED_NS+=("$ns")
  if ! err=$(ip netns exec "$ns" true 2>&1); then
    skip "'ip netns exec $ns' failed: ${err:-unknown error}"
  fi
  ip -n "$ns" link set lo up 2>/dev/null || fail "cannot bring up lo in $ns"
done
for i in 0 1; do
  if ! err=$(ip -n "$NS_C" link add "${C_DEV[$i]}" type veth peer name "${W_DEV[$i]}" netns "${NS_W[$i]}" 2>&1); then
    skip "cannot create a veth pair between $NS_C and ${NS_W[$i]}: ${err:-unknown error}"
  fi
  ip -n "$NS_C" addr add "${COORD_ADDR[$i]}/30" dev "${C_DEV[$i]}" &&
  ip -n "${NS_W[$i]}" addr add "${WORKER_ADDR[$i]}/30" dev "${W_DEV[$i]}" &&
  ip -n "$NS_C" link set "${C_DEV[$i]}" up &&
  ip -n "${NS_W[$i]}" link set "${W_DEV[$i]}" up ||
    fail "cannot configure veth ${C_DEV[$i]} <-> ${W_DEV[$i]}"
done
echo "PASS: namespaces $NS_C, ${NS_W[0]}, ${NS_W[1]} joined by veths" \
     "${COORD_ADDR[0]}<->${WORKER_ADDR[0]}, ${COORD_ADDR[1]}<->${WORKER_ADDR[1]} (/30)"

# Wait until each worker can reach the coordinator side of its veth (if ping
# is installed; otherwise the health check below covers it).
if command -v ping >/dev/null 2>&1; then
  for i in 0 1; do
    deadline=$((SECONDS + 10))
    until run_fg /dev/null ip netns exec "${NS_W[$i]}" ping -c 1 -W 1 "${COORD_ADDR[$i]}"; do
      [ "$SECONDS" -ge "$deadline" ] && fail "${NS_W[$i]} cannot ping ${COORD_ADDR[$i]} over ${W_DEV[$i]} within 10 s"
      sleep 0.2
    done
  done
fi

export VRL_TOKEN
VRL_TOKEN=$(od -An -N16 -tx1 /dev/urandom | tr -d ' \n')
[ ${#VRL_TOKEN} -eq 32 ] || fail "could not make a random token"

# ---- coordinator -------------------------------------------------------------
# `ip netns exec` execs the command, so $! is the coordinator itself.
ip netns exec "$NS_C" "$COORD_BIN" --listen 0.0.0.0:0 --state-dir "$TMP/state" \
  --port-file "$TMP/port" --drain-timeout 5 --log-level warn >"$TMP/coordinator.log" 2>&1 &
COORD_PID=$!
STARTED_PIDS+=("$COORD_PID")

PORT=""
deadline=$((SECONDS + 30))
while :; do
  if [ -s "$TMP/port" ]; then
    PORT=$(tr -dc 0-9 <"$TMP/port")
    [ -n "$PORT" ] && break
  fi
  proc_alive "$COORD_PID" || fail "coordinator exited before writing its port file"
  [ "$SECONDS" -ge "$deadline" ] && fail "coordinator wrote no port file within 30 s"
  sleep 0.1
done
echo "PASS: coordinator (pid $COORD_PID) serving in $NS_C on port $PORT"

for i in 0 1; do
  deadline=$((SECONDS + 30))
  until run_fg "$TMP/health$((i + 1)).log" \
          ip netns exec "${NS_W[$i]}" timeout 10 "$VRL_BIN" health --address "${COORD_ADDR[$i]}:$PORT"; do
    [ "$SECONDS" -ge "$deadline" ] &&
      fail "vrl health from ${NS_W[$i]} to ${COORD_ADDR[$i]}:$PORT did not report SERVING within 30 s"
    sleep 0.5
  done
  echo "PASS: vrl health from ${NS_W[$i]} to ${COORD_ADDR[$i]}:$PORT reports SERVING"
done

# ---- workers -----------------------------------------------------------------
WORKER_PID=()
for i in 0 1; do
  ip netns exec "${NS_W[$i]}" "$WORKER_BIN" --coordinator "${COORD_ADDR[$i]}:$PORT" --threads 1 \
    --name "netns-w$((i + 1))" --log-level warn >"$TMP/worker$((i + 1)).log" 2>&1 &
  WORKER_PID[$i]=$!
  STARTED_PIDS+=("${WORKER_PID[$i]}")
done

# Both workers must be connected before the job goes in, or the first one
# could take every tile: wait for an established TCP connection from each
# worker namespace to the coordinator.
deadline=$((SECONDS + 30))
for i in 0 1; do
  while :; do
    proc_alive "${WORKER_PID[$i]}" || fail "worker $((i + 1)) exited early"
    conns=$(ip netns exec "${NS_W[$i]}" ss -Htn state established dst "${COORD_ADDR[$i]}:$PORT" 2>/dev/null | grep -c .)
    [ "${conns:-0}" -ge 1 ] && break
    [ "$SECONDS" -ge "$deadline" ] && fail "worker $((i + 1)) made no TCP connection to ${COORD_ADDR[$i]}:$PORT within 30 s"
    sleep 0.2
  done
done
echo "PASS: workers (pids ${WORKER_PID[0]}, ${WORKER_PID[1]}) connected over their veths"

veth_stat() {   # veth_stat NS DEV rx_bytes|tx_bytes
  ip netns exec "$1" cat "/sys/class/net/$2/statistics/$3" 2>/dev/null || echo -1
}
declare -a TX0 RX0
for i in 0 1; do
  TX0[$i]=$(veth_stat "${NS_W[$i]}" "${W_DEV[$i]}" tx_bytes)
  RX0[$i]=$(veth_stat "${NS_W[$i]}" "${W_DEV[$i]}" rx_bytes)
done

# ---- the job -----------------------------------------------------------------
t0=$SECONDS
run_fg "$TMP/submit.log" ip netns exec "$NS_C" timeout 120 "$VRL_BIN" submit --coordinator "127.0.0.1:$PORT" \
  "$SCENE" -o "$TMP/distributed.exr" "${RENDER_FLAGS[@]}" -q
rc=$?
if [ "$rc" -eq 124 ]; then fail "vrl submit did not finish within 120 s"
elif [ "$rc" -ne 0 ]; then fail "vrl submit failed (exit status $rc)"; fi
[ -s "$TMP/distributed.exr" ] || fail "vrl submit wrote no image"
echo "PASS: distributed job finished in $((SECONDS - t0)) s"
grep -E '^ *worker ' "$TMP/submit.log" | sed 's/^ */  submit summary: /'   # information only

declare -a TX1 RX1
for i in 0 1; do
  TX1[$i]=$(veth_stat "${NS_W[$i]}" "${W_DEV[$i]}" tx_bytes)
  RX1[$i]=$(veth_stat "${NS_W[$i]}" "${W_DEV[$i]}" rx_bytes)
done

run_fg "$TMP/embedded.log" timeout 120 "$VRL_BIN" render "$SCENE" -o "$TMP/embedded.exr" "${RENDER_FLAGS[@]}" -q
rc=$?
[ "$rc" -eq 0 ] || fail "embedded vrl render failed or timed out (exit status $rc)"

if ! run_fg "$TMP/compare.log" timeout 60 "$VRL_BIN" compare --exact "$TMP/distributed.exr" "$TMP/embedded.exr"; then
  fail "distributed image differs from the embedded render (vrl compare --exact)"
fi
echo "PASS: distributed image is bit-identical to the embedded render: $(grep -m1 identical "$TMP/compare.log")"

traffic_ok=1
for i in 0 1; do
  dtx=$((TX1[i] - TX0[i])); drx=$((RX1[i] - RX0[i]))
  echo "worker $((i + 1)) veth ${NS_W[$i]}/${W_DEV[$i]}: during job tx ${dtx} B, rx ${drx} B" \
       "(totals tx ${TX1[$i]} B, rx ${RX1[$i]} B)"
  if [ "${TX0[$i]}" -lt 0 ] || [ "${TX1[$i]}" -lt 0 ]; then
    echo "FAIL: cannot read the byte counters of ${W_DEV[$i]} in ${NS_W[$i]}"; traffic_ok=0
  elif [ "$dtx" -le "$MIN_TX" ]; then
    echo "FAIL: worker $((i + 1)) sent only $dtx bytes over its veth during the job (need > $MIN_TX): it did not contribute tiles"
    traffic_ok=0
  fi
done
[ "$traffic_ok" = 1 ] || fail "not every worker contributed over its veth"
echo "PASS: both workers sent more than $MIN_TX bytes over their veths during the job"

# ---- shutdown ----------------------------------------------------------------
stop_proc() {   # stop_proc PID NAME SECONDS; sets STOP_RC
  kill -TERM "$1" 2>/dev/null
  if ! wait_gone "$1" "$3"; then
    echo "warning: $2 (pid $1) did not exit within $3 s of SIGTERM; sending SIGKILL"
    kill -KILL "$1" 2>/dev/null
    wait_gone "$1" 5
  fi
  wait "$1" 2>/dev/null
  STOP_RC=$?
  forget_pid "$1"
}
shutdown_ok=1
for i in 0 1; do
  stop_proc "${WORKER_PID[$i]}" "worker $((i + 1))" 10
  if [ "$STOP_RC" -ne 0 ]; then
    echo "FAIL: worker $((i + 1)) exited with status $STOP_RC after SIGTERM (expected 0)"; shutdown_ok=0
  fi
done
stop_proc "$COORD_PID" coordinator 15
if [ "$STOP_RC" -ne 0 ]; then
  echo "FAIL: coordinator exited with status $STOP_RC after SIGTERM (expected 0)"; shutdown_ok=0
fi
[ "$shutdown_ok" = 1 ] || fail "unclean shutdown"
echo "PASS: workers and coordinator exited cleanly on SIGTERM"

echo "PASS: netns_test ($((SECONDS)) s)"
exit 0
