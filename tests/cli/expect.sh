#!/usr/bin/env bash
# expect.sh CODE REGEX COMMAND...: runs COMMAND, passes if it exits with CODE
# and its combined output matches the extended REGEX (grep -E, across lines
# joined by \n). Prints the output either way, so ctest logs show it.
set -u
expected_code=$1; pattern=$2; shift 2
output=$("$@" 2>&1); code=$?
printf '%s\n' "$output"
if [ "$code" -ne "$expected_code" ]; then
  echo "expect.sh: exit code $code, expected $expected_code" >&2; exit 1
fi
if ! printf '%s\n' "$output" | grep -Ezq -- "$pattern"; then
  echo "expect.sh: output does not match /$pattern/" >&2; exit 1
fi
echo "expect.sh: ok (exit $code, output matches)"
