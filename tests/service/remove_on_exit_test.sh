#!/usr/bin/env bash
# remove_on_exit_test.sh VRL WORKDIR: the coordinator that `vrl render --workers` starts removes its
# --remove-on-exit folder however many SIGTERMs it gets. A client stopped by a second Ctrl-C while it
# is stopping its coordinator sends two (its own, then PR_SET_PDEATHSIG's); one that came after the
# coordinator had restored its signal handlers killed it before the removal (CI saw the folder left).
# Here SIGTERMs are sent about a millisecond apart until the process is gone, so one lands in every window of
# its teardown; each round must leave no folder. (Its exit code is not checked: after the removal,
# with its handlers restored, a late SIGTERM may still end it as 143, and nothing is lost then.)
# Five rounds, each with a job submitted so the teardown has state to write.
set -u
vrl=$1; work=$2
rm -rf "$work"; mkdir -p "$work"
fail() { echo "remove_on_exit_test: FAIL: $*" >&2; kill -9 "$coordinator" 2>/dev/null; exit 1; }
for round in 1 2 3 4 5; do
  dir=$work/local-$round
  mkdir -p "$dir"
  "$vrl" coordinator --listen 127.0.0.1:0 --port-file "$dir/port" --state-dir "$dir/state" --retention 0 \
    --drain-timeout 5 --remove-on-exit "$dir" 2>"$work/coordinator-$round.log" &
  coordinator=$!
  for _ in $(seq 300); do [ -s "$dir/port" ] && break; sleep 0.1; done
  [ -s "$dir/port" ] || fail "round $round: the coordinator did not start: $(cat "$work/coordinator-$round.log")"
  "$vrl" submit "$(dirname "$0")/../../scenes/smoke-room.xml" -o "$work/x.exr" --method path --spp 1 \
    --coordinator "127.0.0.1:$(cat "$dir/port")" --detach >/dev/null 2>"$work/submit.log" ||
    fail "round $round: submit: $(cat "$work/submit.log")"
  # About one SIGTERM a millisecond: denser floods starve absl's clock calibration in gRPC's
  # teardown (a nanosleep restarted forever), which no client does.
  sent=0 deadline=$((SECONDS + 30))
  while kill -TERM "$coordinator" 2>/dev/null; do
    sent=$((sent + 1)); sleep 0.001
    [ "$SECONDS" -ge "$deadline" ] && fail "round $round: the coordinator did not stop in 30 s of SIGTERMs"
  done
  wait "$coordinator"; code=$?
  [ -e "$dir" ] && fail "round $round: its --remove-on-exit folder was left after $sent SIGTERMs (exit $code): $(ls -R "$dir" | head)"
  echo "remove_on_exit_test: round $round: $sent SIGTERMs, exit $code, folder removed"
done
echo "remove_on_exit_test: ok"
