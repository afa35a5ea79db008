#!/usr/bin/env bash
# robotalk-web whose stdout and stderr take nothing (a pipe that is full and
# never read: a supervisor that never drains it, a terminal stopped with
# Ctrl-S) still serves its page and forwards a PANIC: its start-up lines
# ("open http://...", a warning) went to stdout and stderr directly, and it
# waited there for ever, never serving (so no PANIC button worked). Now they
# go through a LogWriter (robotalk/log_writer.h), which waits at most 0.2 s.
# A start-up error ends it with its status whatever stderr takes. Runs inside
# a private network namespace (CTest wraps it with scripts/netns_run.sh).
#   web_stderr_test.sh SERVER CLI WEB MODELS_DIR
set -u
server_bin=$1 cli=$2 web=$3 models=$4
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../lib.sh" # $tmp, $server_pid, check, start_pioneer
url="udpm://239.255.76.67:7859?ttl=0"
port=18459
mkdir -p "$tmp/modules/three" "$tmp/modules/urdf-loader"  # the page's npm modules: present
start_pioneer "$tmp/server.log" --url "$url" --duration 60 --no-panic-latch
check "the server serves" grep -q "serving robot" "$tmp/server.log"

mkfifo "$tmp/full"
sleep 1000 <"$tmp/full" &  # holds the read end, reads nothing
pids+=($!)
exec 3>"$tmp/full"
head -c 65536 /dev/zero >&3  # the pipe's capacity: full
# stdout and stderr the full pipe; a --package-path that does not exist: a
# warning on stderr before it serves, then "open http://..." on stdout.
"$web" --lcm-url "$url" --port "$port" --node-modules "$tmp/modules" --package-path "$tmp/none" >&3 2>&3 &
web_pid=$!
pids+=("$web_pid")
exec 3>&-
python3 "$here/ws_panic.py" "$port" pioneer 15 >"$tmp/panic.out" 2>&1
panic_status=$?
check "with stdout and stderr taking nothing, the page's PANIC is forwarded and taken: $(cat "$tmp/panic.out")" \
  test "$panic_status" -eq 0
"$cli" --url "$url" --timeout 3 send pioneer setspeed 0.1 0 >"$tmp/send.out" 2>&1
check "and the robot is in panic: $(head -c 300 "$tmp/send.out")" grep -q PANIC "$tmp/send.out"
kill -TERM "$web_pid"
for _ in $(seq 50); do kill -0 "$web_pid" 2>/dev/null || break; sleep 0.1; done
check "robotalk-web ends within 5 s of SIGTERM" sh -c "! kill -0 $web_pid 2>/dev/null"
kill -9 "$web_pid" 2>/dev/null

# errs STATUS PATTERN ARGS...: robotalk-web that cannot start (ARGS) ends with
# STATUS within 5 s whatever its stderr takes, and says why when it takes it.
errs() {
  local status=$1 pattern=$2
  shift 2
  fails_whatever_stderr "$status" "$pattern" "$*: robotalk-web" \
    "$web" --lcm-url "$url" --port "$port" --node-modules "$tmp/modules" "$@"
}
errs 2 "unknown option '--colour'" --colour
errs 2 "no such file" --urdf "arm=$tmp/none.urdf"
errs 1 "cannot open" --server-key "$tmp/none.pub"

echo "web_stderr: $pass passed, $failures failed"
[ "$failures" -eq 0 ]
