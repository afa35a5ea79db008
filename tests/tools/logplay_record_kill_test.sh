#!/usr/bin/env bash
# docs/logplay.md: "a recording loses at most 1.25 s when the recorder is
# killed". A server streams STATE at 1 Hz (a `robotalk watch` asks for it;
# sparse, so the recorder's file buffer never fills and only its own flushes
# write); `robotalk-logplay record` is killed with SIGKILL 6 times, at
# different phases of its flush; each time the log must hold every event
# received up to 1.25 s before the kill. A reference recorder runs
# throughout and is stopped cleanly (it writes everything): the first event
# a killed log lost is the one the reference received after the last event
# the killed log holds (matched by channel and bytes: each recorder stamps
# its own receipt). Prints each measured loss.
# Runs inside a private network namespace (CTest wraps it with netns_run.sh).
#   logplay_record_kill_test.sh SERVER CLI LOGPLAY MODELS_DIR
set -u
server_bin=$1 cli=$2 logplay=$3 models=$4
url="udpm://239.255.76.67:7833?ttl=0"
. "$(dirname "$0")/../lib.sh"

start_pioneer "$tmp/server.log" --url "$url" --duration 90
"$cli" --url "$url" watch pioneer --period 1 >/dev/null 2>&1 &
client_pid=$!
sleep 0.5

record() {  # record LOG NAME: a recorder in the background, once it listens
  "$logplay" record -o "$1" --lcm-url "$url" -c 'ROBOTALK/.*' 2>"$tmp/$2.log" &
  recorder=$!
  wait_for "$tmp/$2.log" "recording" 50 0.05
}
record "$tmp/reference.lcmlog" reference
reference=$recorder
pids+=("$reference")

kills=()
for k in 1 2 3 4 5 6; do
  record "$tmp/kill$k.lcmlog" "record$k"
  sleep "$(python3 -c "print(1.5 + 0.19 * $k)")" # 1.69 .. 2.64 s: every phase of a 1 s flush period
  kills+=("$(date +%s.%N)")
  kill -9 "$recorder"
  wait "$recorder" 2>/dev/null
done
sleep 0.5
kill -INT "$reference"
wait "$reference"

# Per killed log: how long before the kill its first lost event was received.
cat >"$tmp/losses.py" <<'PY'
import struct, sys
def events(path):
    data, pos, out = open(path, "rb").read(), 0, []
    while pos + 28 <= len(data):
        sync, _, stamp, clen, dlen = struct.unpack(">IqqII", data[pos:pos + 28])
        if sync != 0xEDA1DA01 or pos + 28 + clen + dlen > len(data):
            break
        out.append((stamp / 1e6, data[pos + 28:pos + 28 + clen + dlen]))
        pos += 28 + clen + dlen
    return out
tmp, kills = sys.argv[1], [float(k) for k in sys.argv[2:]]
reference = events(tmp + "/reference.lcmlog")
for k, killed in enumerate(kills, 1):
    got = events(f"{tmp}/kill{k}.lcmlog")
    have = set(e for _, e in got)
    # The kill cuts the log's tail (events are written in receipt order):
    # the first event lost is the one the reference received after the last
    # one the killed log holds.
    last = max((i for i, (_, e) in enumerate(reference) if e in have), default=None)
    after = [stamp for stamp, _ in reference[last + 1:] if stamp <= killed] if last is not None else []
    lost = killed - after[0] if after else 0.0
    print(k, len(got), f"{lost:.3f}")
PY
python3 "$tmp/losses.py" "$tmp" "${kills[@]}" >"$tmp/losses.txt"

while read -r k events lost; do
  echo "kill $k: $events events on disk; the first event missing was received $lost s before the kill"
  check "kill $k: the log holds events" test "$events" -gt 0
  check "kill $k: at most 1.25 s lost (measured $lost s)" python3 -c "import sys; sys.exit(0 if $lost <= 1.25 else 1)"
done <"$tmp/losses.txt"
check "every kill measured" test "$(wc -l <"$tmp/losses.txt")" -eq 6

echo "logplay record kill: $pass passed, $failures failed"
[ "$failures" -eq 0 ]
