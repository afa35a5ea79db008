#!/usr/bin/env bash
# The demo itself (scripts/demo.sh runs it, in a private network namespace
# when it can): a robotalk-server with the Pioneer simulated on ODE physics,
# driven by the robotalk CLI from other processes.
set -uo pipefail
BUILD_DIR=${ROBOTALK_BUILD_DIR:-build}
URL=${ROBOTALK_DEMO_URL:-"udpm://239.255.76.67:7667?ttl=0"}
MODEL=models/pioneer2dx_pantilt.urdf
server_bin=$BUILD_DIR/robotalk-server/robotalk-server
# A GOTO is answered when the goal is reached: allow the slow ones 20 s.
robotalk() { "$BUILD_DIR"/robotalk-client/robotalk --url "$URL" --timeout 20 "$@"; }
step() { printf '\n\033[1m== %s\033[0m\n' "$*"; }
show() { printf '$ robotalk %s\n' "$*"; robotalk "$@"; echo "(exit status $?)"; }

log=$(mktemp)
"$server_bin" --robot "pioneer=ode:$MODEL" --url "$URL" --duration 120 2>"$log" &
server=$!
web_pid=; if [ -x "$BUILD_DIR/tools/web/robotalk-web" ]; then "$BUILD_DIR/tools/web/robotalk-web" --lcm-url "$URL" --port "${ROBOTALK_WEB_PORT:-8080}" >/dev/null 2>&1 & web_pid=$!; echo "Live 3D view (robotalk-web, docs/web.md): open http://127.0.0.1:${ROBOTALK_WEB_PORT:-8080}/ (from a browser on this machine: ROBOTALK_DEMO_NETNS=0 scripts/demo.sh)"; fi
trap 'kill $server $web_pid 2>/dev/null; wait $server 2>/dev/null; rm -f "$log"' EXIT
for _ in $(seq 50); do grep -q "serving robot" "$log" && break; sleep 0.1; done
step "A server with one robot on ODE physics: robotalk-server --robot pioneer=ode:$MODEL"
cat "$log"

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
robotalk watch pioneer --period 0.5 --duration 8 &
watcher=$!
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
cat "$log"
