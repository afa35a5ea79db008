#!/usr/bin/env bash
# Deadlines and link health end to end (issue 23): robotalk-server on side B,
# robotalk-lcm-relay between A and B (20 ms each way, 5 % loss client ->
# server, seed 3), robotalk-bench-link on side A. Run inside a private network
# namespace (scripts/netns_run.sh). Asserts:
#   health: the session's link_loss is within 1 % of the loss the relay
#       applied to client -> server messages (its --stats), and link_delay_s
#       (half the client's median network round trip) within 2 ms of the
#       mean of the relay's measured means of both directions (20 ms + its
#       own late wake-ups);
#   health on the WAN profile (a second server and relay, 100 ms +- 50 ms
#       uniform and 1 % loss each way, seed 5, while the stall probes run):
#       the same;
#   stall (the robot's default --max-late 0.1 s): no frame ran more than
#       0.1 s late; at least 240 of the 250 frames of the 5 s burst expired
#       (INTERRUPTED) and expired_commands counts them;
#   stall with max_late never (the paper's "run late"): the burst runs, seconds late.
# usage: link_relay_test.sh SERVER RELAY PROBE MODELS_DIR   (about 30 s)
set -u
server=$1 relay=$2 probe=$3 models=$4
A='udpm://239.255.76.67:7931?ttl=0'
B='udpm://239.255.76.67:8031?ttl=0'
# Every URL is 66 ports wide (the split layout's lanes, traffic_layout.h).
WA='udpm://239.255.76.67:8131?ttl=0'
WB='udpm://239.255.76.67:8231?ttl=0'
tmp=$(mktemp -d)
fail=0
no() { echo "FAIL: $*"; fail=1; }
val() { sed -n "s/^$2=//p" "$1" | head -1; }
near() { awk -v x="$1" -v y="$2" -v t="$3" 'BEGIN { d = x - y; if (d < 0) d = -d; exit !(d <= t) }'; }

"$server" --robot pioneer=kinematic:"$models"/pioneer2dx_pantilt.urdf --url "$B" --duration 80 \
  --no-panic-latch 2>"$tmp/server.log" &
spid=$!
"$relay" --a "$A" --b "$B" --latency-ms 20 --a2b-loss 0.05 --seed 3 --duration 75 --stats \
  >"$tmp/relay.stats" 2>"$tmp/relay.log" &
rpid=$!
"$server" --robot pioneer=kinematic:"$models"/pioneer2dx_pantilt.urdf --url "$WB" --duration 80 \
  --no-panic-latch 2>"$tmp/wserver.log" &
wspid=$!
"$relay" --a "$WA" --b "$WB" --profile wan --seed 5 --duration 75 --stats \
  >"$tmp/wrelay.stats" 2>"$tmp/wrelay.log" &
wrpid=$!
trap 'kill $spid $rpid $wspid $wrpid 2>/dev/null; rm -rf "$tmp"' EXIT
for _ in $(seq 100); do
  grep -q "serving robot" "$tmp/server.log" 2>/dev/null && grep -q "serving robot" "$tmp/wserver.log" 2>/dev/null &&
    break
  sleep 0.1
done
# The WAN health run goes on beside the others: 1500 queries at 200 Hz.
timeout 60 "$probe" "$WA" pioneer health 1500 5 >"$tmp/whealth" 2>&1 &
wppid=$!

# Health: 1500 queries at 200 Hz (7.5 s). The relay counts what it dropped
# once it exits: stop it after the probe (SIGINT prints the stats).
timeout 40 "$probe" "$A" pioneer health 1500 5 >"$tmp/health" 2>&1 || no "health probe: $(cat "$tmp/health")"
# Stall, with the robot's default deadline, then without any.
timeout 40 "$probe" "$A" pioneer stall default >"$tmp/stall" 2>&1 || no "stall probe: $(tail -3 "$tmp/stall")"
timeout 40 "$probe" "$A" pioneer stall never >"$tmp/never" 2>&1 || no "stall probe (never): $(tail -3 "$tmp/never")"
kill -INT $rpid; wait $rpid
cat "$tmp/relay.stats"
grep "^link_\|^expired\|^queries" "$tmp/health"

# Health figures against what the relay did: the loss it applied client ->
# server; the delay against the mean of its two directions' measured means
# (the definition, docs/server.md; the relay's own late wake-ups count).
check_health() {  # NAME RELAY_STATS HEALTH_OUTPUT
  local lost received injected mean loss delay
  lost=$(sed -n 's/^a2b:.*lost=\([0-9]*\).*/\1/p' "$2")
  received=$(sed -n 's/^a2b: received=\([0-9]*\).*/\1/p' "$2")
  injected=$(awk -v l="$lost" -v r="$received" 'BEGIN { printf "%.5f", l / r }')
  mean=$(sed -n 's/^[ab]2[ab]:.*mean_delay_ms=\([0-9.]*\).*/\1/p' "$2" |
    awk '{ s += $1; n++ } END { if (n == 2) printf "%.6f", s / n / 1000 }')
  loss=$(val "$3" link_loss) delay=$(val "$3" link_delay_s)
  echo "$1: relay dropped $lost of $received client -> server messages ($injected), mean delay ${mean} s;" \
    "health: loss $loss, delay $delay s"
  [ -n "$mean" ] || no "$1: the relay's stats have no mean delays"
  near "$loss" "$injected" 0.01 || no "$1: health reports loss $loss, the relay dropped $injected"
  near "$delay" "${mean:-0}" 0.002 || no "$1: health reports delay $delay s, the relay's mean is $mean s"
}
check_health "20 ms" "$tmp/relay.stats" "$tmp/health"

wait $wppid || no "WAN health probe: $(cat "$tmp/whealth")"
kill -INT $wrpid; wait $wrpid
cat "$tmp/wrelay.stats"
grep "^link_\|^queries" "$tmp/whealth"
check_health WAN "$tmp/wrelay.stats" "$tmp/whealth"

# Stall with deadlines: nothing ran past 0.1 s; the burst expired.
awk '$4 == "SUCCESS" || $4 == "MODIFIED" { if ($5 > 0.101) { print "ran late:", $0; bad = 1 } } END { exit bad }' \
  "$tmp/stall" || no "a frame ran more than 0.1 s late"
expired=$(awk '$1 == "frame" && $3 == "burst" && $4 == "INTERRUPTED"' "$tmp/stall" | wc -l)
ran=$(awk '$1 == "frame" && $3 == "burst" && ($4 == "SUCCESS" || $4 == "MODIFIED")' "$tmp/stall" | wc -l)
echo "stall with deadlines: $expired of 250 burst frames expired, $ran ran (within 0.1 s of their start)"
[ "$expired" -ge 240 ] || no "only $expired burst frames expired"
counted=$(val "$tmp/stall" expired_commands)
[ "${counted%.*}" -ge "$expired" ] || no "expired_commands $counted < $expired"
after=$(awk '$1 == "frame" && $3 == "after" && $4 == "SUCCESS"' "$tmp/stall" | wc -l)
[ "$after" -ge 40 ] || no "only $after of 50 frames after the stall ran"
# Without deadlines the burst runs late.
late=$(awk '$1 == "frame" && $3 == "burst" && $4 == "SUCCESS" && $5 > 1' "$tmp/never" | wc -l)
echo "stall without deadlines: $late burst frames ran more than 1 s late"
[ "$late" -ge 150 ] || no "only $late burst frames ran late without deadlines"
[ $fail = 0 ] && echo "ok"
exit $fail
