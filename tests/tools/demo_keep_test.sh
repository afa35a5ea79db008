#!/usr/bin/env bash
# The README's demo session kept running (scripts/demo_session.sh, as
# scripts/demo.sh runs it from a terminal): in a private network namespace of
# its own, nested in this test's (which plays the user's machine), it must
# print a URL that opens from here (scripts/demo_forward.py), keep the robot
# moving (a slow scripted motion) until Ctrl-C, and on Ctrl-C stop every
# process it started and exit 0. Run inside a private network namespace
# (CTest wraps it with netns_run.sh).
#   demo_keep_test.sh SOURCE_DIR BUILD_DIR
set -u
source_dir=$1 build_dir=$2
. "$(dirname "$0")/../lib.sh"  # $tmp, check
cd "$source_dir" || exit 1
exec 9</proc/self/ns/net
# Job control: the demo gets its own process group, as a terminal's
# foreground job, and SIGINT is not ignored in it (it would be in a
# background job of a shell without job control).
set -m
ROBOTALK_DEMO_KEEP=1 ROBOTALK_DEMO_HOST_NETNS_FD=9 ROBOTALK_BUILD_DIR=$build_dir ROBOTALK_WEB_PORT=8090 \
  scripts/netns_run.sh scripts/demo_session.sh >"$tmp/demo.out" 2>&1 </dev/null &
demo=$!
set +m
pids+=("$demo")
exec 9<&-
wait_for "$tmp/demo.out" "Running until Ctrl-C" 1200
check "the walkthrough ends and the demo keeps running" grep -q "Running until Ctrl-C" "$tmp/demo.out"
url=$(grep -o 'Watch it in a browser on this machine: http://127.0.0.1:[0-9]*/' "$tmp/demo.out" | grep -o 'http.*')
check "it prints a URL on this machine's loopback ($url)" test -n "$url"
check "the URL opens from outside the demo's namespace" sh -c "curl -sf --max-time 5 '$url' | grep -qi '<html'"
check "and serves the page's modules" curl -sf --max-time 5 -o /dev/null "${url}modules/three/build/three.module.js"
# The robot keeps moving: its pose, asked from inside the demo's namespace, changes.
pose() {
  nsenter --net="/proc/$demo/ns/net" "$build_dir/robotalk-client/robotalk" --timeout 5 \
    query pioneer base_pose 2>/dev/null | tr -s ' ' | head -3
}
first=$(pose)
sleep 3
second=$(pose)
check "the robot keeps moving ($first | $second)" test -n "$first" -a "$first" != "$second"

kill -INT -- "-$demo"
for _ in $(seq 150); do kill -0 "$demo" 2>/dev/null || break; sleep 0.1; done
check "Ctrl-C ends the demo within 15 s" sh -c "! kill -0 $demo 2>/dev/null"
wait "$demo"
status=$?
check "it exits 0 (got $status)" test "$status" -eq 0
check "it says what it stops" grep -q "^Stopping: the motion, robotalk-web, then the server" "$tmp/demo.out"
sleep 1
# Still running in the demo's process group (an exited child its parent did not reap is not running).
left=$(ps -eo pgid=,pid=,stat=,args= | awk -v g="$demo" '$1 == g && $3 !~ /^Z/')
check "no process of the demo is left ($left)" test -z "$left"
check "the server stopped every robot on its way out" grep -q "robotalk-server: .*, stopping every robot" "$tmp/demo.out"
[ "$failures" -eq 0 ] || { echo "--- demo output"; cat "$tmp/demo.out"; }
echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
