#!/usr/bin/env bash
# `robotalk watch` when its server goes away, and `query --timeout 1` with no
# server (issue 21 item 5): Ctrl-C ends watch at once with 0, also once the
# server is gone; a vanished server is noticed (no STATE, no announcement for
# 3 s), said, and ends watch with 1; a short --timeout without any server
# gives the "no robot" hint. Runs inside a private network namespace (CTest
# wraps it with netns_run.sh).
#   cli_watch_test.sh SERVER CLI MODELS_DIR
set -u
server_bin=$1 cli=$2 models=$3
url="udpm://239.255.76.67:7816?ttl=0"
. "$(dirname "$0")/../lib.sh"  # $tmp, $server_pid, check
rt() { "$cli" --url "$url" "$@"; }
now() { date +%s.%N; }
took() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", b - a }'; }
under() { awk -v t="$1" -v m="$2" 'BEGIN { exit !(t < m) }'; }

# --- query --timeout 1 without a server: the "no robot" hint ------------------
rt --timeout 1 query pioneer base_pose >"$tmp/query.out" 2>&1; status=$?
check "query without a server exits 1 (got $status)" test "$status" -eq 1
check "it gives the no-robot hint: $(cat "$tmp/query.out")" \
  grep -q "no robot 'pioneer' answered within 1 s and no server announced itself" "$tmp/query.out"
check "not the HELLO message" sh -c "! grep -qi hello '$tmp/query.out'"

start_server() {
  start_pioneer "$tmp/server.log" --url "$url" --duration 60
}
stop_server() { kill "$server_pid"; wait "$server_pid" 2>/dev/null; server_pid=""; }
# Starts watch in its own session (a background job of a non-interactive shell
# ignores SIGINT) and waits for its first samples; its pid in $bg.
start_watch() {
  : >"$tmp/watch.out"
  setsid "$cli" --url "$url" watch pioneer --period 0.05 >"$tmp/watch.out" 2>"$tmp/watch.err" &
  bg=$!
  for _ in $(seq 50); do [ "$(wc -l <"$tmp/watch.out")" -ge 3 ] && return 0; sleep 0.1; done
  return 1
}

# --- Ctrl-C with the server there: at once, exit 0 ----------------------------
start_server
check "watch prints samples" start_watch
t0=$(now); kill -INT "$bg"; wait "$bg"; status=$?; t1=$(now)
check "Ctrl-C ends watch with 0 (got $status)" test "$status" -eq 0
check "in $(took "$t0" "$t1") s (< 0.5 s)" under "$(took "$t0" "$t1")" 0.5

# --- Ctrl-C once the server is gone: at once, exit 0 (was 5.1 s, exit 1) ------
check "watch prints samples again" start_watch
stop_server
sleep 1
t0=$(now); kill -INT "$bg"; wait "$bg"; status=$?; t1=$(now)
check "Ctrl-C after the server went ends watch with 0 (got $status): $(cat "$tmp/watch.err")" test "$status" -eq 0
check "in $(took "$t0" "$t1") s (< 0.5 s) after the server went" under "$(took "$t0" "$t1")" 0.5

# --- The server vanishes: watch says so and ends with 1 -----------------------
start_server
check "watch prints samples a third time" start_watch
t0=$(now); kill -KILL "$server_pid"; wait "$server_pid" 2>/dev/null; server_pid=""
for _ in $(seq 80); do kill -0 "$bg" 2>/dev/null || break; sleep 0.1; done
kill -KILL "$bg" 2>/dev/null  # still watching after 8 s: it did not notice
wait "$bg"; status=$?; t1=$(now)
check "a vanished server ends watch with 1 (got $status)" test "$status" -eq 1
check "watch says the server is gone: $(cat "$tmp/watch.err")" \
  grep -q "pioneer: no STATE sample and no announcement for 3 s: its server is gone" "$tmp/watch.err"
check "it noticed in $(took "$t0" "$t1") s (3 s of silence, < 5 s)" under "$(took "$t0" "$t1")" 5

echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
