#!/usr/bin/env bash
# robotalk-ros2's cost (issue 25 item 5, docs/performance.md "ROS 2 bridge"):
# per stream rate, the latency a JointState adds over the STATE stream it
# comes from, and the bridge's CPU beside a plain client reading the same
# stream (robotalk watch, the floor). Run inside a private network namespace:
#   scripts/netns_run.sh tests/ros2/bench_ros2.sh [BUILD_DIR] [SECONDS]
# ros2_peer measures both latencies in one process on one clock: LCM = STATE
# received - its server sample time; DDS = JointState received - the same
# sample time (its header.stamp). Their difference is what the bridge and the
# DDS hop add.
set -u
build=${1:-build}; secs=${2:-10}
root=$(cd "$(dirname "$0")/../.." && pwd)
export LCM_DEFAULT_URL="udpm://239.255.76.67:7854?ttl=0"
export CYCLONEDDS_URI="file://$root/tests/ros2/cyclonedds_loopback.xml"
export ROS_DOMAIN_ID=26
tick=$(getconf CLK_TCK)
cpu() { awk '{print $14 + $15}' "/proc/$1/stat"; }

run() {  # run HZ
  local hz=$1 period_ms=$((1000 / $1))
  "$build/robotalk-server/robotalk-server" --robot "pioneer=kinematic:$root/models/pioneer2dx_pantilt.urdf" 2>/dev/null &
  local server=$!
  sleep 1
  local stats; stats=$(mktemp)
  "$build/robotalk-ros2/robotalk-ros2" --robot pioneer --rate "$hz" --duration $((secs + 6)) --stats >"$stats" 2>/dev/null &
  local bridge=$!
  "$build/robotalk-client/robotalk" watch pioneer --period "$(awk -v p="$period_ms" 'BEGIN { printf "%.3f", p / 1000 }')" \
    >/dev/null 2>&1 &
  local watch=$!
  sleep 2
  local c0 w0; c0=$(cpu $bridge); w0=$(cpu $watch)
  "$build/tests/ros2/ros2_peer" measure pioneer --seconds "$secs" --period-ms "$period_ms" | grep -v "^ok:" |
    sed "s/^/$hz Hz: /"
  local c1 w1; c1=$(cpu $bridge); w1=$(cpu $watch)
  awk -v h="$hz" -v b="$((c1 - c0))" -v w="$((w1 - w0))" -v t="$tick" -v s="$((secs + 1))" \
    'BEGIN { printf "%s Hz: CPU (%% of one core): robotalk-ros2 %.1f, robotalk watch of the same stream %.1f\n", h, 100 * b / t / s, 100 * w / t / s }'
  wait $bridge
  sed "s/^/$hz Hz: /" "$stats"
  kill $watch $server 2>/dev/null
  wait 2>/dev/null
  rm -f "$stats"
}
run 100
run 1000
