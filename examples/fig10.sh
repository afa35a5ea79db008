#!/usr/bin/env bash
# The RoboTalk paper's Fig. 10 on physics: one robotalk-server simulates the
# demo Pioneer and the simple humanoid with the ode driver; the same sequence
# file (examples/fig10_goto_with_head.txt) is sent to both, only the robot
# name changing. Prints every reply and both robots' final base poses.
#
#   examples/fig10.sh            (from the repository root, after building)
# Environment: ROBOTALK_BUILD_DIR (default build), ROBOTALK_SERVER (default
# $ROBOTALK_BUILD_DIR/robotalk-server/robotalk-server), ROBOTALK_URL. Run it
# inside a private network namespace (scripts/netns_run.sh) when the host's
# multicast should not be used.
set -euo pipefail
BUILD_DIR=${ROBOTALK_BUILD_DIR:-build}
SERVER=${ROBOTALK_SERVER:-$BUILD_DIR/robotalk-server/robotalk-server}
CLIENT=$BUILD_DIR/robotalk-client/robotalk
URL=${ROBOTALK_URL:-"udpm://239.255.76.67:7671?ttl=0"}
SEQ=examples/fig10_goto_with_head.txt
robotalk() { "$CLIENT" --url "$URL" --timeout 30 "$@"; }

log=$(mktemp)
"$SERVER" --url "$URL" --duration 120 \
  --robot "pioneer=ode:models/pioneer2dx_pantilt.urdf" \
  --robot "humanoid=ode:models/simple_humanoid.urdf" 2>"$log" &
server=$!
trap 'kill $server 2>/dev/null; wait $server 2>/dev/null; rm -f "$log"' EXIT
for _ in $(seq 100); do [ "$(grep -c "serving robot" "$log")" -ge 2 ] && break; sleep 0.1; done
cat "$log"

status=0
for robot in pioneer humanoid; do
  echo "== robotalk send $robot --file $SEQ"
  robotalk send "$robot" --file "$SEQ" >"$log.$robot" 2>&1 &
done
wait %2 || status=1
wait %3 || status=1
for robot in pioneer humanoid; do
  echo "== $robot replies"
  cat "$log.$robot"
  rm -f "$log.$robot"
  echo "== $robot base pose (x y theta v omega)"
  robotalk query "$robot" base_pose || status=1
done
exit $status
