#!/usr/bin/env bash
# The demo itself (scripts/demo.sh runs it, in a private network namespace
# when it can): a robotalk-server with the Pioneer simulated on ODE physics,
# driven by the robotalk CLI from other processes, shown live by robotalk-web.
# Environment (set by demo.sh): ROBOTALK_DEMO_KEEP=1 keeps the server, the
# web view and a slow scripted motion running after the walkthrough until
# Ctrl-C; ROBOTALK_DEMO_HOST_NETNS_FD names an open descriptor of the
# machine's network namespace, through which scripts/demo_forward.py offers
# the page on the machine's loopback.
set -uo pipefail
BUILD_DIR=${ROBOTALK_BUILD_DIR:-build}
URL=${ROBOTALK_DEMO_URL:-"udpm://239.255.76.67:7667?ttl=0"}
KEEP=${ROBOTALK_DEMO_KEEP:-0}
MODEL=models/pioneer2dx_pantilt.urdf
server_bin=$BUILD_DIR/robotalk-server/robotalk-server
web_bin=$BUILD_DIR/tools/web/robotalk-web
py=/usr/bin/python3
[ -x "$py" ] || py=python3
# A GOTO is answered when the goal is reached: allow the slow ones 20 s.
robotalk() { "$BUILD_DIR"/robotalk-client/robotalk --url "$URL" --timeout 20 "$@"; }
step() { printf '\n\033[1m== %s\033[0m\n' "$*"; }
show() { printf '$ robotalk %s\n' "$*"; robotalk "$@"; echo "(exit status $?)"; }
# wait_for FILE PATTERN [PID]: up to 10 s for a line of FILE to match (not once PID has exited).
wait_for() {
  for _ in $(seq 100); do
    grep -q "$2" "$1" 2>/dev/null && return 0
    [ -z "${3:-}" ] || kill -0 "$3" 2>/dev/null || return 1
    sleep 0.1
  done
  return 1
}

tmp=$(mktemp -d)
pids=() server=
stop_all() {  # the motion and the web view first, the server (it stops the robot) last
  local p
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done
  for p in "${pids[@]}"; do wait "$p" 2>/dev/null; done
  [ -z "$server" ] || { kill "$server" 2>/dev/null; wait "$server" 2>/dev/null; }
  [ "$KEEP" = 1 ] && grep -h "stopping every robot" "$tmp/server.log"
  rm -rf "$tmp"
}
trap stop_all EXIT
trap 'echo; echo "Stopping: the motion, robotalk-web, then the server (it stops the robot)."; exit 0' INT TERM HUP

# Bounded unless kept: a CI run stops by itself.
duration=(--duration 120)
[ "$KEEP" = 1 ] && duration=()
"$server_bin" --robot "pioneer=ode:$MODEL" --url "$URL" "${duration[@]}" 2>"$tmp/server.log" &
server=$!
# robotalk-web on 8080 (or any free port); from inside the namespace, the
# forwarder offers it on this machine's loopback.
browser_url=
for port in "${ROBOTALK_WEB_PORT:-8080}" 0; do
  "$web_bin" --lcm-url "$URL" --port "$port" >"$tmp/web.out" 2>&1 &
  web=$!
  wait_for "$tmp/web.out" "open http" "$web" && break
  kill "$web" 2>/dev/null; wait "$web" 2>/dev/null; web=
done
if [ -n "$web" ]; then
  pids+=("$web")
  web_port=$(grep -o 'open http://[^ ]*' "$tmp/web.out" | sed 's#.*:\([0-9]*\)/$#\1#')
  browser_url="http://127.0.0.1:$web_port/"
  if [ -n "${ROBOTALK_DEMO_HOST_NETNS_FD:-}" ]; then
    "$py" scripts/demo_forward.py "$ROBOTALK_DEMO_HOST_NETNS_FD" "${ROBOTALK_WEB_PORT:-8080}" "$web_port" \
      >"$tmp/forward.out" 2>&1 &
    pids+=($!)
    if wait_for "$tmp/forward.out" '^[0-9][0-9]*$' $!; then
      browser_url="http://127.0.0.1:$(head -1 "$tmp/forward.out")/"
    else
      echo "(robotalk-web runs in the private network namespace only: $(cat "$tmp/forward.out"))"
      browser_url=
    fi
  fi
else
  echo "(robotalk-web did not start: $(cat "$tmp/web.out"))"
fi

wait_for "$tmp/server.log" "serving robot"
step "A server with one robot on ODE physics: robotalk-server --robot pioneer=ode:$MODEL"
cat "$tmp/server.log"
[ -n "$browser_url" ] && echo "Live 3D view (robotalk-web, docs/web.md): open $browser_url in a browser on this machine"

step "Which robots are announced?"
show robots
step "Its description, loaded over LCM (first lines)"
robotalk describe pioneer | head -12
step "Direct mode: point the head, then drive to (0.5, 0.5) facing +y; each call blocks until its reply"
show send pioneer joint_setpoint pan 0.5
show send pioneer joint_setpoint tilt -0.3
show send pioneer goto 0.5 0.5 1.5708
show query pioneer base_pose
show query pioneer joint_state pan
step "Errors name what was wrong"
show send pioneer joint_setpoint neck 0.1
show send pioneer joint_force pan 1.0
step "A timed sequence (examples/demo_arcs.txt) in playback mode, frames paced as a live stream,"
echo "   while another client watches the broadcast state stream (x y theta v omega every 0.5 s)"
grep -v '^#' examples/demo_arcs.txt
# The binary itself, not the robotalk function: $! is then watch's own pid,
# which the cleanup stops on Ctrl-C.
"$BUILD_DIR"/robotalk-client/robotalk --url "$URL" --timeout 20 watch pioneer --period 0.5 --duration 8 &
watcher=$!
pids+=("$watcher")
show send pioneer --file examples/demo_arcs.txt --mode playback --paced
wait $watcher
show query pioneer base_pose
step "Panic from one client: every command of every client is refused until a reset"
show panic pioneer
show send pioneer goto 0 0 0
show reset pioneer
show send pioneer goto 0 0 0
show query pioneer base_pose
step "Server log"
cat "$tmp/server.log"

[ "$KEEP" = 1 ] || exit 0
# The slow scripted motion: home, the arcs with the head following, a look
# around; again and again. Each command runs in the background so that the
# loop stops at once when it is told to (stop_all's TERM, or Ctrl-C's SIGINT
# to the whole process group: a subshell does not keep this script's INT
# trap). Its CLI is killed outright: a TERMed CLI would first wait for the
# server to acknowledge a STOP, and on Ctrl-C the server is already going;
# stop_all stops the server right after, and the server stops the robot as
# it exits.
motion() {
  trap 'kill -KILL $c 2>/dev/null; wait $c 2>/dev/null; exit 0' TERM INT HUP
  while :; do
    for cmd in "send pioneer goto 0 0 0" "send pioneer --file examples/demo_arcs.txt --mode playback --paced" \
      "send pioneer joint_setpoint tilt -0.3" "send pioneer joint_setpoint pan 0.8" \
      "send pioneer joint_setpoint pan -0.8" "send pioneer joint_setpoint tilt 0"; do
      # The binary itself, not the robotalk function: $c must be the CLI's pid,
      # not a subshell's that would leave it running when killed.
      # shellcheck disable=SC2086  # the words of cmd are the CLI's arguments
      "$BUILD_DIR"/robotalk-client/robotalk --url "$URL" --timeout 20 $cmd >/dev/null 2>&1 &
      c=$!
      wait $c
      sleep 1 &
      c=$!
      wait $c
    done
  done
}
motion 2>/dev/null &  # (no "Killed" notice when it stops its CLI)
pids=("$!" "${pids[@]}")
step "Running until Ctrl-C: the server, robotalk-web and a slow scripted motion (home, the arcs, a look around)"
if [ -n "$browser_url" ]; then
  echo "Watch it in a browser on this machine: $browser_url"
else
  echo "(no browser view; watch the state with: $BUILD_DIR/robotalk-client/robotalk --url '$URL' watch pioneer)"
fi
wait "$server"
echo "The server stopped:"
tail -3 "$tmp/server.log"
