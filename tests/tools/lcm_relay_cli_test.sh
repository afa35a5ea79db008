#!/bin/sh
# robotalk-lcm-relay end to end over UDP multicast: forwards both ways with
# the chosen latency and loss, never sends a message back to its own side,
# and the same seed gives the same losses. Run it inside a private network
# namespace (CTest wraps it in scripts/netns_run.sh, DESIGN.md §4).
# usage: lcm_relay_cli_test.sh robotalk-lcm-relay lcm_probe
set -u
relay=$1; probe=$2
# The split traffic layout (docs/protocol.md) uses 66 ports from each URL's:
# A 7711..7776, B 7811..7876.
A='udpm://239.255.76.67:7711?ttl=0'
B='udpm://239.255.76.67:7811?ttl=0'
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
no() { echo "FAIL: $*"; fail=1; }
# val FILE LINE-PREFIX KEY: the value of KEY=... on the first line starting
# with LINE-PREFIX (relay --stats); pv FILE KEY: the same on a probe's line.
val() { grep "^$2" "$1" | head -1 | tr ' ' '\n' | sed -n "s/^$3=//p"; }
pv() { val "$1" "" "$2"; }
# ge X Y: X >= Y for decimals.
ge() { awk -v x="$1" -v y="$2" 'BEGIN { exit !(x + 0 >= y + 0) }'; }

"$relay" --help | grep -q -- '--congestion-max-ms' || no "--help does not list --congestion-max-ms"
"$relay" --a "$A" --b "$A" 2>/dev/null; [ $? = 2 ] || no "identical URLs were not refused with status 2"
"$relay" --a "$A" --b 'udpm://239.255.76.67:7712?ttl=0' 2>/dev/null; [ $? = 2 ] ||
  no "URLs whose lanes share ports were not refused with status 2"
"$relay" --a "$A" --b "$B" --loss 2 2>/dev/null; [ $? = 2 ] || no "--loss 2 was not refused with status 2"

# One run: A->B 40 ms and 25 % loss, B->A 15 ms and no loss. 200 messages
# A->B every 5 ms, 100 messages B->A every 10 ms.
run() {  # run NAME SEED
  "$relay" --a "$A" --b "$B" --a2b-latency-ms 40 --a2b-loss 0.25 --b2a-latency-ms 15 --seed "$2" \
    --duration 4 --stats >"$tmp/$1.stats" 2>"$tmp/$1.log" &
  rpid=$!
  sleep 0.4
  # Each probe listens 3 s for 1 s of sending: a loaded machine (a TSan run
  # beside other tests) once started the sender late enough that the last 5
  # of 200 messages came after a 2 s window.
  "$probe" recv "$B" A2B 3 >"$tmp/$1.b" &
  "$probe" recv "$A" B2A 3 >"$tmp/$1.a" &
  "$probe" recv "$A" A2B 3 >"$tmp/$1.back" &
  sleep 0.3
  "$probe" send "$A" A2B 200 5 &
  "$probe" send "$B" B2A 100 10 &
  wait $rpid || no "$1: relay exited with $?"
  wait
}

check() {  # check NAME
  s=$tmp/$1.stats
  cat "$s"
  lost=$(val "$s" a2b lost); published=$(val "$s" a2b published)
  [ "$(val "$s" a2b received)" = 200 ] || no "$1: relay heard $(val "$s" a2b received) of 200 on A"
  [ $((lost + published)) = 200 ] || no "$1: lost $lost + published $published != 200"
  [ "$lost" -ge 30 ] && [ "$lost" -le 75 ] || no "$1: lost $lost of 200, expected about 50 (25 %)"
  [ "$(pv "$tmp/$1.b" count)" = "$published" ] || no "$1: B got $(pv "$tmp/$1.b" count), relay published $published"
  [ "$(pv "$tmp/$1.b" duplicates)" = 0 ] || no "$1: duplicates on B"
  ge "$(pv "$tmp/$1.b" min_ms)" 40 || no "$1: A->B faster than 40 ms: $(cat "$tmp/$1.b")"
  ge 70 "$(pv "$tmp/$1.b" mean_ms)" || no "$1: A->B mean far above 40 ms: $(cat "$tmp/$1.b")"
  [ "$(pv "$tmp/$1.a" count)" = 100 ] || no "$1: A got $(pv "$tmp/$1.a" count) of 100 B->A messages"
  ge "$(pv "$tmp/$1.a" min_ms)" 15 || no "$1: B->A faster than 15 ms: $(cat "$tmp/$1.a")"
  ge 45 "$(pv "$tmp/$1.a" mean_ms)" || no "$1: B->A mean far above 15 ms: $(cat "$tmp/$1.a")"
  # No loop: A hears each of its 200 messages once (the sender's own), B->A
  # copies are not sent back to B, and the relay recognised its own echoes.
  [ "$(pv "$tmp/$1.back" count)" = 200 ] || no "$1: A heard $(pv "$tmp/$1.back" count) A2B messages, want 200"
  [ "$(val "$s" a2b echoes)" = "$(val "$s" b2a published)" ] || no "$1: a2b echoes != b2a published"
  [ "$(val "$s" b2a echoes)" = "$published" ] || no "$1: b2a echoes != a2b published"
}

run first 7
check first
run second 7
check second
[ "$(pv "$tmp/first.b" seqs)" = "$(pv "$tmp/second.b" seqs)" ] ||
  no "seed 7 lost different messages: $(cat "$tmp/first.b") / $(cat "$tmp/second.b")"

# Every lane: a request (lane 1, port +1) and client 5's replies (lane 2+5,
# port +7) cross on their own lanes, and do not appear on B's main lane.
REQ=ROBOTALK/r/REQUEST
REP=ROBOTALK/r/REPLY/0000000000000005
"$relay" --a "$A" --b "$B" --duration 2.5 --stats >"$tmp/lanes.stats" 2>"$tmp/lanes.log" &
rpid=$!
sleep 0.6
"$probe" recv 'udpm://239.255.76.67:7812?ttl=0' "$REQ" 1.5 >"$tmp/lanes.req" &
"$probe" recv 'udpm://239.255.76.67:7718?ttl=0' "$REP" 1.5 >"$tmp/lanes.rep" &
"$probe" recv "$B" "$REQ" 1.5 >"$tmp/lanes.main" &
sleep 0.3
"$probe" send 'udpm://239.255.76.67:7712?ttl=0' "$REQ" 20 5 &
"$probe" send 'udpm://239.255.76.67:7818?ttl=0' "$REP" 10 5 &
wait $rpid || no "lanes: relay exited with $?"
wait
[ "$(pv "$tmp/lanes.req" count)" = 20 ] || no "lanes: B's request lane got $(pv "$tmp/lanes.req" count) of 20"
[ "$(pv "$tmp/lanes.rep" count)" = 10 ] || no "lanes: reply lane 7 of A got $(pv "$tmp/lanes.rep" count) of 10"
[ "$(pv "$tmp/lanes.main" count)" = 0 ] || no "lanes: B's main lane carried requests"

# The release queue is bounded (gaps14): A->B through a congested link
# serving 20 a second (100 ms at most each) while 200 arrive a second, with
# --max-queue 10: what arrives past 10 queued is dropped, counted as
# queue_dropped, and every message heard is accounted for.
"$relay" --help | grep -q -- '--max-queue' || no "--help does not list --max-queue"
"$relay" --a "$A" --b "$B" --a2b-congestion-max-ms 100 --max-queue 10 --duration 2.5 --stats \
  >"$tmp/bound.stats" 2>"$tmp/bound.log" &
rpid=$!
sleep 0.4
"$probe" send "$A" A2B 200 5
wait $rpid || no "bound: relay exited with $?"
cat "$tmp/bound.stats"
s=$tmp/bound.stats
qd=$(val "$s" a2b queue_dropped)
[ "${qd:-0}" -ge 100 ] || no "bound: queue_dropped=$qd, expected most of 200 past a queue of 10"
[ $(($(val "$s" a2b published) + $(val "$s" a2b unreleased) + qd)) = "$(val "$s" a2b received)" ] ||
  no "bound: published + unreleased + queue_dropped != received"
[ "$(val "$s" a2b unreleased)" -le 10 ] || no "bound: $(val "$s" a2b unreleased) unreleased, more than the bound"

[ $fail = 0 ] && echo "lcm relay end to end: all passed"
exit $fail
