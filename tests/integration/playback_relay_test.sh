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
#     (+ 1 ms) longer than recorded;
#   - the start (after the first frame arrived) is at most 1.5 x the hindsight
#     minimum + 5 ms (issue 11's quick start chose about 2.5 x the 30 ms spread
#     + 10 ms here: 3-4 x; the bench measures the ratio, docs/performance.md).
# usage: playback_relay_test.sh SERVER RELAY BENCH_CLIENT BENCH_RAW MODELS_DIR   (about 15 s)
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

timeout 40 "$raw" arrivals --url "$B" --robot pioneer --frames 30 --timeout 35 >"$tmp/arrivals" 2>&1 &
apid=$!
sleep 0.3
timeout 40 "$client" playback --url "$A" --robot pioneer --frames 30 --period-ms 100 --stretch-bound 0.1 \
  >"$tmp/playback" 2>&1 || no "playback client: $(tail -3 "$tmp/playback")"
wait $apid || no "arrival log: $(tail -3 "$tmp/arrivals")"
tail -1 "$tmp/playback"
grep '"hindsight_min_s"' "$tmp/arrivals" | sed 's/"lag_ms".*//'

python3 - "$tmp/playback" "$tmp/arrivals" <<'EOF' || fail=1
import json, sys
last = lambda path: json.loads([l for l in open(path) if l.startswith("{")][-1])
p, a = last(sys.argv[1]), last(sys.argv[2])
bad = []
if p["lateness_us"]["n"] != 30: bad.append(f"{p['lateness_us']['n']} replies of 30")
if p["not_run"] != 0: bad.append(f"{p['not_run']} frames did not run")
if p["gaps_over_bound"] != 0: bad.append(f"{p['gaps_over_bound']} frames paused past the stretch bound")
if p["lateness_us"]["max"] > 5000: bad.append(f"a frame started {p['lateness_us']['max']} us late")
if p["max_gap_stretch"] > 0.10 + 0.011: bad.append(f"a gap stretched {p['max_gap_stretch']:.3f}")
h, d = a["hindsight_min_s"], p["chosen_delay_s"]
print(f"start {d * 1e3:.1f} ms after the first arrival, hindsight minimum {h * 1e3:.1f} ms, "
      f"largest gap stretch {p['max_gap_stretch'] * 100:.1f} %, whole sequence {p['total_stretch_s'] * 1e3:.1f} ms longer")
if not 0 <= d <= 1.5 * h + 0.005: bad.append(f"start {d:.4f} s is more than 1.5 x the hindsight minimum {h:.4f} s + 5 ms")
for b in bad: print("FAIL:", b)
sys.exit(1 if bad else 0)
EOF
[ $fail = 0 ] && echo "ok"
exit $fail
