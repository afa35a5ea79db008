#!/usr/bin/env bash
# Many hosts on one machine (DESIGN.md §4): a server host, two client hosts and
# a recording host (robotalk-logplay record), network namespaces joined by veth pairs to a bridge,
# multicast TTL 1 (examples/lan.sh sets them up). Everything works as on one
# host, and the recorded log replays with robotalk-logplay.
#   lan_test.sh SERVER CLI LOGPLAY MODELS_DIR
set -u
server_bin=$1 cli=$2 logplay=$3 models=$4
here=$(cd "$(dirname "$0")" && pwd)
if [ -z "${LAN_INNER:-}" ]; then
  unshare -n -m true 2>/dev/null || { echo "SKIP: cannot create network namespaces here (needs root)"; exit 77; }
  LAN_INNER=1 exec unshare -n -m "$0" "$@"
fi
# shellcheck source=../../examples/lan.sh
. "$here/../../examples/lan.sh"
. "$here/../lib.sh"  # $tmp, check, $pass, $failures
trap 'lan_teardown; cleanup' EXIT
lan_setup || { echo "FAIL: could not create the hosts"; exit 1; }
rt() { local h=$1; shift; on "$h" "$cli" --url "$LAN_URL" "$@"; }

on server "$server_bin" --url "$LAN_URL" --duration 90 \
  --robot "pioneer=kinematic:$models/pioneer2dx_pantilt.urdf" \
  --robot "pioneer2=kinematic:$models/pioneer2dx_pantilt.urdf" 2>"$tmp/server.log" &
# Every lane of the split traffic layout into one log (lcm-logger hears one URL).
on logger "$logplay" record -o "$tmp/lan.lcmlog" --lcm-url "$LAN_URL" -c 'ROBOTALK/.*' 2>"$tmp/record.log" &
recorder=$!
for _ in $(seq 50); do [ "$(grep -c "serving robot" "$tmp/server.log")" -ge 2 ] && break; sleep 0.1; done

check "the hosts have their own addresses" bash -c "ip -n client1 -4 addr show eth0 | grep -q '$LAN_SUBNET.2/24'"
rt client1 robots --listen 1.2 >"$tmp/robots" 2>&1
check "client1 hears both robots of the server host" test "$(grep -c '^pioneer' "$tmp/robots")" -eq 2
# A client whose URL says ttl=0 hears the server (which sends with ttl=1), but
# its own requests never leave its host.
on client2 "$cli" --url "${LAN_URL%ttl=1}ttl=0" --timeout 1.5 query pioneer base_pose >"$tmp/ttl0" 2>&1
check "with ttl=0 a request does not cross to another host: $(cat "$tmp/ttl0")" grep -q "no answer to HELLO" "$tmp/ttl0"
rt client1 describe pioneer >"$tmp/describe" 2>&1
check "describe across hosts" grep -q "tilt" "$tmp/describe"

rt client2 watch pioneer --period 0.1 --duration 5 >"$tmp/watch" 2>&1 &
watcher=$!
printf '0 setspeed 0.3 0\n0 joint_setpoint pan 0.4\n1 setspeed 0.3 0.5\n2 setspeed 0.2 -0.5\n3 stop\n' >"$tmp/seq.txt"
sleep 0.5
rt client1 send pioneer --file "$tmp/seq.txt" >"$tmp/send" 2>&1
check "client1's sequence succeeds" test "$(grep -c SUCCESS "$tmp/send")" -eq 5
rt client2 send pioneer2 joint_setpoint tilt -0.2 >"$tmp/tilt2" 2>&1
check "client2 commands the other robot meanwhile" grep -q SUCCESS "$tmp/tilt2"
wait "$watcher"
check "client2 watched client1's motion" awk '/base/ { if ($4 + 0 > 0.3) moved = 1 } END { exit !moved }' "$tmp/watch"
read -r x0 y0 th0 < <(rt client2 query pioneer base_pose | awk '{print $(NF-4), $(NF-3), $(NF-2)}')
sleep 0.3
ip netns pids logger | xargs -r kill -INT
wait "$recorder"
check "the recorder stops on SIGINT with status 0: $(cat "$tmp/record.log")" test $? -eq 0

"$logplay" info "$tmp/lan.lcmlog" >"$tmp/info" 2>&1
check "the logger host recorded client1's stream" grep -q "commands 5 in mode delay: JOINT_SETPOINT 1 SETSPEED 3 STOP 1" "$tmp/info"
check "the logger host recorded client2's watch" grep -q "^state pioneer:" "$tmp/info"
rt client2 stop >/dev/null 2>&1
on client2 "$logplay" replay "$tmp/lan.lcmlog" --robot pioneer2 --from pioneer --url "$LAN_URL" --no-progress \
  >"$tmp/replay" 2>&1
check "the log replays onto pioneer2 from another host" grep -q "replayed 5/5 commands onto 'pioneer2'.*SUCCESS 5" "$tmp/replay"
sleep 0.3
read -r x1 y1 th1 < <(rt client1 query pioneer2 base_pose | awk '{print $(NF-4), $(NF-3), $(NF-2)}')
echo "pioneer  ended at x $x0 y $y0 theta $th0"
echo "pioneer2 ended at x $x1 y $y1 theta $th1"
check "the replay ends where the recording did (1 cm, 0.01 rad)" awk -v a="$x0 $y0 $th0" -v b="$x1 $y1 $th1" \
  'BEGIN { split(a, p); split(b, q); for (i = 1; i <= 3; i++) { d = p[i] - q[i]; if (d < 0) d = -d; if (d > 0.01) exit 1 } }'

echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
