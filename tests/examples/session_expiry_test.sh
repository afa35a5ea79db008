#!/usr/bin/env bash
# A delay-mode client frozen (SIGSTOP) after its sequence was acknowledged,
# long enough for the server to expire its session and drop the queued frames.
# Woken up, its retransmissions are answered SESSION_UNKNOWN: it must not send
# the frames again (they were accepted once; their outcome is unknown), must
# answer them UNKNOWN_OUTCOME or take the server's INTERRUPTED, and must say
# hello again. The server must have executed none of them.
# Run inside a private network namespace (CTest: scripts/netns_run.sh).
#   session_expiry_test.sh SERVER MODELS_DIR PORT CLIENT_COMMAND...
set -u
server_bin=$1 models=$2 port=$3
shift 3
url="udpm://239.255.76.67:$port?ttl=0"
. "$(dirname "$0")/../lib.sh"  # $tmp, $server_pid, $client_pid, check
start_pioneer "$tmp/server.log" --url "$url" --duration 60 --session-timeout 0.5 --log-executions

# The frames start 3 s after they are sent; the client is frozen 0.1 s after sending them, for 4 s.
"$@" --url "$url" --robot pioneer --delay 3 >"$tmp/out" 2>"$tmp/err" &
client_pid=$!
wait_for "$tmp/out" "^sequence sent" 600 0.05
check "the example sent its sequence" grep -q "^sequence sent" "$tmp/out"
sleep 0.1
kill -STOP "$client_pid"
sleep 4
kill -CONT "$client_pid"
timeout 60 tail --pid="$client_pid" -f /dev/null
wait "$client_pid"
status=$?
client_pid=""
cat "$tmp/out"
check "the example reports the failure (exit 1, got $status)" test "$status" -eq 1
check "the server expired the session" grep -q "vanished\|expired" "$tmp/server.log"
check "the server executed none of the frames (never sent twice)" \
  sh -c "! grep -q 'executed client .* JOINT_SETPOINT' '$tmp/server.log'"
check "each frame has one reply: UNKNOWN_OUTCOME or INTERRUPTED" \
  test "$(grep -c '^reply [0-9]* sequence .*: \(UNKNOWN_OUTCOME\|INTERRUPTED\)' "$tmp/out")" -eq 4
check "it said hello again" grep -q "session unknown to the server; saying hello again" "$tmp/err"
check "it went on in the new session (its queries were answered)" grep -q "^joints: pan=0.000" "$tmp/out"
[ "$failures" -eq 0 ] || { echo "--- stderr"; cat "$tmp/err"; echo "--- server"; cat "$tmp/server.log"; }
echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
