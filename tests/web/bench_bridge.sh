#!/usr/bin/env bash
# Prints robotalk-web's CPU use while it decimates a state stream, and what
# it pushes to one page (a curl WebSocket reader stands in for the browser).
# Run inside a private network namespace:
#   scripts/netns_run.sh tests/web/bench_bridge.sh [BUILD_DIR] [SECONDS]
# Two runs: the stream at the bridge's own 30 Hz, and at 1 kHz because another
# client (robotalk watch --period 0.001) asks for it.
set -u
build=${1:-build}; secs=${2:-10}
root=$(cd "$(dirname "$0")/../.." && pwd)
export LCM_DEFAULT_URL="udpm://239.255.76.67:7853?ttl=0"
tick=$(getconf CLK_TCK)
cpu() { awk '{print $14 + $15}' "/proc/$1/stat"; }

run() {  # run LABEL WATCH_PERIOD(or "")
  "$build/robotalk-server/robotalk-server" --robot "pioneer=ode:$root/models/pioneer2dx_pantilt.urdf" 2>/dev/null &
  local server=$!
  local out; out=$(mktemp)
  "$build/tools/web/robotalk-web" --port 0 >"$out" 2>&1 &
  local web=$!
  local port=""
  for _ in $(seq 50); do port=$(grep -o '127.0.0.1:[0-9]*' "$out" | cut -d: -f2); [ -n "$port" ] && break; sleep 0.1; done
  local watch="" samples; samples=$(mktemp)
  if [ -n "$2" ]; then "$build/robotalk-client/robotalk" watch pioneer --period "$2" >"$samples" 2>/dev/null & watch=$!; fi
  local frames; frames=$(mktemp)
  curl -s -N --max-time $((secs + 4)) -H "Connection: Upgrade" -H "Upgrade: websocket" -H "Sec-WebSocket-Version: 13" \
    -H "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==" "http://127.0.0.1:$port/ws" -o "$frames" &
  local reader=$!
  sleep 3  # connect, load the model, start the streams
  local c0; c0=$(cpu $web); local n0; n0=$(grep -a -o '"type":"state"' "$frames" | wc -l); local s0; s0=$(wc -l <"$samples")
  sleep "$secs"
  local c1; c1=$(cpu $web); local n1; n1=$(grep -a -o '"type":"state"' "$frames" | wc -l); local s1; s1=$(wc -l <"$samples")
  awk -v l="$1" -v c="$((c1 - c0))" -v n="$((n1 - n0))" -v t="$tick" -v s="$secs" -v w="$((s1 - s0))" \
    'BEGIN { printf "%-36s bridge CPU %5.1f %% of one core, %5.1f state frames/s to the page", l, 100 * c / t / s, n / s
             if (w > 0) printf ", stream measured by the watch: %.0f samples/s", w / s
             printf "\n" }'
  kill $reader $web $server $watch 2>/dev/null
  wait 2>/dev/null
  rm -f "$out" "$frames" "$samples"
}
run "stream at 30 Hz (the bridge's own)" ""
run "stream at 1 kHz (robotalk watch)" 0.001
