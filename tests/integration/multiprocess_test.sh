#!/usr/bin/env bash
# Multi-process end to end: robotalk-server and robotalk CLI processes talking
# over LCM multicast. Run inside a private network namespace (CTest wraps it
# with scripts/netns_run.sh).
#   multiprocess_test.sh SERVER CLI MODELS_DIR
set -u
server_bin=$1 cli=$2 models=$3
url="udpm://239.255.76.67:7721?ttl=0"
. "$(dirname "$0")/../lib.sh"  # $tmp, $server_pid, check
rt() { "$cli" --url "$url" --timeout 5 "$@"; }

start_server() {  # start_server LOG [extra server flags...]
  local log=$1; shift
  [ -n "$server_pid" ] && kill "$server_pid" 2>/dev/null && wait "$server_pid" 2>/dev/null
  start_pioneer "$log" --url "$url" --session-timeout 0.5 --duration 60 "$@" && return 0
  echo "server did not start:"; cat "$log"; exit 1
}

# Forward speed v (4th value of BASE_POSE) as printed by `robotalk query`.
base_speed() { rt query pioneer base_pose | awk '{print $(NF-1)}'; }

# A stream of SETSPEED commands every 0.1 s for `seconds`.
stream_file() {  # stream_file FILE SECONDS
  awk -v n="$(( $2 * 10 ))" 'BEGIN { for (i = 0; i < n; i++) printf "%.1f setspeed 0.3 0.2\n", i / 10 }' >"$1"
}

# --- 1. list, describe, query, move ------------------------------------------
start_server "$tmp/server1.log"
rt robots --listen 1.5 >"$tmp/robots" 2>&1
check "robots lists pioneer" grep -q pioneer "$tmp/robots"
rt describe pioneer >"$tmp/describe"
check "describe exits 0" test $? -eq 0
check "describe shows joints" grep -q "pan" "$tmp/describe"
rt send pioneer goto 0.4 0 0 >"$tmp/goto"
check "goto succeeds" test $? -eq 0
check "goto prints SUCCESS" grep -q SUCCESS "$tmp/goto"
rt query pioneer base_pose >"$tmp/pose"
check "base pose reached x=0.4" awk '{ x = $(NF-4); exit !(x > 0.38 && x < 0.42) }' "$tmp/pose"
rt send pioneer joint_setpoint nope 0.1 >/dev/null 2>&1
check "unknown joint exits 1" test $? -eq 1

# --- 2. one client panics while another streams ------------------------------
stream_file "$tmp/stream.txt" 4
"$cli" --url "$url" send pioneer --file "$tmp/stream.txt" >"$tmp/streamer" 2>&1 &
streamer=$!
sleep 1
rt panic pioneer >"$tmp/panic" 2>&1
check "panic exits 0" test $? -eq 0
wait "$streamer"
check "the streamer sees failure" test $? -eq 1
check "the streamer's queued commands were interrupted" grep -q INTERRUPTED "$tmp/streamer"
check "robot halted" test "$(base_speed)" = "0"
rt send pioneer setspeed 0.1 0 >"$tmp/refused" 2>&1
check "commands refused in panic" grep -q PANIC "$tmp/refused"
rt reset pioneer >/dev/null 2>&1
check "reset succeeds" test $? -eq 0
rt send pioneer joint_setpoint pan 0.2 >/dev/null 2>&1
check "commands run again after reset" test $? -eq 0

# --- 3. a client killed mid-stream leaves the robot stopped ------------------
stream_file "$tmp/long.txt" 8
"$cli" --url "$url" send pioneer --file "$tmp/long.txt" >/dev/null 2>&1 &  # the process itself, not a subshell
victim=$!
sleep 1.5
check "moving before the kill" awk -v v="$(base_speed)" 'BEGIN { exit !(v > 0.2) }'
kill -9 "$victim"
wait "$victim" 2>/dev/null
stopped=no
for _ in $(seq 30); do
  speed=$(base_speed)
  [ "$speed" = "0" ] && { stopped=yes; break; }
  sleep 0.1
done
check "watchdog stopped the robot (last speed $speed)" test "$stopped" = yes
check "server logged the watchdog stop" grep -q "vanished; stopping what it moved (the base" "$tmp/server1.log"

# --- 4. lost and duplicated replies still give exactly-once execution -------
start_server "$tmp/server2.log" --inject-reply-drop 0.3 --inject-reply-dup 0.3 --seed 3 --log-executions
awk 'BEGIN { for (i = 1; i <= 40; i++) printf "%.2f joint_setpoint pan %.3f\n", i / 20, i / 100 }' >"$tmp/setpoints.txt"
rt send pioneer --file "$tmp/setpoints.txt" >"$tmp/setpoints.out" 2>&1
check "every set-point answered" test "$(grep -c SUCCESS "$tmp/setpoints.out")" -eq 40
executed=$(grep -c "command [0-9]* JOINT_SETPOINT" "$tmp/server2.log")
distinct=$(grep -o "client [0-9a-f]* command [0-9]* JOINT_SETPOINT" "$tmp/server2.log" | sort -u | wc -l)
check "40 executions, each once (got $executed, $distinct distinct)" test "$executed" -eq 40 -a "$distinct" -eq 40

# --- 5. a server restart (kill -9) during a timed sequence --------------------
# Issue 9: three commands were never executed and the CLI named only the first.
start_server "$tmp/server3.log" --log-executions
printf '0 joint_setpoint pan 0.1\n1 joint_setpoint pan 0.2\n2.5 joint_setpoint pan 0.3\n3 joint_setpoint pan 0.4\n3.5 joint_setpoint pan 0.5\n' >"$tmp/restart.txt"
rt send pioneer --file "$tmp/restart.txt" >"$tmp/restart.out" 2>&1 &
sender=$!
sleep 1.5
kill -9 "$server_pid"; wait "$server_pid" 2>/dev/null; server_pid=""
start_server "$tmp/server4.log" --log-executions
wait "$sender"; sender_rc=$?
check "the CLI fails after a restart (rc $sender_rc)" test "$sender_rc" -ne 0
check "it names each of the 3 commands that may or may not have run: $(cat "$tmp/restart.out")" \
  test "$(grep -c "may or may not have run, and was not sent again" "$tmp/restart.out")" -eq 3
check "and says how many" grep -q "3 of 5 commands may or may not have run" "$tmp/restart.out"
check "the new instance ran none of the old session's commands" \
  test "$(grep -c "JOINT_SETPOINT" "$tmp/server4.log")" -eq 0

echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
