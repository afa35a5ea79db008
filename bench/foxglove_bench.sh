#!/usr/bin/env bash
# The Foxglove endpoint's added latency and CPU (docs/performance.md,
# "Foxglove endpoint"), in one run per stream rate: a kinematic Pioneer,
# robotalk-web at --rate 100 (it asks for the state stream at 100 Hz; for the
# 1 kHz stream another client, robotalk watch --period 0.001, asks for it and
# the bridge decimates to 100 Hz), one Foxglove client
# subscribed to the robot's five channels (foxglove_bench.mjs), and beside it
# the floor: the same STATE stream's latency on LCM
# (robotalk-bench-state-latency). Both measure arrival minus the sample's
# server time on CLOCK_MONOTONIC. Run inside a private network namespace:
#   scripts/netns_run.sh bench/foxglove_bench.sh [BUILD_DIR] [SECONDS]
# RT="chrt -f 5" in the environment runs the bridge, the Foxglove client and
# the LCM floor listener under SCHED_FIFO (root), as the server's daemons
# run: on a loaded machine, this separates the path's own latency from the
# scheduler's wait for a core.
set -u
rt=${RT:-}
build=${1:-build}; secs=${2:-10}
root=$(cd "$(dirname "$0")/.." && pwd)
url="udpm://239.255.76.67:7861?ttl=0"
tick=$(getconf CLK_TCK)
cpu() { awk '{print $14 + $15}' "/proc/$1/stat"; }
run() {  # run STREAM_HZ
  "$build/robotalk-server/robotalk-server" --robot "pioneer=kinematic:$root/models/pioneer2dx_pantilt.urdf" \
    --url "$url" --duration $((secs + 20)) 2>/dev/null &
  local server=$!
  local out; out=$(mktemp)
  $rt "$build/tools/web/robotalk-web" --port 0 --lcm-url "$url" --rate 100 >"$out" 2>&1 &
  local web=$!
  local port=""
  for _ in $(seq 50); do port=$(grep -o '127.0.0.1:[0-9]*' "$out" | cut -d: -f2); [ -n "$port" ] && break; sleep 0.1; done
  local watch=""
  if [ "$1" != 100 ]; then
    "$build/robotalk-client/robotalk" --url "$url" watch pioneer --period "$(awk -v r="$1" 'BEGIN{print 1/r}')" >/dev/null 2>&1 &
    watch=$!
  fi
  local fox; fox=$(mktemp)
  $rt node "$root/bench/foxglove_bench.mjs" "$port" pioneer "$secs" >"$fox" &
  local node_pid=$!
  sleep 3  # connect, subscribe, stream
  local floor; floor=$(mktemp)
  $rt "$build/bench/robotalk-bench-state-latency" --url "$url" --robot pioneer --seconds "$((secs - 3))" >"$floor" &
  local c0; c0=$(cpu "$web")
  sleep "$((secs - 3))"
  local c1; c1=$(cpu "$web")
  wait "$node_pid"
  sleep 0.5
  echo "{\"stream_hz\": $1, \"bridge_rate_hz\": 100, \"bridge_cpu_percent\": $(awk -v c="$((c1 - c0))" -v t="$tick" -v s="$((secs - 3))" 'BEGIN{printf "%.1f", 100*c/t/s}'), \"foxglove\": $(cat "$fox"), \"lcm\": $(cat "$floor")}"
  kill "$web" "$server" $watch 2>/dev/null
  wait 2>/dev/null
  rm -f "$out" "$fox" "$floor"
}
run 100
run 1000
