#!/usr/bin/env bash
# robotalk-logplay end to end (docs/logplay.md): a session recorded with
# `robotalk-logplay record` (every lane of the split traffic layout) on the
# ODE Pioneer, sent in the DEFAULT `robotalk send --file`
# mode, replays onto a SECOND robot of another name and ends within 1 cm /
# 0.01 rad of the recorded final pose. Also: info, extract (a file `robotalk
# send --file` accepts), export (CSV, PNG).
# The final pose depends on when the server executes each SETSPEED (a late
# start by dt shifts the pose by about v*dt and the heading by omega*dt), so
# speeds are modest; a machine starved for CPU can still exceed the bounds.
# Runs inside a private network namespace (CTest wraps it with netns_run.sh).
#   logplay_replay_test.sh SERVER CLI LOGPLAY MODELS_DIR
set -u
server_bin=$1 cli=$2 logplay=$3 models=$4
url="udpm://239.255.76.67:7811?ttl=0"
. "$(dirname "$0")/../lib.sh"
rt() { "$cli" --url "$url" "$@"; }

"$server_bin" --robot "pioneer=ode:$models/pioneer2dx_pantilt.urdf" \
  --robot "pioneer2=ode:$models/pioneer2dx_pantilt.urdf" --url "$url" --duration 100 2>"$tmp/server.log" &
pids+=($!)
for _ in $(seq 50); do [ "$(grep -c "serving robot" "$tmp/server.log")" -ge 2 ] && break; sleep 0.1; done

# --- record: the state stream and a sequence in send's default mode ---------
"$logplay" record -o "$tmp/session.lcmlog" --lcm-url "$url" -c 'ROBOTALK/.*' 2>"$tmp/record.log" &
logger=$!
wait_for "$tmp/record.log" "recording"
# The binary itself in the background, not the rt function: $! must be
# watch's own pid, or the kill below leaves it running.
"$cli" --url "$url" watch pioneer --period 0.05 >"$tmp/watch.txt" 2>&1 &
watcher=$!
cat >"$tmp/seq.txt" <<'SEQ'
0.0 setspeed 0.2 0
0.0 joint_setpoint pan 0.4
1.0 setspeed 0.2 0.4
1.5 joint_setpoint tilt -0.3
2.2 setspeed 0.2 -0.3
3.0 joint_setpoint pan -0.2
3.4 stop
SEQ
sleep 0.5
rt send pioneer --file "$tmp/seq.txt" >"$tmp/send.out" 2>&1
check "the recorded sequence succeeds" test "$(grep -c SUCCESS "$tmp/send.out")" -eq 7
# The recording ends once the robot has settled (no longer moving).
for _ in $(seq 40); do
  tail -1 "$tmp/watch.txt" | grep -q "v=0.000 w=0.000" && break
  sleep 0.1
done
sleep 0.3
kill "$watcher"; wait "$watcher" 2>/dev/null
sleep 0.2
kill -INT "$logger"; wait "$logger"
check "record stops on SIGINT with status 0: $(cat "$tmp/record.log")" test $? -eq 0
check "record says what it wrote" grep -q "wrote [0-9]* events" "$tmp/record.log"

# --- info ---------------------------------------------------------------------
"$logplay" info "$tmp/session.lcmlog" >"$tmp/info.txt" 2>&1
check "info exits 0" test $? -eq 0
check "info lists both robots" grep -q "pioneer2  driver ode" "$tmp/info.txt"
check "info shows the command stream, sent in send's default mode (delay)" \
  grep -q "commands 7 in mode delay: JOINT_SETPOINT 3 SETSPEED 3 STOP 1" "$tmp/info.txt"
check "info places it on the server clock" grep -q "7 frames over 3.4 s (server clock)" "$tmp/info.txt"
final=$(grep "^state pioneer:" "$tmp/info.txt")
read -r x0 y0 th0 < <(echo "$final" | sed 's/.*final base x \([^ ]*\) y \([^ ]*\) theta \([^;]*\);.*/\1 \2 \3/')
read -r pan0 tilt0 < <(echo "$final" | awk '{print $(NF-1), $NF}')
check "the recorded robot moved (x=$x0)" awk -v x="$x0" 'BEGIN { exit !(x > 0.4) }'

# --- extract ------------------------------------------------------------------
"$logplay" extract "$tmp/session.lcmlog" --robot pioneer -o "$tmp/extracted.txt" 2>"$tmp/extract.err"
check "extract exits 0" test $? -eq 0
check "extract writes 7 commands" test "$(grep -vc '^#' "$tmp/extracted.txt")" -eq 7
check "extract recovers the offsets" grep -q "^3.400000 stop" "$tmp/extracted.txt"
check "extract keeps targets and values" grep -q "^1.500000 joint_setpoint tilt -0.3$" "$tmp/extracted.txt"

# --- replay onto pioneer2 -------------------------------------------------------
"$logplay" replay "$tmp/session.lcmlog" --robot pioneer2 --from pioneer --url "$url" >"$tmp/replay.out" 2>&1
check "replay exits 0" test $? -eq 0
check "replay summarises the signals" grep -q "replayed 7/7 commands onto 'pioneer2'.*SUCCESS 7" "$tmp/replay.out"
for _ in $(seq 50); do  # until pioneer2 has settled (v = omega = 0)
  read -r x1 y1 th1 v1 w1 < <(rt query pioneer2 base_pose | awk '{print $(NF-4), $(NF-3), $(NF-2), $(NF-1), $NF}')
  awk -v v="${v1:-1}" -v w="${w1:-1}" 'BEGIN { exit !(v * v + w * w < 1e-8) }' && break
  sleep 0.1
done
read -r pan1 tilt1 < <(rt query pioneer2 joint_state | awk '{print $6, $7}')
echo "recorded final: x $x0 y $y0 theta $th0 pan $pan0 tilt $tilt0"
echo "replayed final: x $x1 y $y1 theta $th1 pan $pan1 tilt $tilt1"
within() { awk -v a="$1" -v b="$2" -v tol="$3" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d <= tol) }'; }
check "x within 1 cm" within "$x0" "$x1" 0.01
check "y within 1 cm" within "$y0" "$y1" 0.01
check "theta within 0.01 rad" within "$th0" "$th1" 0.01
check "pan within 0.01 rad" within "$pan0" "$pan1" 0.01
check "tilt within 0.01 rad" within "$tilt0" "$tilt1" 0.01

# --- replay whose stdout and stderr take nothing ------------------------------
# The window 0-2.5 s ends in "2.2 setspeed 0.2 -0.3": a servo command kept
# only while the replay runs. With a stdout and a stderr that take nothing
# (full pipes nobody reads) the replay must still end its session once its
# frames have answered (before: it waited in its summary line, its heartbeats
# keeping pioneer2 driving).
rt send pioneer2 stop >/dev/null 2>&1
"$cli" --url "$url" watch pioneer2 --json --period 0.05 --duration 20 >"$tmp/watch_full.json" 2>/dev/null &
pids+=($!)
mkfifo "$tmp/full_out"
# Its reader takes the first line ("replaying ..."), then nothing: the pipe
# is filled once that line is read, so the replay's later lines wait.
python3 -c 'import sys, time
with open(sys.argv[1], "rb", buffering=0) as f, open(sys.argv[2], "wb") as out:
    out.write(f.readline())
    out.flush()
    time.sleep(1000)' "$tmp/full_out" "$tmp/replay_head.txt" &
pids+=($!)
exec 4>"$tmp/full_out"
"$logplay" replay "$tmp/session.lcmlog" --robot pioneer2 --from pioneer --url "$url" --window 0:2.5 >"$tmp/full_out" 2>&4 &
replay_pid=$!
pids+=("$replay_pid")
wait_for "$tmp/replay_head.txt" "replaying"
head -c 65536 /dev/zero >&4  # the pipe's capacity: full
exec 4>&-
sleep 1.5
read -r v w moving < <(last_motion "$tmp/watch_full.json")
check "replay with full stdout and stderr: pioneer2 moves (v=$v moving=$moving)" \
  python3 -c "import sys; sys.exit(not (abs($v) > 0.05 and '$moving' == 'true'))"
sleep 5  # the window's end (2.2 s after its start), the session timeout (2 s), the watchdog
read -r v w moving < <(last_motion "$tmp/watch_full.json")
check "... and its base stops within the session timeout of its last frame (v=$v w=$w)" \
  python3 -c "import sys; sys.exit(not (abs($v) < 0.01 and abs($w) < 0.01))"
kill -9 "$replay_pid" 2>/dev/null

# --- export -------------------------------------------------------------------
py=/usr/bin/python3; [ -x "$py" ] || py=python3
if "$py" -c 'import matplotlib' 2>/dev/null; then plot=""; else plot="--no-plot"; fi
"$logplay" export "$tmp/session.lcmlog" -o "$tmp/export" $plot >"$tmp/export.out" 2>&1
check "export exits 0" test $? -eq 0
check "commands.csv has 7 commands" test "$(grep -c ',pioneer,' "$tmp/export/commands.csv")" -eq 7
check "commands.csv labels the delay session delay (issue 20)" \
  test "$(grep -c ',pioneer,[0-9]*,delay,' "$tmp/export/commands.csv")" -eq 7
check "state.csv has the samples" test "$(grep -c '^pioneer,' "$tmp/export/state.csv")" -gt 40
[ -z "$plot" ] && check "the PNG was written" test -s "$tmp/export/session.png"
if [ -z "$plot" ]; then  # the plot's arguments are words, no shell's (before: a quote broke the command)
  "$logplay" export "$tmp/session.lcmlog" -o "$tmp/it's here" >"$tmp/export_quote.out" 2>&1
  check "export to a directory named with a quote writes the PNG too" test -s "$tmp/it's here/session.png"
fi
check "state.csv names the joints from the logged configuration (issue 21)" \
  grep -q '^robot,.*,omega,left_wheel_joint,right_wheel_joint,pan,tilt$' "$tmp/export/state.csv"
check "joints.csv gives their units" grep -q '^pioneer,2,pan,rad,config$' "$tmp/export/joints.csv"
check "export warns of no unnamed robot" test "$(grep -c 'q0' "$tmp/export.out")" -eq 0
if [ -z "$plot" ]; then
  "$py" "$models/../tools/logplay/plot_log.py" --summary "$tmp/export/commands.csv" "$tmp/export/state.csv" \
    "$tmp/export/again.png" "$tmp/export/joints.csv" >"$tmp/plot.txt"
  check "the plot has one axis per joint" test "$(grep -c '^joint axis' "$tmp/plot.txt")" -eq 4
  check "the pan axis is pan's alone" grep -q '^joint axis 2: pioneer: pan (rad)$' "$tmp/plot.txt"
fi

echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
