#!/usr/bin/env bash
# A client example given no key against a keyed server (robotalk-server --key
# --clients): it must say the server requires keys, exit 1, and not move the
# robot (the Java and Lua examples speak open mode only; the C example speaks
# keyed mode when given a key: tests/examples/c_keyed_session_test.sh). Run
# inside a private network namespace (CTest: scripts/netns_run.sh).
#   keyed_refusal_test.sh SERVER KEYGEN MODELS_DIR PORT CLIENT_COMMAND...
set -u
server_bin=$1 keygen=$2 models=$3 port=$4
shift 4
url="udpm://239.255.76.67:$port?ttl=0"
. "$(dirname "$0")/../lib.sh"  # $tmp, $server_pid, check
. "$(dirname "$0")/keyed_server.sh"  # start_keyed_server
start_keyed_server "$server_bin" "$keygen" "$models" "$url" 60

ROBOTALK_KEY= timeout 30 "$@" --url "$url" --robot pioneer >"$tmp/out" 2>"$tmp/err"
status=$?
check "the example exits 1 (got $status)" test "$status" -eq 1
check "it says the server requires keys" \
  grep -q "error: the server of 'pioneer' requires keys (keyed mode, docs/security.md)" "$tmp/err"
check "it never said hello (the server counted none)" sh -c "! grep -qi 'hello' '$tmp/server.log'"
[ "$failures" -eq 0 ] || { cat "$tmp/out" "$tmp/err" "$tmp/server.log"; }
echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
