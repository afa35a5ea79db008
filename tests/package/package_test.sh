#!/usr/bin/env bash
# Installs the build into a temporary prefix and builds a separate CMake
# project against it with find_package(robotalk): a client program, and a
# server with out-of-tree drivers (one whose Execute throws). Then, in a
# private network namespace, the throwing driver's robot answers ERROR and
# is held in panic while the other robot of the same server keeps serving.
#   package_test.sh BUILD_DIR SOURCE_DIR CLI
set -euo pipefail
build=$1 source=$2 cli=$3
. "$(dirname "$0")/../lib.sh"  # $tmp, $server_pid, check
# The outside server latches panics by default: in this run's folder, so a
# second run by hand does not start with robot 'bad' in panic.
export ROBOTALK_STATE_DIR="$tmp/state"
cmake --install "$build" --prefix "$tmp/prefix" >"$tmp/install.log"
cmake -S "$source/tests/package/consumer" -B "$tmp/consumer" -DCMAKE_PREFIX_PATH="$tmp/prefix" >"$tmp/configure.log"
cmake --build "$tmp/consumer" -j2 >"$tmp/build.log" || { cat "$tmp/build.log"; exit 1; }
urdf="$source/models/pioneer2dx_pantilt.urdf"
check "client program runs" sh -c "'$tmp/consumer/consumer' '$urdf' | grep -q 'pioneer2dx_pantilt 4 dofs'"
check "the ode driver's installed header builds a driver that steps" \
  sh -c "'$tmp/consumer/ode-consumer' '$urdf' | grep -q 'ode p 100 steps on wheels'"
server="$tmp/consumer/outside-server"
check "ServerMain gives the full --help" sh -c "'$server' --help | grep -q -- '--session-timeout'"
check "its drivers and the shipped one are registered" \
  sh -c "'$server' --list-drivers | tr '\n' ' ' | grep -q 'failing_arm holding_arm kinematic'"

if ! "$source/scripts/netns_run.sh" true 2>/dev/null; then
  echo "SKIP: no network namespace for the throwing-driver case"
  echo "$pass passed, $failures failed"
  [ "$failures" -eq 0 ]; exit
fi
url="udpm://239.255.76.67:7731?ttl=0"
cat >"$tmp/case.sh" <<CASE
set -u
"$server" --url "$url" --robot "bad=failing_arm:$urdf" --robot "good=holding_arm:$urdf" --duration 30 2>"$tmp/server.log" &
pid=\$!
for _ in \$(seq 50); do grep -q "serving robot 'good'" "$tmp/server.log" 2>/dev/null && break; sleep 0.1; done
"$cli" --url "$url" --timeout 5 send bad joint_setpoint pan 0.5 >"$tmp/bad.out" 2>&1
"$cli" --url "$url" --timeout 5 send good joint_setpoint pan 0.5 >"$tmp/good.out" 2>&1
"$cli" --url "$url" --timeout 5 send bad joint_setpoint pan 0.1 >"$tmp/bad2.out" 2>&1
"$cli" --url "$url" --timeout 5 query good joint_state pan >"$tmp/good_state.out" 2>&1
kill \$pid; wait \$pid
echo "server exit \$?" >"$tmp/exit.out"
CASE
"$source/scripts/netns_run.sh" bash "$tmp/case.sh"
check "the throwing driver's command answers ERROR naming the driver and its message" \
  grep -q "ERROR.*driver 'failing_arm' threw in Execute: serial port write failed" "$tmp/bad.out"
check "the other robot keeps serving" grep -q "SUCCESS" "$tmp/good.out"
check "the faulted robot is held in panic" grep -q "PANIC" "$tmp/bad2.out"
check "the other robot's state is what it was told" grep -q "0.5" "$tmp/good_state.out"
check "the server logged the fault" grep -q "DRIVER FAULT" "$tmp/server.log"
check "the server kept running to a clean exit" grep -q "server exit 0" "$tmp/exit.out"
for f in bad good bad2 good_state; do [ "$failures" -eq 0 ] || { echo "--- $f"; cat "$tmp/$f.out"; }; done
[ "$failures" -eq 0 ] || { echo "--- server log"; cat "$tmp/server.log"; }
echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
