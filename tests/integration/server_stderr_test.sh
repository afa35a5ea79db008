#!/usr/bin/env bash
# A server whose stderr goes away (the pipe's reader exits: `robotalk-server
# ... 2>&1 | head`, a log collector restarted) goes on serving: a log line
# written to the closed pipe is lost, never the server (before: SIGPIPE
# killed it at its next line, no STOP, the robot left moving). The robot
# moves under `send setspeed --hold`, stderr's reader exits, the server logs
# (--log-executions: every command a line), and still answers; SIGTERM then
# stops the robot (an observer's last STATE sample at rest) and the server
# exits 0. Runs inside a private network namespace (CTest wraps it with
# scripts/netns_run.sh).
#   server_stderr_test.sh SERVER CLI MODELS_DIR
set -u
server_bin=$1 cli=$2 models=$3
. "$(dirname "$0")/../lib.sh" # $tmp, $server_pid, check
urdf="$models/pioneer2dx_pantilt.urdf"
url="udpm://239.255.76.67:7719?ttl=0"
# moves NAME WATCH_JSON / at_rest NAME WATCH_JSON: the last STATE sample of
# a `watch --json` output shows pioneer moving / at rest (a check named NAME).
moves() {
  read -r v w moving < <(last_motion "$2")
  check "$1 (v=$v w=$w moving=$moving)" python3 -c "import sys; sys.exit(not (abs($v) > 0.05 and '$moving' == 'true'))"
}
at_rest() {
  read -r v w moving < <(last_motion "$2")
  check "$1 (v=$v w=$w moving=$moving)" python3 -c "import sys; sys.exit(not ($v == 0 and $w == 0 and '$moving' == 'false'))"
}
# is_moving / is_at_rest WATCH_JSON: the same without a check, for poll_until
# (which ends a wait once it holds; the check that follows decides).
is_moving() {
  read -r v w moving < <(last_motion "$1")
  [ "$moving" = true ] && awk -v v="$v" 'BEGIN { exit !(v > 0.05 || v < -0.05) }'
}
is_at_rest() {
  read -r v w moving < <(last_motion "$1")
  [ "$moving" = false ] && awk -v v="$v" -v w="$w" 'BEGIN { exit !(v == 0 && w == 0) }'
}

# stderr's reader copies lines to server.log until the server serves, then exits.
mkfifo "$tmp/stderr"
python3 -c 'import sys
with open(sys.argv[1]) as f, open(sys.argv[2], "w") as out:
    for line in f:
        out.write(line); out.flush()
        if "serving robot" in line: break' "$tmp/stderr" "$tmp/server.log" &
reader=$!
pids+=("$reader")
"$server_bin" --robot "pioneer=kinematic:$urdf" --url "$url" --log-executions --duration 60 2>"$tmp/stderr" &
server_pid=$!
check "the server starts" wait_for "$tmp/server.log" "serving robot 'pioneer'"
wait "$reader"  # stderr's reader is gone: the pipe has none

"$cli" --url "$url" watch pioneer --json --period 0.05 --duration 30 >"$tmp/watch.json" 2>"$tmp/watch.err" &
pids+=($!)
"$cli" --url "$url" send pioneer setspeed 0.3 0.1 --hold >"$tmp/hold.out" 2>&1 &
pids+=($!)
poll_until "$(deadline 1.5)" is_moving "$tmp/watch.json"  # the SETSPEED and its audit line: a write to a pipe without a reader
check "the server lives on after a log line to a stderr without a reader" kill -0 "$server_pid"
check "it still answers: $("$cli" --url "$url" --timeout 3 query pioneer base_pose 2>&1 | head -c 300)" \
  "$cli" --url "$url" --timeout 3 query pioneer base_pose
moves "pioneer moves before the signal" "$tmp/watch.json"

signal_server TERM
check "the server exits 0 on SIGTERM (status $server_status)" test "$server_status" -eq 0
sleep 0.3
at_rest "the last STATE sample shows pioneer at rest" "$tmp/watch.json"

# A stderr that takes nothing from the start (a pipe that is full and never
# read: a supervisor that never drains it, a terminal stopped with Ctrl-S):
# the server serves all the same, and SIGTERM still STOPs the robot and ends
# it (before: it hung in its first line, "open mode: ...", and never served;
# SIGTERM, taken by the thread that writes its lines, did nothing).
url="udpm://239.255.76.67:7720?ttl=0"
mkfifo "$tmp/full"
sleep 1000 <"$tmp/full" &  # holds the read end, reads nothing
pids+=($!)
exec 3>"$tmp/full"
head -c 65536 /dev/zero >&3  # the pipe's capacity: full
"$server_bin" --robot "pioneer=kinematic:$urdf" --url "$url" --log-executions --duration 60 2>&3 &
server_pid=$!
exec 3>&-
served=1
for _ in $(seq 20); do
  "$cli" --url "$url" --timeout 1 query pioneer base_pose >/dev/null 2>&1 && served=0 && break
  sleep 0.2
done
check "a server whose stderr takes nothing serves" test "$served" -eq 0
"$cli" --url "$url" watch pioneer --json --period 0.05 --duration 30 >"$tmp/watch2.json" 2>/dev/null &
pids+=($!)
"$cli" --url "$url" send pioneer setspeed 0.3 0.1 --hold >"$tmp/hold2.out" 2>&1 &
pids+=($!)
poll_until "$(deadline 1.5)" is_moving "$tmp/watch2.json"
moves "full stderr: pioneer moves before the signal" "$tmp/watch2.json"
signal_server TERM
check "full stderr: the server ends within 10 s of SIGTERM" test "$server_ended" -eq 1
check "full stderr: it exits 0 (status $server_status)" test "$server_status" -eq 0
sleep 0.3
at_rest "full stderr: the last STATE sample shows pioneer at rest" "$tmp/watch2.json"

# The same for the server's other start-up lines, which were written to
# stderr directly (final review 11): the ode driver's walking note ("walks
# with ..."), the --no-panic-latch warning, and start-up errors. With a
# stderr that takes nothing (the same full pipe, $tmp/full) such a server
# never served and SIGTERM did not end it; an error never ended it. Now every
# line of the process goes through its one LogWriter: it serves, SIGTERM ends
# it with 0, and an error ends it with its status within the writer's bound.
# full_server NAME PORT ARGS...: a server on PORT, stderr the full pipe; it
# must serve robot NAME (a query answered) within 10 s.
full_server() {
  local name=$1 port=$2
  shift 2
  url="udpm://239.255.76.67:$port?ttl=0"
  "$server_bin" --url "$url" --duration 60 "$@" 2>"$tmp/full" &
  server_pid=$!
  served=1
  for _ in $(seq 40); do
    "$cli" --url "$url" --timeout 1 query "$name" base_pose >/dev/null 2>&1 && served=0 && break
    sleep 0.25
  done
  check "full stderr, $*: the server serves '$name'" test "$served" -eq 0
}
full_server humanoid 7723 --robot "humanoid=ode:$models/simple_humanoid.urdf,walk=true"
signal_server TERM
check "full stderr, a walking humanoid: the server ends within 10 s of SIGTERM" test "$server_ended" -eq 1
check "full stderr, a walking humanoid: it exits 0 (status $server_status)" test "$server_status" -eq 0
full_server pioneer 7724 --robot "pioneer=kinematic:$urdf" --no-panic-latch
"$cli" --url "$url" watch pioneer --json --period 0.05 --duration 30 >"$tmp/watch5.json" 2>/dev/null &
pids+=($!)
"$cli" --url "$url" send pioneer setspeed 0.3 0.1 --hold >/dev/null 2>&1 &
pids+=($!)
poll_until "$(deadline 1.5)" is_moving "$tmp/watch5.json"
moves "full stderr, --no-panic-latch: pioneer moves before the signal" "$tmp/watch5.json"
signal_server TERM
check "full stderr, --no-panic-latch: the server ends within 10 s of SIGTERM" test "$server_ended" -eq 1
check "full stderr, --no-panic-latch: it exits 0 (status $server_status)" test "$server_status" -eq 0
sleep 0.3
at_rest "full stderr, --no-panic-latch: the last STATE sample shows pioneer at rest" "$tmp/watch5.json"
# errs STATUS WHAT ARGS...: a server that cannot start (ARGS) ends with STATUS
# within 5 s whatever its stderr takes, and says why when stderr takes it.
errs() {
  local status=$1 what=$2
  shift 2
  fails_whatever_stderr "$status" "robotalk-server: .*$what" "$what: the server" \
    "$server_bin" --url "udpm://239.255.76.67:7725?ttl=0" --duration 60 "$@"
}
errs 2 "unknown option" --robot "pioneer=kinematic:$urdf" --colour
errs 1 "cannot open" --robot "pioneer=kinematic:/nonexistent.urdf"
errs 1 "panic latch" --robot "pioneer=kinematic:$urdf" --panic-latch /nonexistent/dir/latch
# The usage after "no --robot given" is lines, not one line of \x0a escapes
# (every LogWriter line is written on one line).
"$server_bin" --url "udpm://239.255.76.67:7725?ttl=0" 2>"$tmp/usage.log"
check "no --robot: the usage on lines of their own, no escaped line break" \
  sh -c "grep -q '^usage: robotalk-server' '$tmp/usage.log' && ! grep -q 'x0a' '$tmp/usage.log'"

# The CLI's `send ... --hold`: its stderr stops taking lines after "holding
# ... until Ctrl-C" (a full pipe); Ctrl-C must still STOP the robot (before:
# it wrote "robotalk: " before it sent the STOP, and waited there; its
# heartbeats kept its session, so the server's watchdog never stopped it).
url="udpm://239.255.76.67:7721?ttl=0"
start_pioneer "$tmp/server.log" --url "$url" --duration 60
mkfifo "$tmp/cli_err"
python3 -c 'import sys, time
with open(sys.argv[1]) as f:
    for line in f:
        if "holding" in line:
            open(sys.argv[2], "w").close()
            break
    time.sleep(1000)  # holds the read end, reads nothing more' "$tmp/cli_err" "$tmp/holding" &
pids+=($!)
"$cli" --url "$url" watch pioneer --json --period 0.05 --duration 30 >"$tmp/watch3.json" 2>/dev/null &
pids+=($!)
setsid "$cli" --url "$url" send pioneer setspeed 0.3 0.1 --hold >/dev/null 2>"$tmp/cli_err" &
hold_pid=$!
pids+=("$hold_pid")
for _ in $(seq 50); do [ -e "$tmp/holding" ] && break; sleep 0.1; done
check "the CLI holds the SETSPEED" test -e "$tmp/holding"
head -c 65536 /dev/zero >"$tmp/cli_err"  # the pipe's capacity: its stderr takes nothing now
sleep 0.5
kill -INT "$hold_pid"
ended() { [ ! -e "/proc/$1" ] || [ "$(cut -d')' -f2 "/proc/$1/stat" | cut -c2)" = Z ]; }  # gone, or a zombie
# 2.5 s: past the session timeout (2 s): the STOP, not the watchdog, if anything
poll_until "$(deadline 2.5)" eval 'is_at_rest "$tmp/watch3.json" && ended "$hold_pid"'
at_rest "Ctrl-C on a --hold whose stderr takes nothing still stops pioneer" "$tmp/watch3.json"
check "and the CLI ends within 2.5 s of the Ctrl-C (StopOnInterrupt::kTakeOver, 2 s)" ended "$hold_pid"
wait "$hold_pid"
hold_status=$?
# gaps13: a --hold's Ctrl-C is its normal end (exit 0 when its STOP is
# answered SUCCESS); ended by the take-over it exited 130 instead, the status
# of a command cut short. Now the take-over exits as the hold would have.
check "with a --hold's own status, 0: its STOP answered SUCCESS (status $hold_status; before: 130)" \
  test "$hold_status" -eq 0
kill -9 "$hold_pid" 2>/dev/null

# A SETSPEED without --hold lasts "only while this command runs": the CLI
# exits after its reply and a note, and the watchdog stops the robot. With
# a stderr (or stdout) that takes nothing the CLI waited in that note's
# write for ever, its heartbeats keeping the robot moving (0.3 m/s 6 s
# later, before). Its session now ends before it writes: the robot stops.
"$cli" --url "$url" send pioneer stop >/dev/null 2>&1
for out in stderr stdout; do
  mkfifo "$tmp/full_$out"
  sleep 1000 <"$tmp/full_$out" &  # holds the read end, reads nothing
  pids+=($!)
  exec 5>"$tmp/full_$out"
  head -c 65536 /dev/zero >&5  # the pipe's capacity: full
  if [ "$out" = stderr ]; then
    "$cli" --url "$url" send pioneer setspeed 0.3 0.1 >/dev/null 2>&5 &
  else
    "$cli" --url "$url" send pioneer setspeed 0.3 0.1 >&5 2>/dev/null &
  fi
  speed_pid=$!
  pids+=("$speed_pid")
  exec 5>&-
  t0=$(date +%s%N)
  poll_until "$(deadline 1 "$t0")" is_moving "$tmp/watch3.json"
  c0=$(date +%s%N)
  moves "a SETSPEED without --hold whose $out takes nothing: pioneer moves" "$tmp/watch3.json"
  # the session timeout (2 s) and the watchdog: at the latest when the old
  # 'sleep 1; moves ...; sleep 3.5' looked (the check's own time included)
  poll_until "$(deadline 3.5 $(($(deadline 1 "$t0") + $(date +%s%N) - c0)))" is_at_rest "$tmp/watch3.json"
  at_rest "a SETSPEED without --hold whose $out takes nothing stops within the session timeout" "$tmp/watch3.json"
  kill -9 "$speed_pid" 2>/dev/null
done

# The CLI's progress line while it waits for a task (`send ... goto`) on a
# terminal that takes nothing (a pty nobody reads, its buffer full; a
# terminal stopped with Ctrl-S): Ctrl-C must still STOP the robot (before:
# the line's write waited, so the Ctrl-C was never acted on, and the CLI's
# heartbeats kept its session and the GOTO alive).
url="udpm://239.255.76.67:7722?ttl=0"
signal_server TERM
start_pioneer "$tmp/server.log" --url "$url" --duration 60
"$cli" --url "$url" watch pioneer --json --period 0.05 --duration 30 >"$tmp/watch4.json" 2>/dev/null &
pids+=($!)
python3 -c 'import json, os, pty, signal, subprocess, sys, time
cli, url, out, watch = sys.argv[1:5]
def at_rest():  # the last STATE sample of the watch at rest (at_rest, below, checks it)
    lines = [l for l in open(watch) if l.startswith("{")]
    s = json.loads(lines[-1]) if lines else None
    return s is not None and s["base"][3] == 0 and s["base"][4] == 0 and not s["moving"]
master, slave = pty.openpty()
fill = os.open(os.ttyname(slave), os.O_WRONLY | os.O_NONBLOCK | os.O_NOCTTY)
total, chunk = 0, 4096
while chunk and total < 1 << 24:  # until it takes not one byte more (bounded)
    try:
        total += os.write(fill, b"x" * chunk)
    except BlockingIOError:
        chunk //= 2
goto = subprocess.Popen([cli, "--url", url, "send", "pioneer", "goto", "6", "0", "0"], stdin=subprocess.DEVNULL,
                        stdout=subprocess.DEVNULL, stderr=slave, start_new_session=True)
time.sleep(2.0)  # moving, its progress line due every 50 ms after 0.3 s
goto.send_signal(signal.SIGINT)
end = time.monotonic() + 2.5  # past the session timeout (2 s): the STOP, not the watchdog, if anything
while not at_rest() and time.monotonic() < end:
    time.sleep(0.1)
with open(out, "w") as f:
    f.write("filled %d bytes; the CLI %s\n" % (total, "ended" if goto.poll() is not None else "still runs"))
goto.kill()
goto.wait()' "$cli" "$url" "$tmp/pty.out" "$tmp/watch4.json"
cat "$tmp/pty.out"
at_rest "Ctrl-C on a goto whose terminal takes nothing still stops pioneer" "$tmp/watch4.json"

# The same with a stdout that takes nothing (`robotalk send --file seq.txt |
# a reader that stalls`): a frame's reply line waits in its write, so the
# CLI's thread never sees the Ctrl-C; the signal's own thread sends the STOP
# (before: the sequence played on to its end, 0.3 m/s 2.5 s after Ctrl-C).
# A frame queued for 7 s (5 s after the Ctrl-C, past the CLI's 2 s take-over
# bound and the session's 2 s expiry) must not run either: one STOP does not
# cancel it, the CLI's exit (its session expiring) does.
printf '0.0 setspeed 0.3 0.0\n0.5 joint_setpoint pan 0.3\n1.0 joint_setpoint pan -0.3\n7.0 setspeed 0.3 0.0\n12.0 stop\n' >"$tmp/seq.txt"
mkfifo "$tmp/full_out"
sleep 1000 <"$tmp/full_out" &  # holds the read end, reads nothing
pids+=($!)
exec 4>"$tmp/full_out"
head -c 65536 /dev/zero >&4  # the pipe's capacity: full
setsid "$cli" --url "$url" send pioneer --file "$tmp/seq.txt" --mode delay >&4 2>/dev/null &
seq_pid=$!
pids+=("$seq_pid")
exec 4>&-
sleep 2.0
moves "a sequence whose stdout takes nothing: pioneer moves before Ctrl-C" "$tmp/watch4.json"
kill -INT "$seq_pid"
sleep 2.5
at_rest "Ctrl-C on a sequence whose stdout takes nothing still stops pioneer" "$tmp/watch4.json"
check "the CLI stuck in its write ends by itself within 2 s of the Ctrl-C's STOP" ended "$seq_pid"
wait "$seq_pid"
seq_status=$?
check "with the status of an interrupted run, 130 (status $seq_status)" test "$seq_status" -eq 130
sleep 4.0
at_rest "the frame queued for 5 s after the Ctrl-C does not run" "$tmp/watch4.json"
kill -9 "$seq_pid" 2>/dev/null

# A sequence that ends in a SETSPEED, its stdout taking nothing, no Ctrl-C:
# the SETSPEED lasts only while the command runs (as a single one without
# --hold). Before, the CLI waited in a frame's reply line, its heartbeats
# keeping the session and the base at 0.3 m/s for ever (gaps12, 6 s later);
# the frames' lines are now written by a thread of their own, and the session
# ends when the sequence has run, before the CLI waits for its output.
"$cli" --url "$url" send pioneer stop >/dev/null 2>&1
"$cli" --url "$url" watch pioneer --json --period 0.05 --duration 30 >"$tmp/watch6.json" 2>/dev/null &
pids+=($!)
printf '0.0 setspeed 0.3 0.0\n0.3 joint_setpoint pan 0.3\n0.6 joint_setpoint pan -0.3\n' >"$tmp/seq_end.txt"
for mode in delay direct playback; do
  mkfifo "$tmp/full_seq_$mode"
  sleep 1000 <"$tmp/full_seq_$mode" &  # holds the read end, reads nothing
  pids+=($!)
  exec 4>"$tmp/full_seq_$mode"
  head -c 65536 /dev/zero >&4  # the pipe's capacity: full
  "$cli" --url "$url" send pioneer --file "$tmp/seq_end.txt" --mode "$mode" >&4 2>/dev/null &
  seq_pid=$!
  pids+=("$seq_pid")
  exec 4>&-
  t0=$(date +%s%N)
  poll_until "$(deadline 1.2 "$t0")" is_moving "$tmp/watch6.json"
  c0=$(date +%s%N)
  moves "a sequence ending in a SETSPEED, its stdout taking nothing ($mode): pioneer moves" "$tmp/watch6.json"
  # the sequence's end, the session timeout (2 s) and the watchdog: at the
  # latest when the old 'sleep 1.2; moves ...; sleep 3.5' looked
  poll_until "$(deadline 3.5 $(($(deadline 1.2 "$t0") + $(date +%s%N) - c0)))" is_at_rest "$tmp/watch6.json"
  at_rest "... and stops within the session timeout of the sequence's end ($mode)" "$tmp/watch6.json"
  kill -9 "$seq_pid" 2>/dev/null
  "$cli" --url "$url" send pioneer stop >/dev/null 2>&1
done

echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
