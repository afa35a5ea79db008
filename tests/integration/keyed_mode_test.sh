#!/usr/bin/env bash
# Keyed mode end to end (issue 9): a server with --key and --clients, CLI
# processes with and without keys, rights per key. Runs inside a private
# network namespace (CTest wraps it with scripts/netns_run.sh).
#   keyed_mode_test.sh SERVER CLI KEYGEN MODELS_DIR
set -u
server_bin=$1 cli=$2 keygen=$3 models=$4
url="udpm://239.255.76.67:7600?ttl=0"
. "$(dirname "$0")/../lib.sh"  # $tmp, $server_pid, check
rt() { "$cli" --url "$url" --timeout 3 "$@"; }

for who in server alice monitor viewer stranger; do "$keygen" --out "$tmp/$who" --name "$who" >/dev/null; done
{
  echo "$(cat "$tmp/alice.pub") *=all"
  echo "$(cat "$tmp/monitor.pub") *=query,panic"
  echo "$(cat "$tmp/viewer.pub") *=query"
} >"$tmp/clients"
chmod 644 "$tmp/clients"

start_pioneer "$tmp/server.log" --url "$url" --key "$tmp/server" --clients "$tmp/clients" --duration 60
check "the server says it runs keyed" grep -q "keyed mode: 3 client keys" "$tmp/server.log"

rt --key "$tmp/alice" query pioneer base_pose >"$tmp/alice_query" 2>&1
check "alice may query: $(cat "$tmp/alice_query")" grep -q "SUCCESS" "$tmp/alice_query"
rt query pioneer base_pose >"$tmp/open" 2>&1
check "a client without a key is refused with the reason: $(cat "$tmp/open")" grep -q "keyed mode: give the client a key" "$tmp/open"
rt --key "$tmp/stranger" query pioneer base_pose >"$tmp/stranger_out" 2>&1
check "an unlisted key is refused: $(cat "$tmp/stranger_out")" grep -q "not in the access list" "$tmp/stranger_out"
ROBOTALK_KEY="$tmp/alice" rt send pioneer joint_setpoint pan 0.3 >"$tmp/env" 2>&1
check "ROBOTALK_KEY works like --key: $(cat "$tmp/env")" grep -q "SUCCESS" "$tmp/env"
rt --key "$tmp/monitor" send pioneer joint_setpoint pan -1 >"$tmp/monitor_cmd" 2>&1
check "monitor may not command: $(cat "$tmp/monitor_cmd")" grep -q "monitor" "$tmp/monitor_cmd"
# Issue 19 item 2: a query-only key's panic printed "panic acknowledged" and
# exited 0 while the robot went on moving.
rt --key "$tmp/viewer" panic pioneer >"$tmp/viewer_panic" 2>&1
status=$?
check "a panic refused for rights exits non-zero (status $status)" test "$status" -ne 0
check "and says REFUSED with the server's reason: $(cat "$tmp/viewer_panic")" \
  grep -q "panic REFUSED by pioneer: .*may not panic robot 'pioneer'" "$tmp/viewer_panic"
rt --key "$tmp/alice" send pioneer joint_setpoint pan 0.1 >"$tmp/after_refused" 2>&1
check "the robot is not in panic after the refused one: $(cat "$tmp/after_refused")" \
  grep -q "SUCCESS" "$tmp/after_refused"
rt --key "$tmp/monitor" panic pioneer >"$tmp/monitor_panic" 2>&1
check "monitor may raise a panic: $(cat "$tmp/monitor_panic")" grep -q "panic taken by pioneer" "$tmp/monitor_panic"
# Issue 19: the line alone proved nothing; the robot must really be in panic.
rt --key "$tmp/viewer" watch pioneer --count 1 --json >"$tmp/panic_state" 2>&1
check "after monitor's panic the STATE stream says panic: $(cat "$tmp/panic_state")" \
  grep -q '"panic":true' "$tmp/panic_state"
rt --key "$tmp/alice" send pioneer joint_setpoint pan 0.2 >"$tmp/in_panic" 2>&1
check "and alice's command is answered PANIC, not run: $(cat "$tmp/in_panic")" grep -q " PANIC " "$tmp/in_panic"
rt --key "$tmp/monitor" reset pioneer >"$tmp/monitor_reset" 2>&1
check "monitor may not reset it: $(cat "$tmp/monitor_reset")" grep -q "ERROR" "$tmp/monitor_reset"
rt --key "$tmp/alice" reset pioneer >"$tmp/alice_reset" 2>&1
check "alice may reset: $(cat "$tmp/alice_reset")" grep -q "SUCCESS" "$tmp/alice_reset"
rt --key "$tmp/alice" send pioneer joint_setpoint pan 0.2 >"$tmp/after_reset" 2>&1
check "after alice's reset the robot runs commands again: $(cat "$tmp/after_reset")" \
  grep -q "SUCCESS" "$tmp/after_reset"
check "the reset is logged with the key's name" grep -q "panic reset by 'alice' (rt:" "$tmp/server.log"
rt --key "$tmp/alice" --server-key "$tmp/alice.pub" query pioneer base_pose >"$tmp/pinned" 2>&1
check "a pinned server key that does not match is refused: $(cat "$tmp/pinned")" grep -q "given with --server-key; refused" "$tmp/pinned"
chmod 664 "$tmp/clients"
"$server_bin" --robot "other=kinematic:$models/pioneer2dx_pantilt.urdf" --url "$url" \
  --key "$tmp/server" --clients "$tmp/clients" --duration 1 >"$tmp/writable" 2>&1
check "an access list others may write is refused: $(cat "$tmp/writable")" grep -q "chmod" "$tmp/writable"

echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
