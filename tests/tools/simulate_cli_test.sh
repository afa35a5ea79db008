#!/usr/bin/env bash
# robotalk-server --simulate: a sequence on physics, as fast as possible,
# twice with the same seed -> byte-identical CSV.
#   simulate_cli_test.sh SERVER MODELS_DIR EXAMPLES_DIR
set -u
server=$1 models=$2 examples=$3
. "$(dirname "$0")/../lib.sh"  # $tmp, check, $pass, $failures
for run in a b; do
  "$server" --robot "pioneer=ode:$models/pioneer2dx_pantilt.urdf,seed=5" --simulate "$examples/demo_arcs.txt" \
    --duration 8 --sample-period 0.05 >"$tmp/$run.csv" 2>"$tmp/$run.err"
  check "run $run exits 0" test $? -eq 0
done
check "CSV header" grep -q "^t,x,y,theta,v,omega,q0" "$tmp/a.csv"
check "161 samples over 8 s" test "$(($(wc -l <"$tmp/a.csv") - 1))" -eq 161
check "every command answered SUCCESS" test "$(grep -c SUCCESS "$tmp/a.err")" -eq 7
check "same seed, same trajectory" cmp -s "$tmp/a.csv" "$tmp/b.csv"
check "the robot drove" awk -F, 'END { exit !($2 > 1.0) }' "$tmp/a.csv"
"$server" --robot "a=ode:$models/pioneer2dx_pantilt.urdf" --robot "b=ode:$models/pioneer2dx_pantilt.urdf" \
  --simulate "$examples/demo_arcs.txt" >/dev/null 2>"$tmp/two.err"
check "two robots refused" grep -q "exactly one --robot" "$tmp/two.err"
# The base acceleration limit's bad values are refused by name (before anything runs).
for bad in "0|'0' is not a number in [0.001, 1000]" "1,x|'x' is not a number" "=1,2|'=1,2' names no robot (NAME=LIN[,ANG])"; do
  "$server" --robot "pioneer=kinematic:$models/pioneer2dx_pantilt.urdf" --max-base-acceleration "${bad%%|*}" \
    --simulate "$examples/speed_ramp.txt" >/dev/null 2>"$tmp/bad.err"
  check "--max-base-acceleration ${bad%%|*} refused (exit 2)" test $? -eq 2
  check "--max-base-acceleration ${bad%%|*}: says why" grep -qF -- "--max-base-acceleration: ${bad#*|}" "$tmp/bad.err"
done
# The playback options' bad values too (issue 23 item 3), and a count is a
# whole number: '--max-queue 2.5' was taken as 2 without a word.
for bad in "--playback-queue-start|maybe|--playback-queue-start 'maybe': expected on or off" \
           "--playback-follow-queue|maybe|--playback-follow-queue 'maybe': expected on or off" \
           "--playback-burst-discount|yes|--playback-burst-discount 'yes': expected on or off" \
           "--playback-resent-delays|1|--playback-resent-delays '1': expected on or off" \
           "--playback-margin|-1|--playback-margin: '-1' is not a number in [0, 1000]" \
           "--playback-start-lead|x|--playback-start-lead: 'x' is not a number in [0, 100]" \
           "--max-queue|2.5|--max-queue: '2.5' is not a whole number in [1, 10000000]" \
           "--max-sessions|1.5|--max-sessions: '1.5' is not a whole number" \
           "--max-sessions-per-robot|3.9|--max-sessions-per-robot: '3.9' is not a whole number" \
           "--max-queued-total|1e2.5|--max-queued-total: '1e2.5' is not a whole number" \
           "--log-lines-per-second|0.5|--log-lines-per-second: '0.5' is not a whole number" \
           "--playback-min-frames|2.5|--playback-min-frames: '2.5' is not a whole number" \
           "--seed|9007199254740993|--seed: '9007199254740993' is not a whole number in [0, 9007199254740991]"; do
  IFS='|' read -r flag value why <<<"$bad"
  "$server" --robot "pioneer=kinematic:$models/pioneer2dx_pantilt.urdf" "$flag" "$value" \
    --simulate "$examples/speed_ramp.txt" >/dev/null 2>"$tmp/bad.err"
  check "$flag $value refused (exit 2)" test $? -eq 2
  check "$flag $value: says why" grep -qF -- "$why" "$tmp/bad.err"
done
echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
