#!/usr/bin/env bash
# Issue 19 item 11: the panic latch is on by default. panic -> kill -9 ->
# restart: the next command answers PANIC naming the latch; a reset runs it.
# Servers on another network (port) do not see the latch; --no-panic-latch
# warns and keeps none; a state directory that cannot be made is an error.
# Run inside a private network namespace (CTest: scripts/netns_run.sh).
#   panic_latch_test.sh SERVER CLI MODELS_DIR
set -u
server_bin=$1 cli=$2 models=$3
. "$(dirname "$0")/../lib.sh"  # $tmp, $server_pid, check
port=7741
url() { echo "udpm://239.255.76.67:$1?ttl=0"; }
rt() { local p=$1; shift; "$cli" --url "$(url "$p")" --timeout 5 "$@"; }
# The default state directory, as robotalk-server finds it (nothing given on its command line).
export ROBOTALK_STATE_DIR="$tmp/state"

start_server() {  # start_server PORT LOG [extra server flags...]
  local p=$1 log=$2; shift 2
  start_pioneer "$log" --url "$(url "$p")" --duration 60 "$@" && return 0
  echo "server did not start:"; cat "$log"; exit 1
}
kill9_server() { kill -9 "$server_pid" 2>/dev/null; wait "$server_pid" 2>/dev/null; server_pid=""; }

# --- 1. panic, kill -9, restart: still in panic --------------------------------
start_server $port "$tmp/s1.log"
check "the server names its latch file" grep -q "panic latch $tmp/state/panic-latch.udpm-239.255.76.67-$port" "$tmp/s1.log"
rt $port panic pioneer >"$tmp/panic" 2>&1
check "panic acknowledged" test $? -eq 0
check "the latch file names the robot" grep -q "^pioneer	" "$tmp/state/panic-latch.udpm-239.255.76.67-$port"
kill9_server
start_server $port "$tmp/s2.log"
check "the restarted server says it starts in PANIC" grep -q "starts in PANIC, latched in" "$tmp/s2.log"
# ... before "serving robot", the line start-up scripts wait for (it came
# after, from the ServerDaemon's first loop: a loaded test read the log too early).
panic_line=$(grep -n "starts in PANIC" "$tmp/s2.log" | head -1 | cut -d: -f1)
serving_line=$(grep -n "serving robot" "$tmp/s2.log" | head -1 | cut -d: -f1)
check "it says so before 'serving robot'" test "${panic_line:-999}" -lt "${serving_line:-0}"
rt $port send pioneer goto 0.3 0 0 >"$tmp/after_restart" 2>&1
check "the next command after the restart is refused" test $? -ne 0
check "it answers PANIC" grep -q PANIC "$tmp/after_restart"
check "the answer names the latch file" grep -q "panic-latch.udpm-239.255.76.67-$port" "$tmp/after_restart"
rt $port reset pioneer >/dev/null 2>&1
check "reset succeeds" test $? -eq 0
rt $port send pioneer goto 0.3 0 0 >"$tmp/after_reset" 2>&1
check "after the reset the command runs" grep -q SUCCESS "$tmp/after_reset"
check "the reset cleared the latch file" sh -c "! grep -q '^pioneer	' '$tmp/state/panic-latch.udpm-239.255.76.67-$port'"

# --- 2. scoped: another network is not latched ----------------------------------
rt $port panic pioneer >/dev/null 2>&1
kill9_server
start_server $((port + 1)) "$tmp/s3.log"
rt $((port + 1)) send pioneer joint_setpoint pan 0.2 >"$tmp/other_net" 2>&1
check "a server on another port runs commands (its own latch)" grep -q SUCCESS "$tmp/other_net"
kill9_server
start_server $port "$tmp/s4.log"
rt $port send pioneer joint_setpoint pan 0.2 >"$tmp/same_net" 2>&1
check "the latched network is still in panic" grep -q PANIC "$tmp/same_net"
rt $port reset pioneer >/dev/null 2>&1
kill9_server

# --- 3. --no-panic-latch: warned, nothing kept ---------------------------------
start_server $((port + 2)) "$tmp/s5.log" --no-panic-latch
check "--no-panic-latch warns" grep -q "WARNING: --no-panic-latch" "$tmp/s5.log"
rt $((port + 2)) panic pioneer >/dev/null 2>&1
kill9_server
start_server $((port + 2)) "$tmp/s6.log" --no-panic-latch
rt $((port + 2)) send pioneer joint_setpoint pan 0.1 >"$tmp/nolatch" 2>&1
check "without a latch the restarted server runs the command" grep -q SUCCESS "$tmp/nolatch"
check "no latch file was written for it" test ! -e "$tmp/state/panic-latch.udpm-239.255.76.67-$((port + 2))"
kill9_server

# --- 4. --panic-latch FILE and --state-dir DIR override the default --------------
start_server $((port + 3)) "$tmp/s7.log" --state-dir "$tmp/elsewhere"
check "--state-dir places the latch" grep -q "panic latch $tmp/elsewhere/panic-latch" "$tmp/s7.log"
kill9_server
start_server $((port + 3)) "$tmp/s8.log" --panic-latch "$tmp/my.latch"
check "--panic-latch names the file" grep -q "panic latch $tmp/my.latch" "$tmp/s8.log"
kill9_server

# --- 5. a state directory that cannot be made: clear error, non-zero exit -------
touch "$tmp/a_file"
"$server_bin" --robot "pioneer=kinematic:$models/pioneer2dx_pantilt.urdf" --url "$(url $((port + 4)))" \
  --duration 5 --state-dir "$tmp/a_file/state" >"$tmp/bad.out" 2>&1
status=$?
check "an unusable state directory exits non-zero" test $status -ne 0
check "its error names the directory" grep -q "state directory '$tmp/a_file/state'" "$tmp/bad.out"
"$server_bin" --robot "pioneer=kinematic:$models/pioneer2dx_pantilt.urdf" --url "$(url $((port + 4)))" \
  --duration 5 --no-panic-latch --panic-latch "$tmp/x" >"$tmp/both.out" 2>&1
check "--no-panic-latch with --panic-latch is a usage error" test $? -eq 2

echo "panic latch: $pass passed, $failures failed"
[ "$failures" -eq 0 ]
