#!/usr/bin/env bash
# Playback over a jittery link end to end (issue 23 item 3): robotalk-server
# (its default, adaptive playback start) on side B, robotalk-lcm-relay between
# A and B (client -> server: 20 ms +- 15 ms uniform jitter, seed 5), a paced
# 30-frame playback sequence at 10 Hz from robotalk-bench-client on side A,
# and robotalk-bench-raw's arrival log on side B (the hindsight minimum: the
# least start after the first arrival with no frame late). Run inside a
# private network namespace (scripts/netns_run.sh). Asserts:
#   - every frame ran (SUCCESS), none paused past the stretch bound, none
#     started more than 5 ms after its time (the RobotDaemon's wake-up on a
#     loaded 2-core machine; the schedule itself never places a frame before
#     its arrival + 2 ms);
#   - no gap between successive frames' execution played more than 10 %
#     (+ 1 ms) longer than recorded (the default; 25 % only with
#     --playback-thin-stretch 0.25, an option);
#   - the start (after the first frame arrived) is at most 1.5 x the hindsight
#     minimum + 5 ms (issue 11's quick start chose about 2.5 x the 30 ms spread
#     + 10 ms here: 3-4 x; the bench measures the ratio, docs/performance.md).
# A loaded machine (a build beside it) can delay frames by hundreds of ms,
# more than the link: such a run (hindsight minimum above 60 ms) holds only
# the start's bound and "every frame ran", and is tried again (3 times at
# most; then it skips, exit 77).
# usage: playback_relay_test.sh SERVER RELAY BENCH_CLIENT BENCH_RAW MODELS_DIR   (about 6 s, 25 s at most)
set -u
server=$1 relay=$2 client=$3 raw=$4 models=$5
A='udpm://239.255.76.67:7937?ttl=0'
B='udpm://239.255.76.67:8037?ttl=0'
tmp=$(mktemp -d)
fail=0
no() { echo "FAIL: $*"; fail=1; }

"$server" --robot pioneer=kinematic:"$models"/pioneer2dx_pantilt.urdf --url "$B" --duration 60 \
  --no-panic-latch 2>"$tmp/server.log" &
spid=$!
"$relay" --a "$A" --b "$B" --a2b-latency-ms 20 --a2b-jitter-ms 15 --seed 5 --duration 55 2>"$tmp/relay.log" &
rpid=$!
trap 'kill $spid $rpid 2>/dev/null; rm -rf "$tmp"' EXIT
for _ in $(seq 100); do grep -q "serving robot" "$tmp/server.log" 2>/dev/null && break; sleep 0.1; done

# One attempt: the arrival log and the sequence; returns 0 (all held), 1 (a
# failure) or 3 (the machine, not the link, delayed the frames: the hindsight
# minimum exceeds the relay's 30 ms spread by more than 30 ms, as when a build
# runs beside it; then only the start's bound and "every frame ran" are held).
attempt() {
  timeout 40 "$raw" arrivals --url "$B" --robot pioneer --frames 30 --timeout 35 >"$tmp/arrivals" 2>&1 &
  apid=$!
  sleep 0.3
  timeout 40 "$client" playback --url "$A" --robot pioneer --frames 30 --period-ms 100 --stretch-bound 0.1 \
    >"$tmp/playback" 2>&1 || { echo "FAIL: playback client: $(tail -3 "$tmp/playback")"; return 1; }
  wait $apid || { echo "FAIL: arrival log: $(tail -3 "$tmp/arrivals")"; return 1; }
  tail -1 "$tmp/playback"
  python3 - "$tmp/playback" "$tmp/arrivals" <<'EOF'
import json, sys
last = lambda path: json.loads([l for l in open(path) if l.startswith("{")][-1])
p, a = last(sys.argv[1]), last(sys.argv[2])
h, d = a["hindsight_min_s"], p["chosen_delay_s"]
print(f"start {d * 1e3:.1f} ms after the first arrival, hindsight minimum {h * 1e3:.1f} ms, "
      f"largest gap stretch {p['max_gap_stretch'] * 100:.1f} %, whole sequence {p['total_stretch_s'] * 1e3:.1f} ms longer")
bad = []
if p["lateness_us"]["n"] != 30: bad.append(f"{p['lateness_us']['n']} replies of 30")
if p["not_run"] != 0: bad.append(f"{p['not_run']} frames did not run")
if not 0 <= d <= 1.5 * h + 0.005: bad.append(f"start {d:.4f} s is more than 1.5 x the hindsight minimum {h:.4f} s + 5 ms")
disturbed = h > 0.060
if not disturbed:
    if p["gaps_over_bound"] != 0: bad.append(f"{p['gaps_over_bound']} frames paused past the stretch bound")
    if p["lateness_us"]["max"] > 5000: bad.append(f"a frame started {p['lateness_us']['max']} us late")
    if p["max_gap_stretch"] > 0.10 + 0.011: bad.append(f"a gap stretched {p['max_gap_stretch']:.3f}")
for b in bad: print("FAIL:", b)
sys.exit(1 if bad else 3 if disturbed else 0)
EOF
}
held=0
for try in 1 2 3; do
  attempt
  rc=$?
  if [ $rc = 1 ]; then fail=1; break; fi
  if [ $rc = 0 ]; then held=1; break; fi
  echo "attempt $try: the machine delayed the frames (hindsight minimum above 60 ms); again"
  sleep 1
done
if [ $fail = 0 ] && [ $held = 0 ]; then
  echo "SKIP: three attempts, each delayed by the machine beyond the link's jitter"
  exit 77
fi
[ $fail = 0 ] && echo "ok"
exit $fail
