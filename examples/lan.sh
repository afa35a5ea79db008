#!/usr/bin/env bash
# RoboTalk across several hosts, on one machine: a server host, two client
# hosts and a recording host (robotalk-logplay record), each a network namespace joined by veth pairs
# to one bridge, multicast routed to each host's veth, LCM URL with ttl=1
# (DESIGN.md §4). Everything stays inside a private network namespace (needs
# root); addresses are from a test subnet that exists only in there.
#   examples/lan.sh [BUILD_DIR]            (default build/)
# Sourced by tests/integration/lan_test.sh for lan_setup / lan_teardown.
set -u
LAN_SUBNET=${LAN_SUBNET:-10.77.0}
LAN_HOSTS=(server client1 client2 logger)
LAN_URL=${LAN_URL:-"udpm://239.255.76.67:7813?ttl=1"}

# Creates the hosts. Must run inside `unshare -n -m` (a private network and mount namespace).
lan_setup() {
  mkdir -p /run/netns && mount -t tmpfs lan-netns /run/netns || return 1  # namespaces stay private
  ip link set lo up
  ip link add lanbr0 type bridge mcast_snooping 0 || return 1
  ip link set lanbr0 up
  local i=1 h
  for h in "${LAN_HOSTS[@]}"; do
    ip netns add "$h" || return 1
    ip link add "v-$h" type veth peer name eth0 netns "$h" || return 1
    ip link set "v-$h" master lanbr0 up
    ip -n "$h" link set lo up
    ip -n "$h" addr add "$LAN_SUBNET.$i/24" dev eth0
    ip -n "$h" link set eth0 up
    ip -n "$h" route add 224.0.0.0/4 dev eth0   # LCM multicast leaves through the veth
    i=$((i + 1))
  done
}

lan_teardown() {
  local h
  for h in "${LAN_HOSTS[@]}"; do ip netns pids "$h" 2>/dev/null | xargs -r kill 2>/dev/null; done
  sleep 0.2
  for h in "${LAN_HOSTS[@]}"; do ip netns del "$h" 2>/dev/null; done
}

on() { local h=$1; shift; ip netns exec "$h" "$@"; }  # on HOST COMMAND...

lan_demo() {
  local build=$1 models=$2 tmp
  tmp=$(mktemp -d)
  lan_setup || { echo "lan.sh: cannot create the hosts (needs root)"; return 1; }
  on server "$build/robotalk-server/robotalk-server" --url "$LAN_URL" --duration 60 \
    --robot "pioneer=kinematic:$models/pioneer2dx_pantilt.urdf" \
    --robot "pioneer2=kinematic:$models/pioneer2dx_pantilt.urdf" 2>"$tmp/server.log" &
  # Every lane of the split traffic layout into one log (lcm-logger hears one URL).
  on logger "$build/tools/logplay/robotalk-logplay" record -o "$tmp/lan.lcmlog" --lcm-url "$LAN_URL" \
    -c 'ROBOTALK/.*' &
  sleep 1.5
  echo "== client1 ($LAN_SUBNET.2): robotalk robots"
  on client1 "$build/robotalk-client/robotalk" --url "$LAN_URL" robots --listen 1.2
  on client2 "$build/robotalk-client/robotalk" --url "$LAN_URL" watch pioneer --period 0.5 --duration 4 &
  echo "== client1: a sequence; client2 watches"
  printf '0 setspeed 0.3 0\n0 joint_setpoint pan 0.4\n1 setspeed 0.3 0.5\n2 setspeed 0.2 -0.5\n3 stop\n' >"$tmp/seq.txt"
  on client1 "$build/robotalk-client/robotalk" --url "$LAN_URL" send pioneer --file "$tmp/seq.txt"
  wait %3 2>/dev/null
  ip netns pids logger | xargs -r kill -INT
  sleep 0.5
  echo "== the log (from $LAN_SUBNET.4)"
  "$build/tools/logplay/robotalk-logplay" info "$tmp/lan.lcmlog"
  echo "== client2: replay onto pioneer2"
  on client2 "$build/tools/logplay/robotalk-logplay" replay "$tmp/lan.lcmlog" --robot pioneer2 --from pioneer \
    --url "$LAN_URL" --no-progress
  lan_teardown
  rm -rf "$tmp"
}

if [ "${BASH_SOURCE[0]}" = "$0" ]; then
  here=$(cd "$(dirname "$0")" && pwd)
  build=$(cd "${1:-$here/../build}" && pwd)
  if [ -z "${LAN_INNER:-}" ]; then
    LAN_INNER=1 exec unshare -n -m "$0" "$build"
  fi
  lan_demo "$build" "$here/../models"
fi
