#!/usr/bin/env bash
# review14: a program started with its stdout and stderr closed (`>&- 2>&-`,
# as a careless init script or a parent that closed them does) took the
# next files it opened for descriptors 1 and 2, and wrote its log lines into
# them: robotalk-server's log went into its panic latch's lock file (any
# file opened for writing while descriptor 2 was free could be the one).
# Each of robotalk-server, robotalk-web, the robotalk CLI (watch),
# robotalk-lcm-relay and robotalk-logplay (record), started so, must have
# /dev/null on descriptors 0-2; the server writes nothing into a file of its
# own, serves, takes a panic and latches it; the recorder records.
# Usage: closed_stdio_test.sh SERVER ROBOTALK WEB MODELS WWW RELAY LOGPLAY (inside a private network namespace).
set -u
server_bin=$1 cli=$2 web=$3 models=$4 www=$5 relay=$6 logplay=$7
. "$(dirname "$0")/../lib.sh"
url="udpm://239.255.76.67:7795?ttl=0"
null_on_stdio() {  # null_on_stdio WHAT PID: descriptors 0, 1, 2 of PID are /dev/null
  local fd target
  for fd in 0 1 2; do
    target=$(readlink "/proc/$2/fd/$fd")
    check "$1: descriptor $fd is /dev/null (it is '$target')" test "$target" = /dev/null
  done
}
# robotalk-server: its panic latch and lock file in $tmp/state.
"$server_bin" --robot "pioneer=kinematic:$models/pioneer2dx_pantilt.urdf" --url "$url" \
  --state-dir "$tmp/state" </dev/null >&- 2>&- &
server_pid=$!
served=0
for _ in $(seq 50); do
  timeout 5 "$cli" --url "$url" query pioneer joint_state pan >/dev/null 2>&1 && { served=1; break; }
  sleep 0.1
done
check "robotalk-server started with stdout and stderr closed serves" test "$served" = 1
null_on_stdio robotalk-server "$server_pid"
# The CLI's watch and the recorder, while the server serves.
"$cli" --url "$url" watch pioneer --duration 3 </dev/null >&- 2>&- &
watch_pid=$!
pids+=($watch_pid)
"$logplay" record -o "$tmp/state.lcmlog" --lcm-url "$url" </dev/null >&- 2>&- &
record_pid=$!
pids+=($record_pid)
sleep 1
null_on_stdio "robotalk watch" "$watch_pid"
null_on_stdio "robotalk-logplay record" "$record_pid"
kill -INT "$record_pid"
wait "$record_pid"
check "robotalk-logplay record started so records the state stream" test -s "$tmp/state.lcmlog"
check "its panic is taken" timeout 5 "$cli" --url "$url" panic pioneer
signal_server TERM
check "robotalk-server ends with 0 on SIGTERM (status $server_status)" test "$server_status" = 0
written=$(grep -rl "robotalk-server: " "$tmp/state")  # a log line's prefix
check "no file of the server's holds its log lines (found in: $written)" test -z "$written"
check "the panic is latched" grep -rq pioneer "$tmp/state"
# robotalk-web: its descriptors.
mkdir -p "$tmp/node_modules/three" "$tmp/node_modules/urdf-loader"
"$web" --port 18451 --lcm-url "$url" --www "$www" --node-modules "$tmp/node_modules" </dev/null >&- 2>&- &
pids+=($!)
sleep 1
null_on_stdio robotalk-web "$!"
"$relay" --a "$url" --b "udpm://239.255.76.67:7995?ttl=0" --duration 3 </dev/null >&- 2>&- &
pids+=($!)
sleep 0.5
null_on_stdio robotalk-lcm-relay "$!"
echo "closed_stdio: $pass passed, $failures failed"
[ "$failures" = 0 ]
