#!/usr/bin/env bash
# robotalk-spy under Xvfb against a running server (kinematic Pioneer) with a
# client streaming state: lcm-spy must find our types ("Found N LCM types",
# N >= the number of robotalk_msgs types) and shows the channels; a
# screenshot is saved for a person to look at. Runs inside a private network
# namespace (CTest wraps it with netns_run.sh).
#   spy_test.sh SPY SERVER CLI MODELS_DIR NUM_TYPES OUT.png
set -u
spy=$1 server_bin=$2 cli=$3 models=$4 num_types=$5 out_png=$6
here=$(cd "$(dirname "$0")" && pwd)
url="udpm://239.255.76.67:7812?ttl=0"
py=/usr/bin/python3; [ -x "$py" ] || py=python3  # Debian's, with python3-matplotlib
for tool in Xvfb xwd java "$py"; do
  command -v "$tool" >/dev/null || { echo "SKIP: $tool not installed (scripts/setup.sh installs it)"; exit 77; }
done
[ -x "$spy" ] || { echo "SKIP: robotalk-spy was not built (no robotalk_lcmtypes.jar)"; exit 77; }
. "$(dirname "$0")/../lib.sh"

display=":$((100 + $$ % 400))"
Xvfb "$display" -screen 0 1100x560x24 -nolisten tcp >"$tmp/xvfb.log" 2>&1 &
pids+=($!)
"$server_bin" --robot "pioneer=kinematic:$models/pioneer2dx_pantilt.urdf" --url "$url" --duration 60 \
  2>"$tmp/server.log" &
pids+=($!)
wait_for "$tmp/server.log" "serving robot"

DISPLAY=$display "$spy" --url "$url" >"$tmp/spy.out" 2>&1 &
pids+=($!)
found=""
for _ in $(seq 200); do
  found=$(grep -o "Found [0-9]* LCM types" "$tmp/spy.out" | head -1)
  [ -n "$found" ] && break
  sleep 0.1
done
echo "lcm-spy: ${found:-nothing}"
n=$(echo "$found" | awk '{print $2}')
check "lcm-spy found our $num_types types (${found:-no line})" test "${n:-0}" -ge "$num_types"
# Nor an error on start-up (issue 21: five IllegalAccessError / NoClassDefFoundError
# lines from jars lcm-spy should not have scanned).
check "no Java exception or error" bash -c "! grep -qE 'Exception|Error' '$tmp/spy.out'"

# Traffic on every RoboTalk channel (once the window is up and subscribed);
# with the split traffic layout the spy on the main URL sees ANNOUNCE, CONFIG
# and STATE, while REQUEST and REPLY travel on their own ports.
sleep 2
"$cli" --url "$url" watch pioneer --period 0.1 --duration 8 >/dev/null 2>&1 &
pids+=($!)
sleep 1
"$cli" --url "$url" send pioneer setspeed 0.2 0.3 >/dev/null 2>&1
"$cli" --url "$url" send pioneer joint_setpoint pan 0.5 >/dev/null 2>&1
"$cli" --url "$url" describe pioneer >/dev/null 2>&1
sleep 3
xwd -root -silent -display "$display" >"$tmp/spy.xwd"
check "xwd took a screenshot" test -s "$tmp/spy.xwd"
"$py" "$here/xwd_to_png.py" "$tmp/spy.xwd" "$out_png"
check "the screenshot is a PNG ($out_png)" test -s "$out_png"
check "lcm-spy is still running" kill -0 "${pids[2]}"

echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
