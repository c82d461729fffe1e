#!/usr/bin/env bash
# deploy/smoke.sh [--full] [--build-dir DIR] [--cache DIR] [--no-compose] [--measure] [--keep]
#
# Smoke test of the container image with podman, on one host, with no registry:
#
#  1. podman is pointed at files this script writes (CONTAINERS_CONF,
#     CONTAINERS_STORAGE_CONF, CONTAINERS_REGISTRIES_CONF): runtime runc,
#     default ulimits within this shell's hard limits (nofile = `ulimit -Hn`,
#     nproc 32768 or `ulimit -Hu` if lower), no registries, pull policy "never", and a private image
#     store under the cache folder (kept between runs, so a second run reuses
#     the base image and the cached layers). The user's podman settings and
#     images are not touched.
#  2. The Debian 12 base image localhost/debian:12 is made by
#     deploy/base-image.sh (debootstrap from this machine's apt sources) unless
#     the store already has it.
#  3. The image is built from deploy/Dockerfile:
#       default: runtime-only, localhost/vrlcuts:prebuilt, from the binaries in
#                --build-dir (default build/, as CI built them) and the package
#                list deploy/runtime-packages.sh derives from them here
#                (`--build-context binaries=DIR` replaces the compile stages);
#       --full:  the whole multi-stage build, localhost/vrlcuts:latest (compiles
#                inside the container: slow).
#  4. A cluster on the host network (`--network host`), the token mounted as a
#     file at /run/secrets/vrl_token: one coordinator and two workers with
#     --health-listen, each in its own container; the client commands run in
#     one-off containers (`podman run --rm`) on the host network too.
#     `vrl health` must answer SERVING for the coordinator and both workers;
#     `vrl submit` renders a small job, which must equal the embedded render
#     of the same job (`vrl render` in a client container) bit for bit
#     (`vrl compare --exact`), and both workers must have returned tiles. SIGTERM (`podman stop -t 30`) must stop each container with exit
#     status 0.
#  5. The same with deploy/compose.yaml under podman-compose (project
#     vrlsmoke<pid>, the coordinator published on a free port, two worker
#     replicas on the compose network reaching `coordinator:50051`): the
#     compose healthchecks (`podman healthcheck run`) must pass, a job
#     submitted to the published port must equal the embedded render, and
#     `podman-compose stop -t 30` must end every container with status 0.
#     Skipped (the rest still counts) with --no-compose, or with a printed
#     reason when podman-compose or netavark/aardvark-dns (service names) are
#     missing.
#
# Exit status: 0 pass; 1 fail; 77 skip (ctest SKIP_RETURN_CODE), printing
# "SKIP: <reason>", when podman cannot run here: podman missing, its
# configuration refused, no container can start (user namespaces, runtime),
# or the base image cannot be made (not root, debootstrap missing, no
# reachable Debian mirror in the apt sources).
#
# Everything stops by itself: an overall time limit (VRL_SMOKE_TIME_LIMIT,
# default 1200 s, 7200 s with --full) ends the run with a failure, and an
# EXIT trap removes every container, compose network and volume this run
# made, and its temporary folder (kept with --keep). Images stay in the cache.
#
# Options:
#   --full          build the whole image (compile inside the build stage)
#   --build-dir DIR where the runtime-only image takes its binaries (default:
#                   build/ of this checkout)
#   --cache DIR     private podman store and settings (default:
#                   $VRL_SMOKE_CACHE or ${XDG_CACHE_HOME:-~/.cache}/vrlcuts-smoke)
#   --no-compose    skip step 5
#   --measure       after the build, print what each shared library costs in the
#                   image (deploy/library_costs.py; the table in deploy/README.md)
#   --keep          keep the temporary folder (logs, token, images)
# Environment: VRL_SMOKE_FORCE_SKIP=1 takes the skip path (exit 77);
# VRL_SMOKE_TIME_LIMIT=S overrides the time limit.
set -u

REPO=$(cd "$(dirname "$0")/.." && pwd)
MODE=runtime
BUILD_DIR=$REPO/build
CACHE=${VRL_SMOKE_CACHE:-${XDG_CACHE_HOME:-${HOME:-/tmp}/.cache}/vrlcuts-smoke}
COMPOSE=1
MEASURE=0
KEEP=0
usage() { sed -n '2,/^set -u/p' "$0" | sed -e 's/^# \{0,1\}//' -e '/^set -u/d'; }
while [ $# -gt 0 ]; do
  case $1 in
    --full) MODE=full ;;
    --build-dir) BUILD_DIR=${2:?--build-dir needs a folder}; shift ;;
    --cache) CACHE=${2:?--cache needs a folder}; shift ;;
    --no-compose) COMPOSE=0 ;;
    --measure) MEASURE=1 ;;
    --keep) KEEP=1 ;;
    -h|--help) usage; exit 0 ;;
    *) echo "smoke: unknown option '$1' (see --help)" >&2; exit 1 ;;
  esac
  shift
done
if [ "$MODE" = full ]; then TIME_LIMIT=${VRL_SMOKE_TIME_LIMIT:-7200}; else TIME_LIMIT=${VRL_SMOKE_TIME_LIMIT:-1200}; fi

BASE_IMAGE=localhost/debian:12
if [ "$MODE" = full ]; then IMAGE=localhost/vrlcuts:latest; else IMAGE=localhost/vrlcuts:prebuilt; fi
RUN_ID=vrlsmoke$$
PROJECT=$RUN_ID                           # podman-compose project
# The job, small enough for one thread per worker: 48x36 in 8-pixel tiles = 30 tiles.
JOB=(--resolution 48x36 --method vrl-lightcuts --vrls 3000 --spp 1 --seed 9)
SECRET=/run/secrets/vrl_token

T0=$SECONDS
skip() { echo "SKIP: $*"; exit 77; }
say() { printf '[%4d s] %s\n' "$((SECONDS - T0))" "$*"; }

# ---- state used by the EXIT trap -------------------------------------------
WORK=""
WATCHDOG_PID=""
CHILD_PID=""
COMPOSE_UP=0
cleanup() {
  local rc=$? ids
  trap - EXIT INT TERM HUP USR1
  [ -n "$WATCHDOG_PID" ] && kill -TERM "$WATCHDOG_PID" 2>/dev/null
  [ -n "$CHILD_PID" ] && kill -TERM "$CHILD_PID" 2>/dev/null
  if [ -n "$WORK" ]; then
    ids=$(podman ps -aq --filter "label=vrlcuts-smoke=$RUN_ID" 2>/dev/null)
    [ -n "$ids" ] && podman rm -f -t 0 $ids >/dev/null 2>&1
    if [ "$COMPOSE_UP" = 1 ]; then
      ids=$(podman ps -aq --filter "label=io.podman.compose.project=$PROJECT" 2>/dev/null)
      [ -n "$ids" ] && podman rm -f -t 0 $ids >/dev/null 2>&1
      podman volume rm -f "${PROJECT}_vrl-state" >/dev/null 2>&1
      podman network rm -f "${PROJECT}_default" >/dev/null 2>&1
    fi
    if [ "$KEEP" = 1 ]; then echo "kept $WORK"; else rm -rf -- "$WORK"; fi
  fi
  exit "$rc"
}
trap cleanup EXIT
trap 'echo "FAIL: interrupted by a signal"; exit 1' INT TERM HUP
trap 'echo "FAIL: overall time limit of $TIME_LIMIT s exceeded"; container_logs; dump_logs; exit 1' USR1

dump_logs() {
  local f
  [ -n "$WORK" ] || return 0
  for f in "$WORK"/*.log; do
    [ -s "$f" ] || continue
    echo "---- tail of $(basename "$f") ----"
    tail -n 40 "$f"
  done
}
# The logs of every container of this run, for dump_logs.
container_logs() {
  local c
  [ -n "$WORK" ] && [ -n "${CONTAINERS_CONF:-}" ] || return 0
  for c in $(podman ps -a --format '{{.Names}}' --filter "label=vrlcuts-smoke=$RUN_ID" 2>/dev/null) \
           $(podman ps -a --format '{{.Names}}' --filter "label=io.podman.compose.project=$PROJECT" 2>/dev/null); do
    podman logs "$c" > "$WORK/$c.log" 2>&1
  done
}
fail() { echo "FAIL: $*"; container_logs; dump_logs; exit 1; }

# run LOG CMD...: CMD in the background, output to LOG, and wait for it, so the
# watchdog's signal interrupts the wait at once (the trap then stops CMD).
run() {
  local log=$1 rc
  shift
  "$@" >"$log" 2>&1 &
  CHILD_PID=$!
  wait "$CHILD_PID"; rc=$?
  CHILD_PID=""
  return "$rc"
}

# ---- can podman run here? -----------------------------------------------------
[ "${VRL_SMOKE_FORCE_SKIP:-0}" = 1 ] && skip "VRL_SMOKE_FORCE_SKIP=1 set: acting as if podman cannot run"
command -v podman >/dev/null || skip "podman is not installed (scripts/setup.sh installs it)"
command -v python3 >/dev/null || skip "python3 is not installed"

# Watchdog: SIGUSR1 to this script after TIME_LIMIT s.
(
  trap - EXIT INT TERM HUP USR1
  n=0
  while [ "$n" -lt "$TIME_LIMIT" ]; do sleep 1; n=$((n + 1)); kill -0 $$ 2>/dev/null || exit 0; done
  kill -USR1 $$ 2>/dev/null
) </dev/null >/dev/null 2>&1 &
WATCHDOG_PID=$!

mkdir -p "$CACHE" || fail "cannot create the cache folder $CACHE"
CACHE=$(cd "$CACHE" && pwd)
WORK=$(mktemp -d "${TMPDIR:-/tmp}/vrl-smoke.XXXXXX") || fail "mktemp -d failed"

# Private podman settings. The run root (locks, mounts) is per cache folder and
# outside it, as podman expects a run root that does not outlive a reboot.
key=$(printf '%s' "$CACHE" | cksum | cut -d' ' -f1)
if [ "$(id -u)" -eq 0 ]; then RUNROOT=/run/vrlcuts-smoke-$key
else RUNROOT=${XDG_RUNTIME_DIR:-${TMPDIR:-/tmp}}/vrlcuts-smoke-$(id -u)-$key; fi
mkdir -p "$RUNROOT" && chmod 0700 "$RUNROOT" || fail "cannot create $RUNROOT"
write_file() { cat > "$1.$$" && mv -f "$1.$$" "$1"; }
# Default ulimits no higher than this shell's hard limits (runc cannot raise them).
NOFILE=$(ulimit -Hn) NPROC=$(ulimit -Hu)
[ "$NOFILE" = unlimited ] && NOFILE=1048576
{ [ "$NPROC" = unlimited ] || [ "$NPROC" -gt 32768 ]; } && NPROC=32768
NETWORK_BACKEND=""
if [ -x /usr/lib/podman/netavark ] && [ -x /usr/lib/podman/aardvark-dns ]; then NETWORK_BACKEND=netavark; fi
write_file "$CACHE/containers.conf" <<EOF
# Written by deploy/smoke.sh on every run; used only through CONTAINERS_CONF.
[containers]
default_ulimits = ["nofile=$NOFILE:$NOFILE", "nproc=$NPROC:$NPROC"]

[network]
${NETWORK_BACKEND:+network_backend = \"$NETWORK_BACKEND\"}
network_config_dir = "$CACHE/networks"

[engine]
runtime = "runc"
pull_policy = "never"
cgroup_manager = "cgroupfs"
events_logger = "file"
tmp_dir = "$RUNROOT/libpod"
volume_path = "$CACHE/volumes"
EOF
mount_program=""
if [ "$(id -u)" -ne 0 ] && command -v fuse-overlayfs >/dev/null && [ -e /dev/fuse ]; then
  mount_program="mount_program = \"$(command -v fuse-overlayfs)\""
fi
write_file "$CACHE/storage.conf" <<EOF
# Written by deploy/smoke.sh on every run; used only through CONTAINERS_STORAGE_CONF.
[storage]
driver = "overlay"
graphroot = "$CACHE/storage"
runroot = "$RUNROOT/storage"
${mount_program:+[storage.options.overlay]
$mount_program}
EOF
write_file "$CACHE/registries.conf" <<'EOF'
# Written by deploy/smoke.sh: no registry at all; images come from this store.
unqualified-search-registries = []
short-name-mode = "disabled"
EOF
export CONTAINERS_CONF=$CACHE/containers.conf
export CONTAINERS_STORAGE_CONF=$CACHE/storage.conf
export CONTAINERS_REGISTRIES_CONF=$CACHE/registries.conf

if ! out=$(podman info 2>&1); then
  skip "podman refuses to start here: $(tail -n 3 <<<"$out" | tr '\n' ' ')"
fi
say "podman $(podman --version | awk '{print $NF}'), runtime runc, ulimits nofile $NOFILE nproc $NPROC, store $CACHE/storage, network backend ${NETWORK_BACKEND:-default}"

# ---- 2. the Debian 12 base image ---------------------------------------------
t=$SECONDS
run "$WORK/base-image.log" bash "$REPO/deploy/base-image.sh" "$BASE_IMAGE"
case $? in
  0) say "base image $BASE_IMAGE: $(tail -n 1 "$WORK/base-image.log" | sed 's/^base-image: //') ($((SECONDS - t)) s)" ;;
  77) skip "no base image: $(grep '^SKIP' "$WORK/base-image.log" | sed 's/^SKIP: //')" ;;
  *) fail "deploy/base-image.sh failed" ;;
esac
if ! out=$(podman run --rm --pull=never --network host "$BASE_IMAGE" true 2>&1); then
  skip "podman cannot run a container here: $(tail -n 3 <<<"$out" | tr '\n' ' ')"
fi

# ---- 3. the image ---------------------------------------------------------------
build=(podman build --pull=never --network host -f "$REPO/deploy/Dockerfile" --build-arg "BASE=$BASE_IMAGE" -t "$IMAGE")
if [ "$MODE" = runtime ]; then
  # Binaries built outside, on Debian 12 like the image: the package list is
  # derived here, from the same binaries, with the same script as the build stage.
  . /etc/os-release 2>/dev/null
  [ "${ID:-}" = debian ] && [ "${VERSION_ID:-}" = 12 ] ||
    skip "the runtime-only image takes this host's binaries, which must be built on Debian 12 (this is ${PRETTY_NAME:-unknown}); use --full"
  mkdir -p "$WORK/binaries/bin"
  for b in client/vrl server/vrl-coordinator worker/vrl-worker; do
    [ -x "$BUILD_DIR/$b" ] || fail "binary $BUILD_DIR/$b not found (build first, or use --full)"
    cp "$BUILD_DIR/$b" "$WORK/binaries/bin/" || fail "cannot copy $BUILD_DIR/$b"
  done
  strip "$WORK/binaries/bin/"* || fail "strip failed"
  "$REPO/deploy/runtime-packages.sh" "$WORK/binaries/bin/"* > "$WORK/binaries/runtime-packages.txt" 2>"$WORK/runtime-packages.log" ||
    fail "deploy/runtime-packages.sh failed"
  say "runtime packages: $(wc -l < "$WORK/binaries/runtime-packages.txt") (deploy/runtime-packages.sh on $BUILD_DIR)"
  build+=(--build-context "binaries=$WORK/binaries")
fi
t=$SECONDS
previous=$(podman image inspect --format '{{.Id}}' "$IMAGE" 2>/dev/null)
run "$WORK/image-build.log" "${build[@]}" "$REPO" || fail "podman build failed (tail of the log below)"
size=$(podman image inspect --format '{{.Size}}' "$IMAGE")
say "image $IMAGE built: $((size / 1000000)) MB ($((SECONDS - t)) s, $MODE)"
# The image this tag named before (an earlier run's binaries) only takes space;
# its layers that the new image shares stay. Fails harmlessly while in use.
if [ -n "$previous" ] && [ "$previous" != "$(podman image inspect --format '{{.Id}}' "$IMAGE")" ]; then
  podman rmi "$previous" >/dev/null 2>&1
fi
if [ "$MEASURE" = 1 ]; then
  run "$WORK/library-costs.md" python3 "$REPO/deploy/library_costs.py" "$IMAGE" "$BASE_IMAGE" ||
    fail "deploy/library_costs.py failed"
  say "what each library costs in $IMAGE (base $BASE_IMAGE: $(($(podman image inspect --format '{{.Size}}' "$BASE_IMAGE") / 1000000)) MB):"
  cat "$WORK/library-costs.md"
fi

# ---- 4. a cluster on the host network ---------------------------------------------
free_ports() {
  python3 - "$1" <<'EOF'
import socket, sys
socks = [socket.socket() for _ in range(int(sys.argv[1]))]
for s in socks:
    s.bind(("127.0.0.1", 0))
print(" ".join(str(s.getsockname()[1]) for s in socks))
EOF
}
read -r CPORT W1PORT W2PORT COMPOSE_PORT <<<"$(free_ports 4)"
od -An -tx1 -N32 /dev/urandom | tr -d ' \n' > "$WORK/token"
chmod 0644 "$WORK/token"                   # the image user (uid 10001) reads it
mkdir -p "$WORK/out" && chmod 0777 "$WORK/out"
common=(--pull=never --network host --label "vrlcuts-smoke=$RUN_ID" -v "$WORK/token:$SECRET:ro")

start() { # start NAME CMD...: a detached container of the image
  local name=$1
  shift
  podman run -d --name "$name" "${common[@]}" "$@" >/dev/null 2>"$WORK/$name.start.log" ||
    fail "cannot start container $name: $(cat "$WORK/$name.start.log")"
}
COORD=$RUN_ID-coordinator W1=$RUN_ID-worker1 W2=$RUN_ID-worker2
# "${CLIENT[@]}" CMD...: a one-off client container, with the scenes and the output folder.
CLIENT=(podman run --rm "${common[@]}" -v "$REPO/scenes:/scenes:ro" -v "$WORK/out:/out" "$IMAGE")
# health ADDRESS SECONDS: `vrl health` from a client container until SERVING.
health() {
  local deadline=$((SECONDS + $2)) out
  while true; do
    if out=$("${CLIENT[@]}" vrl health --address "$1" 2>&1); then say "vrl health $1: $out"; return 0; fi
    [ "$SECONDS" -ge "$deadline" ] && { echo "vrl health $1: $out"; return 1; }
    sleep 0.5
  done
}
# same_as_embedded NAME: /out/NAME.exr equals the embedded render bit for bit.
same_as_embedded() {
  "${CLIENT[@]}" vrl compare --exact "/out/$1.exr" /out/embedded.exr > "$WORK/compare-$1.log" 2>&1 &&
    grep -Eq '^identical +yes' "$WORK/compare-$1.log"
}
# stopped_cleanly NAME...: exit status 0 after SIGTERM.
stopped_cleanly() {
  local c code
  for c in "$@"; do
    code=$(podman inspect --format '{{.State.ExitCode}}' "$c")
    podman logs "$c" > "$WORK/$c.log" 2>&1
    [ "$code" = 0 ] || fail "$c exited with status $code on SIGTERM"
  done
}
# tiles_returned LOGFILE: the count in the worker's "stopped (N tiles returned)".
tiles_returned() { sed -n 's/.*stopped (\([0-9]*\) tiles returned).*/\1/p' "$1" | tail -n 1; }

t=$SECONDS
start "$COORD" "$IMAGE" vrl-coordinator --listen "127.0.0.1:$CPORT" --state-dir /var/lib/vrl/state \
  --token-file "$SECRET" --threads 1
health "127.0.0.1:$CPORT" 30 || fail "the coordinator does not answer SERVING"
for i in 1 2; do
  name=W$i port=W${i}PORT
  start "${!name}" "$IMAGE" vrl-worker --coordinator "127.0.0.1:$CPORT" --token-file "$SECRET" \
    --health-listen "127.0.0.1:${!port}" --threads 1 --name "smoke-worker$i"
done
health "127.0.0.1:$W1PORT" 60 || fail "worker 1 does not answer SERVING (registered)"
health "127.0.0.1:$W2PORT" 60 || fail "worker 2 does not answer SERVING (registered)"

run "$WORK/embedded.log" "${CLIENT[@]}" vrl render -q /scenes/smoke-room.xml -o /out/embedded.exr "${JOB[@]}" ||
  fail "the embedded render failed"
run "$WORK/submit.log" timeout 300 "${CLIENT[@]}" vrl submit -q --coordinator "127.0.0.1:$CPORT" \
  --token-file "$SECRET" --tile-size 8 /scenes/smoke-room.xml -o /out/submitted.exr "${JOB[@]}" ||
  fail "vrl submit from the client container failed"
same_as_embedded submitted || fail "the submitted job differs from the embedded render: $(cat "$WORK/compare-submitted.log")"
say "vrl submit from a client container: identical to the embedded render bit for bit"

ts=$SECONDS
podman stop -t 30 "$W1" "$W2" >/dev/null && podman stop -t 30 "$COORD" >/dev/null || fail "podman stop failed"
stopped_cleanly "$W1" "$W2" "$COORD"
n1=$(tiles_returned "$WORK/$W1.log") n2=$(tiles_returned "$WORK/$W2.log")
[ "${n1:-0}" -gt 0 ] && [ "${n2:-0}" -gt 0 ] || fail "both workers should have returned tiles (worker 1: ${n1:-?}, worker 2: ${n2:-?})"
say "SIGTERM: workers (tiles returned: $n1 + $n2) and coordinator exited 0 in $((SECONDS - ts)) s"
say "PASS: host-network cluster ($((SECONDS - t)) s)"

# ---- 5. deploy/compose.yaml under podman-compose ----------------------------------------
compose_reason=""
if [ "$COMPOSE" = 0 ]; then compose_reason="--no-compose"
elif ! command -v podman-compose >/dev/null; then compose_reason="podman-compose is not installed (scripts/setup.sh installs it)"
elif [ -z "$NETWORK_BACKEND" ]; then compose_reason="netavark and aardvark-dns are not installed: the workers could not resolve 'coordinator'"
fi
if [ -n "$compose_reason" ]; then
  say "compose: skipped ($compose_reason)"
else
  t=$SECONDS
  pc=(podman-compose --no-ansi -p "$PROJECT" -f "$REPO/deploy/compose.yaml")
  export VRL_IMAGE=$IMAGE VRL_PORT=127.0.0.1:$COMPOSE_PORT VRL_TOKEN_FILE=$WORK/token
  COMPOSE_UP=1
  run "$WORK/compose-up.log" timeout 120 "${pc[@]}" up -d --no-build || fail "podman-compose up failed"
  COORD_C=${PROJECT}_coordinator_1 WORKERS_C=("${PROJECT}_worker_1" "${PROJECT}_worker_2")
  for c in "$COORD_C" "${WORKERS_C[@]}"; do
    podman container exists "$c" || fail "podman-compose did not create $c"
  done
  # The compose healthchecks themselves (no systemd timer runs them here).
  for c in "$COORD_C" "${WORKERS_C[@]}"; do
    deadline=$((SECONDS + 60))
    until podman healthcheck run "$c" >/dev/null 2>&1; do
      [ "$SECONDS" -ge "$deadline" ] && { podman logs "$c" > "$WORK/$c.log" 2>&1; fail "compose: $c is not healthy"; }
      sleep 1
    done
  done
  say "compose: $COORD_C and ${#WORKERS_C[@]} workers healthy (podman healthcheck run)"
  run "$WORK/compose-submit.log" timeout 300 "${CLIENT[@]}" vrl submit -q --coordinator "127.0.0.1:$COMPOSE_PORT" \
    --token-file "$SECRET" --tile-size 8 /scenes/smoke-room.xml -o /out/compose.exr "${JOB[@]}" ||
    fail "vrl submit to the compose coordinator failed"
  same_as_embedded compose || fail "the compose job differs from the embedded render: $(cat "$WORK/compare-compose.log")"
  say "compose: vrl submit to the published port 127.0.0.1:$COMPOSE_PORT, identical to the embedded render"
  run "$WORK/compose-stop.log" timeout 120 "${pc[@]}" stop -t 30 || fail "podman-compose stop failed"
  stopped_cleanly "${WORKERS_C[@]}" "$COORD_C"
  n1=$(tiles_returned "$WORK/${WORKERS_C[0]}.log") n2=$(tiles_returned "$WORK/${WORKERS_C[1]}.log")
  [ "${n1:-0}" -gt 0 ] && [ "${n2:-0}" -gt 0 ] || fail "compose: both workers should have returned tiles (${n1:-?}, ${n2:-?})"
  run "$WORK/compose-down.log" timeout 120 "${pc[@]}" down -v || fail "podman-compose down failed"
  podman network rm -f "${PROJECT}_default" >/dev/null 2>&1
  say "PASS: compose (podman-compose up, healthchecks, submit, stop -t 30: all exited 0, tiles returned $n1 + $n2; $((SECONDS - t)) s)"
fi

say "PASS: deploy/smoke.sh ($MODE image $IMAGE) in $((SECONDS - T0)) s"
