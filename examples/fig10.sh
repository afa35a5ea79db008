#!/usr/bin/env bash
# The RoboTalk paper's Fig. 10 on physics: one robotalk-server simulates the
# demo Pioneer and the simple humanoid with the ode driver, the humanoid
# walking on its own legs (walk=true: docs/ode_sim.md, "Walking"); the same
# sequence file (examples/fig10_goto_with_head.txt) is sent to both, only the
# robot name changing. Prints every reply and both robots' final base poses,
# records both paths from the STATE stream (robotalk watch) and, with
# python3-matplotlib, plots them (FIG10_PLOT, default docs/figures/fig10_paths.png).
# Takes about 3 minutes (the humanoid walks each 1 m leg in 15-25 s).
#
#   examples/fig10.sh            (from the repository root, after building)
# Environment: ROBOTALK_BUILD_DIR (default build), ROBOTALK_SERVER (default
# $ROBOTALK_BUILD_DIR/robotalk-server/robotalk-server), ROBOTALK_URL, FIG10_PLOT.
# Run it inside a private network namespace (scripts/netns_run.sh) when the
# host's multicast should not be used.
set -euo pipefail
BUILD_DIR=${ROBOTALK_BUILD_DIR:-build}
SERVER=${ROBOTALK_SERVER:-$BUILD_DIR/robotalk-server/robotalk-server}
CLIENT=$BUILD_DIR/robotalk-client/robotalk
URL=${ROBOTALK_URL:-"udpm://239.255.76.67:7671?ttl=0"}
SEQ=examples/fig10_goto_with_head.txt
PLOT=${FIG10_PLOT:-docs/figures/fig10_paths.png}
robotalk() { "$CLIENT" --url "$URL" --timeout 30 "$@"; }

log=$(mktemp)
"$SERVER" --url "$URL" --duration 220 \
  --robot "pioneer=ode:models/pioneer2dx_pantilt.urdf" \
  --robot "humanoid=ode:models/simple_humanoid.urdf,walk=true" 2>"$log" &
server=$!
trap 'kill $server 2>/dev/null; wait $server 2>/dev/null; rm -f "$log" "$log".*' EXIT
for _ in $(seq 100); do [ "$(grep -c "serving robot" "$log")" -ge 2 ] && break; sleep 0.1; done
cat "$log"

status=0
watchers=() senders=()
for robot in pioneer humanoid; do  # the paths, every 0.2 s, while the sequence runs
  robotalk watch "$robot" --period 0.2 --duration 180 >"$log.$robot.path" 2>/dev/null &
  watchers+=($!)
done
for robot in pioneer humanoid; do
  echo "== robotalk send $robot --file $SEQ"
  robotalk send "$robot" --file "$SEQ" >"$log.$robot" 2>&1 &
  senders+=($!)
done
for pid in "${senders[@]}"; do wait "$pid" || status=1; done
for pid in "${watchers[@]}"; do wait "$pid" || true; done
for robot in pioneer humanoid; do
  echo "== $robot replies"
  cat "$log.$robot"
  echo "== $robot base pose (x y theta v omega)"
  robotalk query "$robot" base_pose || status=1
done
PY=python3
[ -x /usr/bin/python3 ] && PY=/usr/bin/python3  # Debian's, where python3-matplotlib lives
if "$PY" -c 'import matplotlib' 2>/dev/null; then
  mkdir -p "$(dirname "$PLOT")"
  "$PY" scripts/plot_walk.py --paths "$PLOT" "pioneer=$log.pioneer.path" "humanoid=$log.humanoid.path" &&
    echo "paths: $PLOT"
fi
exit $status
