#!/usr/bin/env bash
# Runs one libFuzzer target the way the fuzz.<target> ctest tests do:
#  1. replays every file under the regressions directory (each must run clean);
#  2. fuzzes a fresh copy of the seed corpus for a fixed time.
# Any crash, sanitizer report, timeout or out-of-memory fails with the fuzzer's
# output; the input that caused it is left in the work directory.
#
#   run_fuzzer.sh --fuzzer BIN --seeds DIR --regressions DIR --work DIR
#                 [--seconds N] [--dict FILE] [-- EXTRA_LIBFUZZER_FLAGS...]
set -uo pipefail

fuzzer="" seeds="" regressions="" work="" seconds=20 dict=""
extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --fuzzer) fuzzer="$2"; shift 2 ;;
    --seeds) seeds="$2"; shift 2 ;;
    --regressions) regressions="$2"; shift 2 ;;
    --work) work="$2"; shift 2 ;;
    --seconds) seconds="$2"; shift 2 ;;
    --dict) dict="$2"; shift 2 ;;
    --) shift; extra=("$@"); break ;;
    *) echo "run_fuzzer.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
if [ -z "$fuzzer" ] || [ -z "$seeds" ] || [ -z "$regressions" ] || [ -z "$work" ]; then
  echo "usage: run_fuzzer.sh --fuzzer BIN --seeds DIR --regressions DIR --work DIR [--seconds N] [--dict FILE]" >&2
  exit 2
fi
if [ ! -x "$fuzzer" ]; then
  echo "run_fuzzer.sh: the fuzzer '$fuzzer' has not been built (the nested clang build in <build>/fuzz-build)" >&2
  exit 1
fi
name=$(basename "$fuzzer")

# Fatal sanitizer reports with symbolised stacks; leaks are findings too.
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0:symbolize=1:detect_stack_use_after_return=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
if [ -z "${ASAN_SYMBOLIZER_PATH:-}" ]; then
  for s in llvm-symbolizer llvm-symbolizer-19 llvm-symbolizer-16 llvm-symbolizer-15 llvm-symbolizer-14; do
    if command -v "$s" >/dev/null 2>&1; then export ASAN_SYMBOLIZER_PATH=$(command -v "$s"); break; fi
  done
fi

common=(-rss_limit_mb=2048 -timeout=10)

rm -rf "$work"
mkdir -p "$work/corpus" "$work/artifacts" "$work/tmp"
export TMPDIR="$work/tmp"   # the targets' scratch directories
log="$work/fuzz.log"

# 1. Regressions, one run per file so that every failing input is named.
failed=()
mapfile -t inputs < <(find "$regressions" -type f ! -name '.*' 2>/dev/null | sort)
if [ ${#inputs[@]} -gt 0 ]; then
  echo "== $name: replaying ${#inputs[@]} regression input(s) from $regressions"
  for input in "${inputs[@]}"; do
    if "$fuzzer" "${common[@]}" "$input" >"$work/replay.log" 2>&1; then
      echo "   ok:     $input"
    else
      echo "   CRASH:  $input"
      grep -E 'ERROR:|runtime error:|SUMMARY:|==vrl-fuzz==|^ +#[0-9]+ ' "$work/replay.log" | head -n 12 | sed 's/^/           /'
      failed+=("$input")
    fi
  done
else
  echo "== $name: no regression inputs in $regressions"
fi

# 2. A fixed-time fuzzing run on a copy of the seeds.
cp -r "$seeds"/. "$work/corpus/"
args=("${common[@]}" -max_total_time="$seconds" -seed=1 -print_final_stats=1
      -artifact_prefix="$work/artifacts/")
if [ -n "$dict" ]; then args+=(-dict="$dict"); fi
echo "== $name: fuzzing $(find "$work/corpus" -type f | wc -l) seed(s) for ${seconds}s"
"$fuzzer" "${args[@]}" "${extra[@]}" "$work/corpus" >"$log" 2>&1
status=$?
result=0
if [ $status -ne 0 ]; then
  tail -n 200 "$log"
  echo "FAIL: $name exited with status $status while fuzzing (whole log: $log); the input is in $work/artifacts/:"
  ls -l "$work/artifacts/"
  result=1
else
  grep -E '^(stat::number_of_executed_units|stat::peak_rss_mb|Done [0-9]+ runs)' "$log" | sed 's/^/   /'
fi
if [ ${#failed[@]} -gt 0 ]; then
  echo "FAIL: $name crashes on ${#failed[@]} regression input(s) (see above; fuzz/regressions/README.md):"
  printf '   %s\n' "${failed[@]}"
  result=1
fi
[ $result -eq 0 ] && echo "PASS: $name"
exit $result
