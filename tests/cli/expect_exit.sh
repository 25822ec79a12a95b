#!/usr/bin/env bash
# expect_exit.sh CODE PATTERN COMMAND...: passes when COMMAND exits with CODE
# and its output (stdout and stderr) matches the extended regex PATTERN.
expected=$1 pattern=$2
shift 2
output=$("$@" 2>&1)
code=$?
printf '%s\n' "$output"
if [ "$code" -ne "$expected" ]; then echo "expected exit $expected, got $code"; exit 1; fi
if ! printf '%s\n' "$output" | grep -Eq -- "$pattern"; then echo "output does not match: $pattern"; exit 1; fi
