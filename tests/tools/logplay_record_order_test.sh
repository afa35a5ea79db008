#!/usr/bin/env bash
# Issue 19 item 13: `robotalk-logplay record` wrote replies before their
# requests (6 of 19 in a direct-mode session: events stamped at dispatch
# across the split layout's 66 lanes), so `info` miscounted the replies and
# `export` lost their signals. A direct-mode session of 40 commands on the
# split layout is recorded; info and export must count a reply for every
# command (a reply written before its request is matched to nothing).
# Runs inside a private network namespace (CTest wraps it with netns_run.sh).
#   logplay_record_order_test.sh SERVER CLI LOGPLAY MODELS_DIR
set -u
server_bin=$1 cli=$2 logplay=$3 models=$4
url="udpm://239.255.76.67:7831?ttl=0"
. "$(dirname "$0")/../lib.sh"
rt() { "$cli" --url "$url" "$@"; }

start_pioneer "$tmp/server.log" --url "$url" --duration 60

"$logplay" record -o "$tmp/session.lcmlog" --lcm-url "$url" -c 'ROBOTALK/.*' 2>"$tmp/record.log" &
logger=$!
wait_for "$tmp/record.log" "recording"
sleep 0.3

n=40
awk -v n=$n 'BEGIN { for (i = 0; i < n; i++) printf "%.2f joint_setpoint pan %.2f\n", i * 0.01, (i % 10) / 20 }' \
  >"$tmp/seq.txt"
rt send pioneer --file "$tmp/seq.txt" --mode direct >"$tmp/send.out" 2>&1
check "the direct-mode session succeeds" test "$(grep -c SUCCESS "$tmp/send.out")" -eq $n
sleep 0.5
kill -INT "$logger"; wait "$logger"
check "record stops on SIGINT with status 0: $(cat "$tmp/record.log")" test $? -eq 0

"$logplay" info "$tmp/session.lcmlog" >"$tmp/info.txt" 2>&1
check "info counts $n commands" grep -q "commands $n in mode direct: JOINT_SETPOINT $n" "$tmp/info.txt"
check "info counts a reply for every command: $(grep replies "$tmp/info.txt")" grep -q "replies SUCCESS $n\$" "$tmp/info.txt"

"$logplay" export "$tmp/session.lcmlog" -o "$tmp/csv" --no-plot >/dev/null 2>&1
check "export writes commands.csv" test -s "$tmp/csv/commands.csv"
rows=$(tail -n +2 "$tmp/csv/commands.csv" | wc -l)
# column 11 is the signal (docs/logplay.md)
signals=$(tail -n +2 "$tmp/csv/commands.csv" | awk -F, '$11 != ""' | wc -l)
check "export has $n command rows (got $rows)" test "$rows" -eq $n
check "export keeps every signal (got $signals of $rows)" test "$signals" -eq $n

echo "logplay record order: $pass passed, $failures failed"
[ "$failures" -eq 0 ]
