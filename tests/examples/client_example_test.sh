#!/usr/bin/env bash
# Runs one client example (examples/c_client, java_client, lua_client) against a
# real robotalk-server (kinematic Pioneer) and checks what it printed and what
# the robot did. Run inside a private network namespace (CTest wraps it with
# scripts/netns_run.sh, which exits 77 = skip where none can be made).
#   client_example_test.sh SERVER CLI MODELS_DIR PORT LAYOUT CLIENT_COMMAND...
# LAYOUT: "default" (the server's default traffic layout), "single" or
# "split" (the URL option traffic=single|split, given to server, clients and
# CLI alike; the clients strip it and follow ANNOUNCE), or "lossy" (default
# layout, but the server drops and duplicates 30 % of its reply packages: each
# command must still run exactly once).
# The client command gets "--url URL --robot NAME" appended.
set -u
server_bin=$1 cli=$2 models=$3 port=$4 layout=$5
shift 5
url="udpm://239.255.76.67:$port?ttl=0"
server_flags=()
case $layout in
  default) ;;
  single | split) url="$url&traffic=$layout" ;;
  lossy) server_flags=(--inject-reply-drop 0.3 --inject-reply-dup 0.3 --seed 5 --log-executions) ;;
  *) echo "unknown layout $layout"; exit 2 ;;
esac
. "$(dirname "$0")/../lib.sh"  # $tmp, $server_pid, check
# value KEY FILE: the number after "KEY=" on the first line that has it.
value() { grep -o -m1 "$1=[-0-9.]*" "$2" | head -1 | cut -d= -f2; }
within() { awk -v v="$1" -v lo="$2" -v hi="$3" 'BEGIN { exit !(v != "" && v >= lo && v <= hi) }'; }

start_pioneer "$tmp/server.log" --url "$url" --duration 90 "${server_flags[@]}"

# A robot nobody announces (checked below) waits out the example's connect
# timeout (5 s) listening to announcements: it runs meanwhile, not after.
timeout 30 "$@" --url "$url" --robot piooner >"$tmp/out2" 2>"$tmp/err2" &
unknown_pid=$!
pids+=("$unknown_pid")

# --- the example: connect, configuration, GOTO, timed sequence, replies ------
timeout 60 "$@" --url "$url" --robot pioneer >"$tmp/out" 2>"$tmp/err"
status=$?
cat "$tmp/out"
check "the example exits 0 (got $status)" test "$status" -eq 0
check "it connected and opened a session" grep -q "^connected: robot=pioneer server=[0-9a-f]\{16\} layout=\(single\|split\) session=" "$tmp/out"
case $layout in single | split)
  check "it took the $layout layout from ANNOUNCE" grep -q "^connected: .* layout=$layout " "$tmp/out" ;;
esac
check "the configuration message matches the CONFIG reply" \
  grep -q "^config: robot=pioneer links=7 joints=6 frames=1 dofs=4 hash=[0-9a-f]\{16\} (reply and message agree)" "$tmp/out"
check "the config hash is the one the server announced" \
  grep -q "config $(grep -o -m1 'hash=[0-9a-f]*' "$tmp/out" | cut -d= -f2)" "$tmp/server.log"
check "the GOTO succeeded" grep -q "^reply [0-9]* GOTO 0.5 0 0: SUCCESS" "$tmp/out"
check "every frame of the sequence succeeded" test "$(grep -c '^reply [0-9]* sequence .*: SUCCESS' "$tmp/out")" -eq 4
# The interpolated sequence (issue 22): each waypoint answered SUCCESS when the
# trajectory passes it, or MODIFIED when a limit changed it.
check "every waypoint of the interpolated sequence was answered SUCCESS or MODIFIED" \
  test "$(grep -c '^reply [0-9]* trajectory cubic .*: \(SUCCESS\|MODIFIED\)' "$tmp/out")" -eq 3
# The frames are 0.25 s apart: the server (delay mode) or the client (direct
# mode) must never run one early. Frame k runs at least k x 0.25 s (less
# 10 ms) after frame 0. (Not each spacing: in direct mode the client sends on
# an absolute schedule, so after a frame that a loaded machine delayed the
# next spacing is shorter, and nothing ran early.)
spacings=$(grep -m1 "^spacing_s:" "$tmp/out" | cut -d: -f2)
check "three spacings printed ($spacings)" test "$(echo $spacings | wc -w)" -eq 3
k=0 since_first=0
for s in $spacings; do
  k=$((k + 1))
  since_first=$(awk -v a="$since_first" -v b="$s" 'BEGIN { printf "%.3f", a + b }')
  check "frame $k runs $since_first s after frame 0 (>= $k x 0.25 s - 10 ms)" \
    within "$since_first" "$(awk -v k=$k 'BEGIN { print k * 0.25 - 0.01 }')" 100
done
check "the example saw the base at the GOTO goal" within "$(value x "$tmp/out")" 0.48 0.52
check "the example saw pan at 0.3" within "$(value pan "$tmp/out")" 0.29 0.31
check "the example saw tilt at -0.2" within "$(value tilt "$tmp/out")" -0.21 -0.19
if [ "$layout" = lossy ]; then
  client=$(grep -o -m1 " client=[0-9a-f]*" "$tmp/out" | cut -d= -f2)
  executed=$(grep -c "executed client $client command" "$tmp/server.log")
  distinct=$(grep -o "executed client $client command [0-9]*" "$tmp/server.log" | sort -u | wc -l)
  check "no command executed twice despite lost and doubled replies (got $executed, $distinct distinct)" \
    test "$executed" -eq "$distinct"
  # The GOTO and the four set-points ran once each (a waypoint may reach the
  # driver as a reference, not as an execution of its own: not counted).
  once=0
  for id in $(grep -o '^reply [0-9]* \(GOTO\|sequence\) ' "$tmp/out" | cut -d' ' -f2); do
    [ "$(grep -c "executed client $client command $id " "$tmp/server.log")" -eq 1 ] && once=$((once + 1))
  done
  check "the GOTO and the 4 set-points each executed once (got $once of 5)" test "$once" -eq 5
fi
# Another client (the C++ CLI) sees the same robot state.
pose=$("$cli" --url "$url" --timeout 5 query pioneer base_pose 2>&1)
check "the robot is at the goal for the CLI too ($pose)" within "$(echo "$pose" | awk '{print $(NF-4)}')" 0.48 0.52

# --- a robot nobody announces: the error lists the robots heard --------------
wait "$unknown_pid"
status=$?
check "an unknown robot exits 1 (got $status)" test "$status" -eq 1
check "the error names the robot and lists those heard" grep -q "no robot 'piooner'.*heard: pioneer" "$tmp/err2"

if [ "$failures" -ne 0 ]; then
  echo "--- client stderr"; cat "$tmp/err"; cat "$tmp/err2"
  echo "--- server log"; cat "$tmp/server.log"
fi
echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
