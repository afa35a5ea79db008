#!/usr/bin/env bash
# examples/python against a real robotalk-server (kinematic Pioneer and, where
# ../shared/robots is, the iiwa14) in a private network namespace (CTest:
# scripts/netns_run.sh): drive_pioneer.py, iiwa_sine.py (1 s of sine, its
# PNG) and log_to_numpy.py on a session recorded meanwhile.
#   examples_test.sh SERVER CLI LOGPLAY PYTHON BUILD_PYTHON_DIR SOURCE_DIR SHARED_ROBOTS PORT
set -u
server_bin=$1 cli=$2 logplay=$3 python=$4 pythonpath=$5 src=$6 shared=$7 port=$8
url="udpm://239.255.76.67:$port?ttl=0"
. "$src/tests/lib.sh"  # $tmp, $server_pid, pids, check
export PYTHONPATH=$pythonpath
robots=(--robot "pioneer=kinematic:$src/models/pioneer2dx_pantilt.urdf")
[ -f "$shared/iiwa14.urdf" ] && robots+=(--robot "iiwa=kinematic:$shared/iiwa14.urdf")
"$server_bin" "${robots[@]}" --url "$url" --duration 60 --state-dir "$tmp/state" 2>"$tmp/server.log" &
server_pid=$!
wait_for "$tmp/server.log" "serving robot"
"$logplay" record -o "$tmp/session.lcmlog" --url "$url" -c 'ROBOTALK/.*' --duration 8 2>"$tmp/record.log" &
recorder=$!
pids+=("$recorder")
sleep 0.5
"$cli" --url "$url" watch pioneer --period 0.05 >/dev/null 2>&1 &
pids+=($!)

timeout 30 "$python" "$src/examples/python/drive_pioneer.py" --url "$url" >"$tmp/drive.out" 2>&1
check "drive_pioneer.py exits 0 ($(tail -1 "$tmp/drive.out"))" test $? -eq 0
check "its GOTO succeeded" grep -q "^GOTO 1 0 0: SUCCESS" "$tmp/drive.out"
check "its sequence succeeded" grep -q "^sequence: <SequenceResult 6/6 succeeded>" "$tmp/drive.out"
check "it saw the base at x=1" grep -q "^pose: x=0.9[89]\|^pose: x=1.00" "$tmp/drive.out"

if [ -f "$shared/iiwa14.urdf" ]; then
  timeout 30 "$python" "$src/examples/python/iiwa_sine.py" --url "$url" --seconds 1 -o "$tmp/tracking.png" \
    >"$tmp/sine.out" 2>&1
  check "iiwa_sine.py exits 0 ($(tail -1 "$tmp/sine.out"))" test $? -eq 0
  check "every set-point succeeded" grep -q "^100 set-points in delay mode (0.2 s ahead): 100 succeeded" "$tmp/sine.out"
  check "it wrote its plot" test -s "$tmp/tracking.png"
else
  echo "SKIP: iiwa_sine.py ($shared/iiwa14.urdf is absent)"
fi

wait "$recorder"
timeout 30 "$python" "$src/examples/python/log_to_numpy.py" "$tmp/session.lcmlog" --robot pioneer \
  -o "$tmp/traces.npz" >"$tmp/log.out" 2>&1
check "log_to_numpy.py exits 0 ($(tail -1 "$tmp/log.out"))" test $? -eq 0
check "it names the Pioneer's joints from the log" grep -q "^  pan: " "$tmp/log.out"
check "the traces load back" "$python" -c "
import numpy as np
d = np.load('$tmp/traces.npz')
assert d['positions'].shape[1] == 4 and list(d['joint_names'])[2] == 'pan', d['positions'].shape
assert abs(d['positions'][:, 2].max() - 0.3) < 1e-6"
[ "$failures" -eq 0 ] || { cat "$tmp"/*.out; tail -20 "$tmp/server.log"; }
echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
