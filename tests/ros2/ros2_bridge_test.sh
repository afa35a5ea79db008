#!/usr/bin/env bash
# robotalk-ros2 end to end (issue 25 item 4): a keyed server, the bridge with
# its own key, and the tests' own DDS program (ros2_peer, built from the same
# IDL) as the ROS 2 side. Runs inside a private network namespace (CTest wraps
# it with scripts/netns_run.sh); Cyclone DDS is bound to lo there by an
# explicit configuration (CYCLONEDDS_URI), so no DDS or LCM traffic leaves it.
#   ros2_bridge_test.sh SERVER KEYGEN BRIDGE PEER MODELS_DIR FORGE
set -u
server_bin=$1 keygen=$2 bridge=$3 peer=$4 models=$5 forge=$6
url="udpm://239.255.76.67:7625?ttl=0"
. "$(dirname "$0")/../lib.sh"  # $tmp, $server_pid, pids, check
export CYCLONEDDS_URI="file://$(cd "$(dirname "$0")" && pwd)/cyclonedds_loopback.xml"
export ROS_DOMAIN_ID=25

for who in server bridge peer; do "$keygen" --out "$tmp/$who" --name "$who" >/dev/null; done
{
  echo "$(cat "$tmp/bridge.pub") *=all"
  echo "$(cat "$tmp/peer.pub") *=query"
} >"$tmp/clients"
chmod 644 "$tmp/clients"

start_pioneer "$tmp/server.log" --url "$url" --key "$tmp/server" --clients "$tmp/clients" --duration 60

"$bridge" --robot pioneer --url "$url" --key "$tmp/bridge" --duration 40 >"$tmp/bridge.out" 2>"$tmp/bridge.log" &
bridge_pid=$!
pids+=("$bridge_pid")
wait_for "$tmp/bridge.log" "bridged" 100
check "the bridge connects with its key: $(cat "$tmp/bridge.log")" grep -q "robot 'pioneer' bridged (DDS domain 25)" "$tmp/bridge.log"

peer_checks() {  # peer_checks MODE WHAT: ros2_peer MODE's own checks, printed, must all pass
  "$peer" "$1" pioneer --url "$url" --key "$tmp/peer" >"$tmp/peer_$1.out" 2>&1
  local status=$?
  cat "$tmp/peer_$1.out"
  check "$2 (ros2_peer $1: status $status)" test "$status" -eq 0
}

peer_checks check "joint states, tf and the robot description follow the robot; a trajectory runs on time"
check "the bridge says when the trajectory starts: $(grep trajectory "$tmp/bridge.log")" \
  grep -q "robot 'pioneer': trajectory of 3 points starts in 0\.[3-6][0-9]* s, 6 JOINT_SETPOINTs" "$tmp/bridge.log"
peer_checks bad_trajectory "a bad trajectory moves nothing"
check "and the bridge says why: $(grep refused "$tmp/bridge.log")" \
  grep -q "robot 'pioneer': trajectory refused: JointTrajectory: joint_names\[0\] 'nek': robot 'pioneer' has no joint" "$tmp/bridge.log"

# cmd_vel drives the base; a silent cmd_vel stops it (a dead teleop).
peer_checks cmd_vel "cmd_vel drives the base, and a silent cmd_vel stops it"
check "the bridge says it stopped the base: $(grep cmd_vel "$tmp/bridge.log")" \
  grep -q "robot 'pioneer': no cmd_vel for 0.5.* s: SETSPEED 0" "$tmp/bridge.log"

# A flood of cmd_vel the bridge refuses (not finite): each refusal was a line
# of its own (review8: 2,000 lines); now the bridge's log is rate-limited as
# the server's (robotalk/log_limiter.h), counted below once the bridge stops.
peer_checks cmd_vel_flood "2,000 refused cmd_vel move nothing"

# The bridge's own lines only (Cyclone DDS may log on the same stderr).
unexpected=$(grep "^robotalk-ros2:" "$tmp/bridge.log" |
  grep -v -e bridged -e "trajectory of" -e "trajectory refused" -e "no cmd_vel" -e "cmd_vel refused" \
    -e "log lines suppressed")
check "no command was refused: $unexpected" test -z "$unexpected"

# stop_bridge SIGNAL PID LOG: the signal stops the bridge: it sends STOP to
# the robot the bridge set moving, and the bridge exits 0.
stop_bridge() {
  kill -"$1" "$2"
  wait "$2"
  local status=$?
  check "the bridge exits 0 on SIG$1 (status $status)" test "$status" -eq 0
  check "and sends STOP to the robot it set moving: $(tail -1 "$3")" \
    grep -q "robot 'pioneer': STOP on shutdown: SUCCESS" "$3"
}
stop_bridge INT "$bridge_pid" "$tmp/bridge.log"
refused_lines=$(grep -c "cmd_vel refused" "$tmp/bridge.log")
echo "2,000 refused cmd_vel: $refused_lines lines name them; $(grep -c "suppressed" "$tmp/bridge.log") per-second summaries"
check "a flood of 2,000 refused cmd_vel logs at most 100 lines ($refused_lines)" test "$refused_lines" -le 100
check "and counts what it did not print: $(grep -e "suppressed" -e "cmd_vel refused.*repeated" "$tmp/bridge.log" | head -3)" \
  grep -q -e "log lines suppressed" -e "cmd_vel refused.*(repeated [0-9]* times" "$tmp/bridge.log"

# A bridge whose queue on the server is full (its own trajectory, seconds
# ahead, past --max-queue): the cmd_vel timeout's SETSPEED 0 is refused
# ("command not queued"), so the bridge escalates to STOP and says so.
url2="udpm://239.255.76.67:7626?ttl=0"
"$server_bin" --robot "pioneer=kinematic:$models/pioneer2dx_pantilt.urdf" --url "$url2" --max-queue 8 \
  --key "$tmp/server" --clients "$tmp/clients" --duration 30 2>"$tmp/server2.log" &
pids+=("$!")
wait_for "$tmp/server2.log" "serving robot"
"$bridge" --robot pioneer --url "$url2" --key "$tmp/bridge" --duration 20 >"$tmp/bridge2.out" 2>"$tmp/bridge2.log" &
bridge2_pid=$!
pids+=("$bridge2_pid")
wait_for "$tmp/bridge2.log" "bridged" 100
url_saved=$url url=$url2
peer_checks cmd_vel_full_queue "with its queue full, the bridge still stops a base whose cmd_vel fell silent"
url=$url_saved
check "the bridge says the SETSPEED 0 was refused and it sent STOP: $(grep -e cmd_vel -e STOP "$tmp/bridge2.log")" \
  grep -q "robot 'pioneer': SETSPEED 0 (cmd_vel timeout) was not executed.*: STOP" "$tmp/bridge2.log"
stop_bridge TERM "$bridge2_pid" "$tmp/bridge2.log"  # SIGTERM too

# A bridge whose stderr takes nothing (a pipe that is full and never read, a
# terminal stopped with Ctrl-S): the cmd_vel timeout's stop logs first ("no
# cmd_vel ...: SETSPEED 0"); it waited for stderr and the base drove on, the
# bridge's heartbeats keeping its session (and so the server's watchdog)
# alive. Its lines wait for stderr at most 0.2 s now.
url3="udpm://239.255.76.67:7630?ttl=0"
"$server_bin" --robot "pioneer=kinematic:$models/pioneer2dx_pantilt.urdf" --url "$url3" \
  --key "$tmp/server" --clients "$tmp/clients" --duration 30 2>"$tmp/server3.log" &
pids+=("$!")
for _ in $(seq 50); do grep -q "serving robot" "$tmp/server3.log" 2>/dev/null && break; sleep 0.1; done
mkfifo "$tmp/full"
sleep 1000 <"$tmp/full" &  # holds the read end, reads nothing
pids+=($!)
exec 3>"$tmp/full"
head -c 65536 /dev/zero >&3  # the pipe's capacity: full
"$bridge" --robot pioneer --url "$url3" --key "$tmp/bridge" --duration 20 >"$tmp/bridge3.out" 2>&3 &
bridge3_pid=$!
pids+=("$bridge3_pid")
exec 3>&-
sleep 2  # it connects (its "bridged" line waits for a stderr that takes nothing)
url_saved=$url url=$url3
peer_checks cmd_vel "with a stderr that takes nothing, the bridge still stops a base whose cmd_vel fell silent"
url=$url_saved
kill -TERM "$bridge3_pid"
for _ in $(seq 100); do kill -0 "$bridge3_pid" 2>/dev/null || break; sleep 0.1; done
check "and it ends on SIGTERM within 10 s" sh -c "! kill -0 $bridge3_pid 2>/dev/null"
kill -9 "$bridge3_pid" 2>/dev/null

# Its other lines, written directly before: a start-up error (the bridge's
# own, or Cyclone DDS's about its configuration) with a stderr that takes
# nothing never ended it; --stats with a stdout that takes nothing held it
# after its shutdown's STOPs, its sessions alive. They now wait at most
# 0.2 s each (one LogWriter per descriptor), and the bridge exits.
"$bridge" --colour 2>"$tmp/full" &
ends_within "full stderr, an unknown option" 2 $!
CYCLONEDDS_URI="<NoSuchElement/>" "$bridge" --robot pioneer --url "$url3" --duration 20 >/dev/null 2>"$tmp/full" &
ends_within "full stderr, a DDS configuration it cannot use" 1 $!
CYCLONEDDS_URI="<NoSuchElement/>" "$bridge" --robot pioneer --url "$url3" --duration 20 >/dev/null 2>"$tmp/dds_err.log"
check "and it says why: $(head -c 300 "$tmp/dds_err.log")" grep -q "cannot join DDS domain" "$tmp/dds_err.log"
check "named once: robotalk-ros2's prefix not doubled" sh -c "! grep -q 'robotalk-ros2: robotalk-ros2:' '$tmp/dds_err.log'"
"$bridge" --robot pioneer --url "$url3" --key "$tmp/bridge" --duration 20 --stats >"$tmp/full" 2>"$tmp/bridge4.log" &
bridge4_pid=$!
wait_for "$tmp/bridge4.log" "bridged" 100
kill -TERM "$bridge4_pid"
ends_within "full stdout, --stats" 0 "$bridge4_pid"

# forged_then_real PORT N ROUNDS: a bridge of every announced robot (no
# --robot) hears N forged names no server answers for (one ANNOUNCE datagram
# each, ROUNDS times 0.5 s apart) before the real server starts; the real robot
# must still be bridged within 30 s. Prints how long it took.
# Further arguments go to the bridge.
forged_then_real() {
  local url="udpm://239.255.76.67:$1?ttl=0" log="$tmp/bridge_forged_$2.log" forge_pid bridge_pid started
  "$forge" "$url" announce-names ghost "$2" "$3" &
  forge_pid=$!
  pids+=("$forge_pid")
  "$bridge" --url "$url" --key "$tmp/bridge" --duration 60 "${@:4}" >/dev/null 2>"$log" &
  bridge_pid=$!
  pids+=("$bridge_pid")
  sleep 2.5  # the bridge has heard the forged names and connects them
  "$server_bin" --robot "pioneer=kinematic:$models/pioneer2dx_pantilt.urdf" --url "$url" \
    --key "$tmp/server" --clients "$tmp/clients" --duration 60 2>"$tmp/server_forged_$2.log" &
  pids+=("$!")
  started=$SECONDS
  wait_for "$log" "robot 'pioneer' bridged" 300
  echo "pioneer bridged $((SECONDS - started)) s after its server started, $2 forged robots announced first"
  check "with $2 forged robots announced first ($3 rounds), the real one is bridged within 30 s ($((SECONDS - started)) s)" \
    grep -q "robot 'pioneer' bridged" "$log"
  kill -INT "$bridge_pid"
  wait "$bridge_pid"
  kill "$forge_pid" 2>/dev/null
}

# 255 forged names, heard before the real server starts, do not delay its
# robot's bridging (review8: the bridge connected one robot at a time, 5 s
# each: 255 forged names held pioneer back 21 minutes).
forged_then_real 7627 255 70  # 35 s of forged names
# A forger re-announcing 256 names (the whole table of announced names) all
# the while kept the table full: the real robot was never bridged. A name
# whose connects failed now gives its place to a new one.
forged_then_real 7628 256 90  # 45 s of forged names
# A forger announcing fresh names faster than any table tries them (2,000
# names, again and again) keeps a real robot out of the bridge of every robot
# announced in open mode; a bridge given its server's key (--server-key) takes
# only the names that key signed, and bridges the real one at once.
forged_then_real 7629 2000 60 --server-key "$tmp/server.pub"  # 30 s of forged names

echo "passed $pass, failed $failures"
[ "$failures" -eq 0 ]
