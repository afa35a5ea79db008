#!/usr/bin/env bash
# Issue 22 item 7, end to end over LCM: `robotalk send --file SEQ
# --interpolation cubic` puts the interpolation on the wire (overriding the
# file's own line), a recording of it says so (`robotalk-logplay info`), and
# `robotalk-logplay replay` sends it again interpolated: a second recording,
# of the replay, says the same. Kinematic Pioneers; the server on this branch
# may or may not interpolate: only replies and what travelled are checked.
# Runs inside a private network namespace (CTest wraps it with netns_run.sh).
#   logplay_interpolated_test.sh SERVER CLI LOGPLAY MODELS_DIR
set -u
server_bin=$1 cli=$2 logplay=$3 models=$4
url="udpm://239.255.76.67:7867?ttl=0"
. "$(dirname "$0")/../lib.sh"

"$server_bin" --robot "pioneer=kinematic:$models/pioneer2dx_pantilt.urdf" \
  --robot "pioneer2=kinematic:$models/pioneer2dx_pantilt.urdf" --url "$url" --duration 60 2>"$tmp/server.log" &
server_pid=$!
for _ in $(seq 50); do [ "$(grep -c "serving robot" "$tmp/server.log")" -ge 2 ] && break; sleep 0.1; done

# record LOG: records the RoboTalk channels of $url into LOG until stop_recording.
record() {
  "$logplay" record -o "$1" --lcm-url "$url" -c 'ROBOTALK/.*' 2>"$tmp/record.log" &
  recorder=$!
  wait_for "$tmp/record.log" "recording"
}
stop_recording() { sleep 0.3; kill -INT "$recorder"; wait "$recorder"; }

cat >"$tmp/seq.txt" <<'SEQ'
interpolation linear   # --interpolation cubic overrides it
0.2 joint_setpoint pan 0.1
0.4 joint_setpoint pan 0.2 velocity 0.3
0.6 joint_setpoint tilt -0.1
0.8 joint_setpoint pan 0.25 velocity 0 acceleration 0
SEQ
record "$tmp/sent.lcmlog"
"$cli" --url "$url" send pioneer --file "$tmp/seq.txt" --interpolation cubic --delay 0.3 >"$tmp/send.out" 2>&1
status=$?
stop_recording
cat "$tmp/send.out"
check "send --interpolation exits 0 (got $status)" test "$status" -eq 0
check "every waypoint answered SUCCESS or MODIFIED" test "$(grep -c ' \(SUCCESS\|MODIFIED\) ' "$tmp/send.out")" -eq 4

"$logplay" info "$tmp/sent.lcmlog" >"$tmp/sent.info" 2>&1
check "the recording shows the 4 commands sent cubic (the flag beat the file's line)" \
  grep -q "commands 4 in mode delay: .*; interpolation cubic 4" "$tmp/sent.info"

record "$tmp/replayed.lcmlog"
"$logplay" replay "$tmp/sent.lcmlog" --robot pioneer2 --from pioneer --url "$url" --delay 0.3 >"$tmp/replay.out" 2>&1
status=$?
stop_recording
cat "$tmp/replay.out"
check "replay exits 0 (got $status)" test "$status" -eq 0
check "replay says it replays them cubic" grep -q "replaying 4 commands .*; interpolation cubic 4)" "$tmp/replay.out"
check "replay summarises 4 answers" grep -q "replayed 4/4 commands onto 'pioneer2'" "$tmp/replay.out"

"$logplay" info "$tmp/replayed.lcmlog" >"$tmp/replayed.info" 2>&1
check "the replay travelled cubic too" grep -q "commands 4 in mode delay: .*; interpolation cubic 4" "$tmp/replayed.info"

# Bad words are named, with the accepted ones (no robot needed).
"$cli" --url "$url" send pioneer --file "$tmp/seq.txt" --interpolation cubc >"$tmp/bad.out" 2>&1
status=$?
check "--interpolation cubc exits 2 (got $status)" test "$status" -eq 2
check "and names the word and the accepted ones" \
  grep -q "interpolation: 'cubc' is not an interpolation (step, linear, cubic, quintic)" "$tmp/bad.out"

if [ "$failures" -ne 0 ]; then
  cat "$tmp/sent.info" "$tmp/replayed.info" "$tmp/record.log"
  echo "--- server"; cat "$tmp/server.log"
fi
echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
