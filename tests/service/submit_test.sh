#!/usr/bin/env bash
# submit_test.sh VRL VRL_COORDINATOR VRL_WORKER SCENE: what `vrl submit` promises
# a user, with the real programs on loopback:
#  - a bad --retention is refused (exit 2, naming the flag);
#  - a bundle over the coordinator's --max-bundle-mib is refused before any upload
#    (exit 2, size, limit and flag), as is neither a scene nor --attach;
#  - a bundle of exactly the coordinator's --max-files is taken, one file more refused
#    before upload (the client counts the bundle's entries as the coordinator does);
#  - J=$(vrl submit --detach ...) captures exactly the job id;
#  - with no worker, one hint how to start one; Ctrl-C leaves the job running and
#    prints the commands to re-attach and cancel (exit 130), SIGTERM likewise (143);
#  - --attach (no scene) survives a coordinator killed and restarted mid-job and
#    writes the same image as an embedded render;
#  - -q prints nothing on a clean run (warnings and errors only); `vrl jobs` shows submit and finish times;
#    `vrl jobs --purge` deletes finished jobs and prints them.
set -u
vrl=$1 coordinator_bin=$2 worker_bin=$3 scene=$4
work=$(mktemp -d)
pids=()
cleanup() { for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null; done; rm -rf "$work"; }
trap cleanup EXIT
fail() { echo "submit_test: FAIL: $*" >&2; for f in "$work"/*.log "$work"/*.err; do [ -f "$f" ] && { echo "--- $f"; cat "$f"; }; done; exit 1; }
pass() { echo "submit_test: ok: $*"; }
free_port() { python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'; }
now_ms() { date +%s%3N; }
addr=127.0.0.1:$(free_port)
flags=(--method path --resolution 160x120 --spp 200 --tile-size 8 --seed 3)  # ~8 s on one worker thread

start_coordinator() {
  "$coordinator_bin" --listen "$addr" --state-dir "$work/state" --threads 1 --max-bundle-mib 1 \
    --log-level info >> "$work/coordinator.log" 2>&1 &
  coordinator=$!; pids+=("$coordinator")
  local deadline=$((SECONDS + 20))
  until "$vrl" health --address "$addr" > /dev/null 2>&1; do
    [ "$SECONDS" -ge "$deadline" ] && fail "the coordinator did not come up"
    sleep 0.1
  done
}
# wait_for FILE REGEX SECONDS
wait_for() {
  local deadline=$((SECONDS + $3))
  until grep -Eq -- "$2" "$1" 2>/dev/null; do
    [ "$SECONDS" -ge "$deadline" ] && return 1
    sleep 0.1
  done
}
job_line() { "$vrl" jobs --coordinator "$addr" 2>/dev/null | grep -- "$1"; }

# 1. A bad --retention: exit 2 naming the flag.
out=$("$coordinator_bin" --retention 7x --state-dir "$work/unused" 2>&1); code=$?
[ "$code" -eq 2 ] && [[ "$out" == *--retention* ]] || fail "--retention 7x: exit $code: $out"
pass "--retention 7x refused (exit 2): $out"

start_coordinator

# 2. A bundle over --max-bundle-mib 1 is refused before upload: a copy of the scene whose mesh carries 1.5 MiB of comments.
mkdir -p "$work/big"
cp -r "$(dirname "$scene")/meshes" "$work/big/meshes"
cp "$scene" "$work/big/scene.xml"
python3 -c 'import sys; f=open(sys.argv[1], "a"); f.write(("# padding" + "." * 90 + "\n") * 16000)' "$work/big/meshes/icosahedron.obj"
out=$("$vrl" submit "$work/big/scene.xml" --coordinator "$addr" -o "$work/big.exr" "${flags[@]}" 2>&1); code=$?
[ "$code" -eq 2 ] || fail "an oversized bundle: exit $code, expected 2: $out"
echo "$out" | grep -Eq "scene bundle is 1\.[0-9] MiB .*over the limit of 1\.0 MiB.*nothing was uploaded.*--max-bundle-mib 2" \
  || fail "the refusal does not give the size, the limit and the flag: $out"
ls "$work/state/bundles/"*.bundle > /dev/null 2>&1 && fail "a bundle was uploaded although refused"
pass "oversized bundle refused before upload (exit 2): $out"

# 2b. --max-files: the client's count is the bundle's. The refusal at --max-files 1 names the
# count N; a coordinator with --max-files N takes the bundle, one with N - 1 refuses it.
files_coordinator() {  # files_coordinator LIMIT ADDRESS: a coordinator of that file limit, up
  "$coordinator_bin" --listen "$2" --state-dir "$work/files-$1" --threads 1 --max-files "$1" \
    --log-level info >> "$work/coordinator-files.log" 2>&1 &
  pids+=("$!")
  local deadline=$((SECONDS + 20))
  until "$vrl" health --address "$2" > /dev/null 2>&1; do
    [ "$SECONDS" -ge "$deadline" ] && fail "the coordinator with --max-files $1 did not come up"
    sleep 0.1
  done
}
files_addr=127.0.0.1:$(free_port)
files_coordinator 1 "$files_addr"
out=$("$vrl" submit --detach "$scene" --coordinator "$files_addr" -o "$work/f.exr" "${flags[@]}" 2>&1); code=$?
[ "$code" -eq 2 ] || fail "a bundle over --max-files 1: exit $code, expected 2: $out"
count=$(echo "$out" | sed -nE 's/.*scene bundle holds ([0-9]+) files, over the limit of 1.*/\1/p')
[ -n "$count" ] && [ "$count" -ge 2 ] || fail "the --max-files refusal does not name the count: $out"
{ kill -9 "${pids[-1]}"; wait "${pids[-1]}"; } 2>/dev/null
files_addr=127.0.0.1:$(free_port)
files_coordinator "$count" "$files_addr"
F=$("$vrl" submit --detach "$scene" --coordinator "$files_addr" -o "$work/f.exr" "${flags[@]}" 2> "$work/files.err") \
  || fail "a bundle of exactly --max-files $count was refused: $(cat "$work/files.err")"
[[ "$F" =~ ^job-[0-9a-f]{12}$ ]] || fail "submit at exactly --max-files $count printed '$F'"
{ kill -9 "${pids[-1]}"; wait "${pids[-1]}"; } 2>/dev/null
files_addr=127.0.0.1:$(free_port)
files_coordinator $((count - 1)) "$files_addr"
out=$("$vrl" submit --detach "$scene" --coordinator "$files_addr" -o "$work/f.exr" "${flags[@]}" 2>&1); code=$?
[ "$code" -eq 2 ] && [[ "$out" == *"holds $count files, over the limit of $((count - 1))"* ]] \
  || fail "a bundle of $count files at --max-files $((count - 1)): exit $code: $out"
{ kill -9 "${pids[-1]}"; wait "${pids[-1]}"; } 2>/dev/null
pass "a bundle of $count files: taken at --max-files $count, refused at $((count - 1)) before upload"

# 3. Neither a scene nor --attach.
out=$("$vrl" submit --coordinator "$addr" -o "$work/x.exr" 2>&1); code=$?
[ "$code" -eq 2 ] && [[ "$out" == *"give a scene file"*"--attach"* ]] || fail "no scene: exit $code: $out"
pass "no scene and no --attach (exit 2): $out"

# 4. --detach: stdout is the job id and nothing else.
J=$("$vrl" submit --detach "$scene" --coordinator "$addr" -o "$work/a.exr" "${flags[@]}" 2> "$work/detach.err") \
  || fail "submit --detach failed"
[[ "$J" =~ ^job-[0-9a-f]{12}$ ]] || fail "stdout of --detach is '$J', not just a job id"
pass "J=\$(vrl submit --detach ...) = $J"

# 5. Watching with no worker: one hint after 1 s (--no-worker-warning), then Ctrl-C leaves the job running.
"$vrl" submit --attach "$J" --coordinator "$addr" -o "$work/a.exr" --no-worker-warning 1 \
  > "$work/watch.out" 2> "$work/watch.err" &
watcher=$!; pids+=("$watcher")
wait_for "$work/watch.err" "no worker has connected to $addr for 1 s; start one with: vrl-worker --coordinator $addr" 15 \
  || fail "no hint about starting a worker"
t0=$(now_ms); kill -INT "$watcher"; wait "$watcher"; code=$?; t1=$(now_ms)
[ "$code" -eq 130 ] || fail "Ctrl-C while watching: exit $code, expected 130"
[ $((t1 - t0)) -lt 2000 ] || fail "Ctrl-C took $((t1 - t0)) ms to be noticed"
grep -q "vrl submit --attach $J --coordinator $addr -o $work/a.exr" "$work/watch.err" || fail "no re-attach command"
grep -q "vrl cancel $J --coordinator $addr" "$work/watch.err" || fail "no cancel command"
[ "$(grep -c 'no worker has connected' "$work/watch.err")" -eq 1 ] || fail "the hint was shown more than once"
[ -s "$work/watch.out" ] && fail "stdout is not empty: $(cat "$work/watch.out")"
job_line "$J" | grep -Eq "queued|preparing|rendering" || fail "the job did not keep running: $(job_line "$J")"
pass "Ctrl-C after $((t1 - t0)) ms: exit 130, job left running; stderr: $(tr '\n' '|' < "$work/watch.err")"

# 6. A worker, then --attach without a scene while the coordinator is killed and restarted.
"$worker_bin" --coordinator "$addr" --threads 1 --log-level info >> "$work/worker.log" 2>&1 &
pids+=($!)
"$vrl" submit --attach "$J" --coordinator "$addr" -o "$work/a.exr" --retry-for 60 > "$work/attach.out" 2> "$work/attach.err" &
attach=$!; pids+=("$attach")
deadline=$((SECONDS + 60))
until job_line "$J" | grep -Eq "rendering +-?[0-9]+ +[1-9][0-9]*/"; do
  [ "$SECONDS" -ge "$deadline" ] && fail "the job did not start rendering"
  sleep 0.1
done
kill -9 "$coordinator"; wait "$coordinator" 2>/dev/null
sleep 1
start_coordinator
wait "$attach"; code=$?
[ "$code" -eq 0 ] || fail "--attach across a restart: exit $code"
grep -q "is unavailable" "$work/attach.err" && grep -q "re-attached to job $J" "$work/attach.err" \
  || fail "the client did not say it retried and re-attached"
"$vrl" render "$scene" -o "$work/reference.exr" "${flags[@]}" -q > /dev/null 2>&1 || fail "embedded reference render"
"$vrl" compare --exact "$work/reference.exr" "$work/a.exr" | grep -Eq "identical +yes" \
  || fail "the image after a restart differs from the embedded render"
pass "--attach survived a coordinator restart: $(grep -E 'unavailable|re-attached' "$work/attach.err" | tr '\n' '|')"

# 7. SIGTERM while watching: exit 143, and the printed cancel command works.
K=$("$vrl" submit --detach "$scene" --coordinator "$addr" -o "$work/b.exr" --method path --resolution 160x120 --spp 64 --tile-size 8 \
  2> /dev/null) || fail "second submit"
"$vrl" submit --attach "$K" --coordinator "$addr" -o "$work/b.exr" 2> "$work/term.err" &
watcher=$!; pids+=("$watcher")
wait_for "$work/term.err" "rendering|preparing|light" 30 || fail "no progress shown"
kill -TERM "$watcher"; wait "$watcher"; code=$?
[ "$code" -eq 143 ] || fail "SIGTERM while watching: exit $code, expected 143"
cancel=$(sed -n 's/^ *cancel: *vrl //p' "$work/term.err")
[ -n "$cancel" ] || fail "no cancel command after SIGTERM"
# shellcheck disable=SC2086
"$vrl" $cancel | grep -q "$K: cancelled" || fail "the printed cancel command did not cancel: vrl $cancel"
pass "SIGTERM: exit 143; 'vrl $cancel' cancelled the job"

# 8. -q: warnings and errors only: nothing on a clean run; stdout empty.
"$vrl" submit -q "$scene" --coordinator "$addr" -o "$work/q.exr" --method path --resolution 32x24 --spp 1 > "$work/q.out" 2> "$work/q.err" \
  || fail "submit -q failed"
[ -s "$work/q.out" ] && fail "stdout of submit -q is not empty"
[ -s "$work/q.err" ] && fail "submit -q printed: $(cat "$work/q.err")"
[ -s "$work/q.exr" ] || fail "submit -q wrote no image"
pass "-q: nothing printed, the image written"

# 9. `vrl jobs` shows times; --purge deletes the finished jobs and says which.
listing=$("$vrl" jobs --coordinator "$addr") || fail "vrl jobs"
echo "$listing"
echo "$listing" | head -1 | grep -q "SUBMITTED.*AGE.*FINISHED" || fail "no time columns"
echo "$listing" | grep "$J" | grep -Eq "done .* [0-9]{4}-[0-9]{2}-[0-9]{2} [0-9:]{8} .* ago" || fail "no times for $J"
out=$("$vrl" jobs --purge --older-than 3x --coordinator "$addr" 2>&1); code=$?
[ "$code" -eq 2 ] && [[ "$out" == *"not a duration"* ]] || fail "--older-than 3x: exit $code: $out"
out=$("$vrl" jobs --purge --older-than 1d --coordinator "$addr") || fail "purge --older-than 1d"
echo "$out" | grep -q "purged 0 jobs" || fail "purge --older-than 1d removed jobs: $out"
out=$("$vrl" jobs --purge --coordinator "$addr") || fail "purge"
echo "$out"
echo "$out" | grep -q "purged $J" && echo "$out" | grep -q "purged $K" && echo "$out" | grep -Eq "purged 3 jobs" \
  || fail "purge did not list the finished jobs"
[ -d "$work/state/jobs/$J" ] && fail "the purged job's folder is still there"
[ -z "$("$vrl" jobs --coordinator "$addr" | tail -n +2)" ] || fail "jobs remain after the purge"
pass "vrl jobs --purge"
echo "submit_test: 9 passed, 0 failed"
