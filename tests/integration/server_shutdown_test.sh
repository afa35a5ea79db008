#!/usr/bin/env bash
# The server's STOP on SIGTERM and SIGINT across processes (docs/server.md: "a
# robot is never left moving by the server going away cleanly"): a server
# with a kinematic and an ode robot, one driven by `send setspeed --hold`, the
# other by a GOTO; the signal; then proof that a STOP ran on each robot before
# the server exited: its log says so per robot, the GOTO's client gets
# INTERRUPTED by that STOP, and an observer's last STATE sample of the
# kinematic robot shows it at rest. Runs inside a private network namespace
# (CTest wraps it with scripts/netns_run.sh).
#   server_shutdown_test.sh SERVER CLI MODELS_DIR
set -u
server_bin=$1 cli=$2 models=$3
. "$(dirname "$0")/../lib.sh" # $tmp, $server_pid, check
urdf="$models/pioneer2dx_pantilt.urdf"


# shutdown_case SIGNAL PORT SETSPEED_ROBOT GOTO_ROBOT
shutdown_case() {
  local sig=$1 port=$2 speeder=$3 driver=$4 dir="$tmp/$1"
  local url="udpm://239.255.76.67:$port?ttl=0"
  mkdir -p "$dir"
  "$server_bin" --robot "pioneer=kinematic:$urdf" --robot "rover=ode:$urdf" --url "$url" \
    --log-executions --duration 60 2>"$dir/server.log" &
  server_pid=$!
  wait_for "$dir/server.log" "serving robot 'rover'" || {
    echo "server did not start:"
    cat "$dir/server.log"
    return 1
  }
  "$cli" --url "$url" watch pioneer --json --period 0.05 --duration 30 >"$dir/watch.json" 2>"$dir/watch.err" &
  local watcher=$!
  pids+=("$watcher")
  "$cli" --url "$url" send "$speeder" setspeed 0.3 0.1 --hold >"$dir/hold.out" 2>&1 &
  pids+=($!)
  "$cli" --url "$url" --timeout 3 send "$driver" goto 5 0 0 >"$dir/goto.out" 2>&1 &
  local goto_client=$!
  pids+=("$goto_client")
  # Both robots move: the server ran both commands, and the observer sees pioneer move.
  check "$sig: the server ran the SETSPEED" wait_for "$dir/server.log" "robot '$speeder': executed .* SETSPEED"
  check "$sig: the server ran the GOTO" wait_for "$dir/server.log" "robot '$driver': executed .* GOTO -> in progress"
  sleep 0.5
  read -r v w moving < <(last_motion "$dir/watch.json")
  check "$sig: pioneer moves before the signal (v=$v w=$w moving=$moving)" \
    python3 -c "import sys; sys.exit(not (abs($v) > 0.05 and '$moving' == 'true'))"

  signal_server "$sig"
  check "$sig: the server exits by itself within 10 s" test "$server_ended" -eq 1
  check "$sig: the server exits 0 (status $server_status)" test "$server_status" -eq 0
  local name
  case "$sig" in TERM) name=Terminated ;; INT) name=Interrupt ;; esac
  check "$sig: the server says why it stops: $(tail -n 4 "$dir/server.log" | tr '\n' '|')" \
    grep -q "robotalk-server: $name, stopping every robot" "$dir/server.log"
  for robot in pioneer rover; do
    check "$sig: a STOP ran on $robot after the signal" \
      sh -c "sed -n '/robotalk-server: $name, stopping every robot/,\$p' '$dir/server.log' |
             grep -q \"robot '$robot': stopped (STOP executed; the server is shutting down)\""
  done
  for _ in $(seq 50); do kill -0 "$goto_client" 2>/dev/null || break; sleep 0.1; done
  check "$sig: the GOTO on $driver ended INTERRUPTED by the STOP: $(cat "$dir/goto.out")" \
    grep -q "INTERRUPTED.*STOP" "$dir/goto.out"
  # The observer's stream ends with pioneer at rest: the last sample came after its STOP.
  sleep 0.3
  read -r v w moving < <(last_motion "$dir/watch.json")
  check "$sig: the last STATE sample shows pioneer at rest (v=$v w=$w moving=$moving)" \
    python3 -c "import sys; sys.exit(not ($v == 0 and $w == 0 and '$moving' == 'false'))"
  kill "$watcher" 2>/dev/null
}

# SIGTERM: pioneer (kinematic) under SETSPEED, rover (ode) in a GOTO; SIGINT: the other way round.
shutdown_case TERM 7714 pioneer rover
shutdown_case INT 7715 rover pioneer

echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
