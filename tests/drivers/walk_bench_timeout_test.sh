#!/usr/bin/env bash
# robotalk-walk-bench counts a GOTO still running at its timeout as TIMEOUT,
# a failure (issue 26: one still walking after 120 s was counted SUCCESS).
# Usage: walk_bench_timeout_test.sh ROBOTALK_WALK_BENCH
set -euo pipefail
bench=$1
# A flag without its value (a trailing --help, --every) is refused at once,
# naming it (before: silently ignored, and the whole default run started).
status=0
err=$(timeout 20 "$bench" --seed 1 --help 2>&1 >/dev/null) || status=$?
[ "$status" -eq 2 ] || { echo "FAIL: a trailing flag: exit status $status, expected 2"; exit 1; }
grep -q -- "--help needs a value" <<<"$err" || { echo "FAIL: a trailing flag not named: $err"; exit 1; }
status=0
out=$("$bench" --goals 1 --goal 0.6,0,0.5 --timeout 2 2>&1) || status=$?
echo "$out"
[ "$status" -eq 1 ] || { echo "FAIL: exit status $status, expected 1"; exit 1; }
grep -q '^0 .* TIMEOUT .*still running after 2' <<<"$out" || { echo "FAIL: goal 0 not reported TIMEOUT"; exit 1; }
grep -q '^success 0/1' <<<"$out" || { echo "FAIL: a timed-out GOTO counted as a success"; exit 1; }
echo PASS
