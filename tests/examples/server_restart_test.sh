#!/usr/bin/env bash
# A client example whose server restarts while it waits: its next package is
# answered SESSION_UNKNOWN by the new instance, so it must say hello again
# (and, in delay mode, synchronise its clock again) and finish its sequence.
# Run inside a private network namespace (CTest: scripts/netns_run.sh).
#   server_restart_test.sh SERVER MODELS_DIR PORT CLIENT_COMMAND...
set -u
server_bin=$1 models=$2 port=$3
shift 3
url="udpm://239.255.76.67:$port?ttl=0"
. "$(dirname "$0")/../lib.sh"  # $tmp, $server_pid, $client_pid, check
start_server() {  # start_server LOG
  start_pioneer "$1" --url "$url" --duration 60 && return 0
  echo "server did not start"; cat "$1"; exit 1
}
start_server "$tmp/first.log"
timeout 60 "$@" --url "$url" --robot pioneer --pause 4 >"$tmp/out" 2>"$tmp/err" &
client_pid=$!
wait_for "$tmp/out" "^pausing" 300
check "the example got to its pause" grep -q "^pausing" "$tmp/out"
kill "$server_pid"; wait "$server_pid" 2>/dev/null
start_server "$tmp/second.log"
wait "$client_pid"
status=$?
client_pid=""
cat "$tmp/out"
first=$(grep -o -m1 "^connected: .* server=[0-9a-f]*" "$tmp/out" | sed 's/.*server=//')
check "the example exits 0 (got $status)" test "$status" -eq 0
check "it said hello again" grep -q "session unknown to the server; saying hello again" "$tmp/err"
check "it noticed the new server instance" grep -q "^new server instance [0-9a-f]\{16\}, session" "$tmp/out"
check "the new instance is another server ($first)" sh -c "! grep -q '^new server instance $first' '$tmp/out'"
check "every frame of the sequence succeeded on the new instance" \
  test "$(grep -c '^reply [0-9]* sequence .*: SUCCESS' "$tmp/out")" -eq 4
check "the new instance's robot started at the origin" grep -q "^pose: x=0.000" "$tmp/out"
[ "$failures" -eq 0 ] || { echo "--- stderr"; cat "$tmp/err"; echo "--- servers"; cat "$tmp/first.log" "$tmp/second.log"; }
echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
