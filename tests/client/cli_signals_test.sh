#!/usr/bin/env bash
# The robotalk CLI against a real robotalk-server (kinematic Pioneer): Ctrl-C
# and SIGTERM during motion send STOP and say so; a GOTO longer than
# --timeout is waited for; servo commands say how long the robot holds them
# and --hold holds until Ctrl-C; an unknown robot fails fast naming the robots
# heard; --json on robots, query, send and watch. Runs inside a private
# network namespace (CTest wraps it with netns_run.sh).
#   cli_signals_test.sh SERVER CLI MODELS_DIR
set -u
server_bin=$1 cli=$2 models=$3
url="udpm://239.255.76.67:7814?ttl=0"
. "$(dirname "$0")/../lib.sh"  # $tmp, $server_pid, check
rt() { "$cli" --url "$url" "$@"; }
start_pioneer "$tmp/server.log" --url "$url" --duration 100
base() { rt query pioneer base_pose | awk '{print $(NF-4), $(NF-1)}'; }  # x v
speed() { rt query pioneer base_pose | awk '{print $(NF-1)}'; }
# Starts the CLI in its own session (a background job of a non-interactive
# shell ignores SIGINT, DESIGN §4) and returns its pid in $bg.
start_bg() { setsid "$cli" --url "$url" "$@" >"$tmp/bg.out" 2>"$tmp/bg.err" & bg=$!; }
moving_soon() {  # waits until the base moves (at most 3 s)
  for _ in $(seq 30); do awk -v v="$(speed)" 'BEGIN { exit !(v > 0.05 || v < -0.05) }' && return 0; sleep 0.1; done
  return 1
}

# --- Ctrl-C during a GOTO sends STOP ------------------------------------------
rt send pioneer goto 0 0 0 >/dev/null 2>&1
start_bg send pioneer goto 3 0 0
check "the GOTO moves the robot" moving_soon
kill -INT "$bg"; wait "$bg"; status=$?
check "SIGINT exits 130 (got $status)" test "$status" -eq 130
check "it says it sent STOP" grep -q "interrupted by SIGINT: STOP sent to pioneer: SUCCESS for the GOTO" "$tmp/bg.err"
check "the GOTO's own reply is INTERRUPTED" grep -q INTERRUPTED "$tmp/bg.out"
sleep 0.3
read -r x v < <(base)
check "the robot stopped short of the goal (x=$x v=$v)" awk -v x="$x" -v v="$v" 'BEGIN { exit !(v == 0 && x < 2.5) }'

# --- SIGTERM the same ------------------------------------------------------------
start_bg send pioneer goto 3 0 0
check "the GOTO again moves the robot" moving_soon
kill -TERM "$bg"; wait "$bg"; status=$?
check "SIGTERM exits 143 (got $status)" test "$status" -eq 143
check "SIGTERM says STOP" grep -q "interrupted by SIGTERM: STOP sent" "$tmp/bg.err"
sleep 0.3
check "stopped after SIGTERM" test "$(speed)" = 0

# --- Ctrl-C during a sequence: STOP, and queued frames stopped as they begin --
awk 'BEGIN { for (i = 0; i < 40; i++) printf "%.1f setspeed 0.3 0.1\n", i / 10; print "4.0 stop" }' >"$tmp/seq.txt"
start_bg send pioneer --file "$tmp/seq.txt"
check "the sequence moves the robot" moving_soon
kill -INT "$bg"; wait "$bg"; status=$?
check "interrupted sequence exits 130" test "$status" -eq 130
check "it names the queued frames" grep -q "frames already queued on the server each get a STOP" "$tmp/bg.err"
# Until the server's session timeout (2 s) drops the interrupted client's queue,
# its queued frames still start, each ended at once by its STOP.
still=yes
for _ in $(seq 12); do sleep 0.2; [ "$(speed)" = 0 ] || still=no; done
check "the queued frames did not move the robot again" test "$still" = yes
sleep 0.5

# --- Ctrl-C while nothing was started ends at once -------------------------------
start_bg robots --listen 5
sleep 0.5
t0=$(date +%s.%N)
kill -INT "$bg"; wait "$bg"; status=$?
t1=$(date +%s.%N)
check "Ctrl-C during robots exits 130 (got $status)" test "$status" -eq 130
check "at once" awk -v a="$t0" -v b="$t1" 'BEGIN { exit !(b - a < 0.5) }'

# --- A GOTO longer than --timeout is waited for -----------------------------------
rt send pioneer goto 0 0 0 >/dev/null 2>&1
# A STOP clears every session's "moved the robot" mark: otherwise the expiry of
# the client above (2 s after it exits) makes the watchdog stop the next GOTO.
rt send pioneer stop >/dev/null 2>&1
t0=$(date +%s.%N)
rt --timeout 1 send pioneer goto 1.5 0 0 >"$tmp/long.out" 2>&1; status=$?
t1=$(date +%s.%N)
took=$(awk -v a="$t0" -v b="$t1" 'BEGIN { print b - a }')
check "a ${took} s GOTO with --timeout 1 succeeds: $(cat "$tmp/long.out")" grep -q SUCCESS "$tmp/long.out"
check "exit 0 after the long GOTO" test "$status" -eq 0
check "it really took longer than --timeout" awk -v t="$took" 'BEGIN { exit !(t > 1.5) }'

# --- Servo commands: the note, and --hold ------------------------------------
rt send pioneer setspeed 0.1 0 >"$tmp/servo.out" 2>"$tmp/servo.err"
check "setspeed says the robot holds it only while the command runs" \
  grep -q "keeps this SETSPEED only while this command runs.*--hold" "$tmp/servo.err"
rt send pioneer stop >/dev/null 2>&1
start_bg send pioneer setspeed 0.1 0 --hold
check "--hold keeps the robot moving" moving_soon
sleep 2.5   # longer than the server's 2 s session timeout: held, not stopped by the watchdog
check "still moving after the session timeout" awk -v v="$(speed)" 'BEGIN { exit !(v > 0.05) }'
kill -INT "$bg"; wait "$bg"; status=$?
check "--hold ends with exit 0 on Ctrl-C" test "$status" -eq 0
check "--hold sends STOP at the end" grep -q "STOP sent to pioneer: SUCCESS (hold ended by SIGINT)" "$tmp/bg.err"
sleep 0.3
check "stopped after --hold" test "$(speed)" = 0

# gaps13: a --hold whose STOP is not answered (its server paused) exits 1,
# not 0 (before: 0 whatever its STOP's fate), as its take-over does.
start_bg --timeout 1 send pioneer setspeed 0.1 0 --hold
check "--hold moves the robot again" moving_soon
kill -STOP "$server_pid"
kill -INT "$bg"; wait "$bg"; status=$?
kill -CONT "$server_pid"
check "--hold whose STOP is not answered exits 1 (got $status)" test "$status" -eq 1
check "and says its STOP failed" grep -q "STOP to pioneer failed" "$tmp/bg.err"
sleep 2.5  # the session timeout: the watchdog stops what the CLI left
rt send pioneer stop >/dev/null 2>&1

# --- An unknown robot fails fast, naming the robots heard ---------------------
t0=$(date +%s.%N)
rt query piooner base_pose >"$tmp/unknown.out" 2>&1; status=$?
t1=$(date +%s.%N)
took=$(awk -v a="$t0" -v b="$t1" 'BEGIN { print b - a }')
check "unknown robot exits 1" test "$status" -eq 1
check "unknown robot message" grep -q "no robot 'piooner' on this network (heard: pioneer)" "$tmp/unknown.out"
check "unknown robot fails in ${took} s, well before the 5 s timeout" awk -v t="$took" 'BEGIN { exit !(t < 3) }'

# --- --json ------------------------------------------------------------------
json_ok() { python3 -c 'import json, sys; [json.loads(l) for l in sys.stdin if l.strip()]' <"$1"; }
rt robots --listen 1.2 --json >"$tmp/robots.json"
check "robots --json parses" json_ok "$tmp/robots.json"
check "robots --json names pioneer" python3 -c 'import json,sys; assert json.load(open(sys.argv[1]))[0]["name"] == "pioneer"' "$tmp/robots.json"
rt query pioneer base_pose --json >"$tmp/query.json"
check "query --json parses" python3 -c 'import json,sys; r = json.load(open(sys.argv[1])); assert r["signal"] == "SUCCESS" and len(r["values"]) == 5' "$tmp/query.json"
rt send pioneer joint_setpoint pan 0.3 --json >"$tmp/send.json"
check "send --json parses" python3 -c 'import json,sys; assert json.load(open(sys.argv[1]))["signal"] == "SUCCESS"' "$tmp/send.json"
printf '0 joint_setpoint pan 0.1\n0.2 joint_setpoint tilt 0.1\n' >"$tmp/two.txt"
rt send pioneer --file "$tmp/two.txt" --json >"$tmp/file.json"
check "send --file --json: one object per reply" test "$(json_ok "$tmp/file.json" && wc -l <"$tmp/file.json")" -eq 2
rt watch pioneer --count 3 --json >"$tmp/watch.json" 2>/dev/null
check "watch --json: 3 samples that parse" test "$(json_ok "$tmp/watch.json" && wc -l <"$tmp/watch.json")" -eq 3
check "watch --json carries the base" python3 -c 'import json,sys; assert len(json.loads(open(sys.argv[1]).readline())["base"]) == 5' "$tmp/watch.json"

echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
