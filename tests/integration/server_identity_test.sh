#!/usr/bin/env bash
# Which server (issue 19 items 3, 4, 7, and item 12's refused robot) across
# processes, inside a private network namespace (scripts/netns_run.sh):
#   - a forged ANNOUNCE leaves the serving server serving;
#   - a keyed CLI pins the server key on first use and says so; `watch`
#     prints no forged STATE; a server with another key is refused
#     (`send ... goto` never reaches it) unless --server-key names it;
#   - a server started while another serves its only robot exits 1.
#   server_identity_test.sh SERVER CLI KEYGEN FORGE MODELS_DIR
set -u
server_bin=$1 cli=$2 keygen=$3 forge=$4 models=$5
url="udpm://239.255.76.67:7610?ttl=0"
. "$(dirname "$0")/../lib.sh"  # $tmp, $server_pid, check; ROBOTALK_KNOWN_SERVERS in $tmp
pins=$ROBOTALK_KNOWN_SERVERS
rt() { "$cli" --url "$url" --timeout 3 --key "$tmp/alice" "$@"; }
serve() {  # serve KEY LOG: a keyed server of pioneer
  start_pioneer "$tmp/$2" --url "$url" --log-executions --key "$tmp/$1" --clients "$tmp/clients" --duration 60
}

for who in server mallory alice; do "$keygen" --out "$tmp/$who" --name "$who" >/dev/null; done
echo "$(cat "$tmp/alice.pub") *=all" >"$tmp/clients"  # public: an impersonator may copy it
chmod 644 "$tmp/clients"
fp() { "$keygen" --fingerprint "$tmp/$1.pub" | cut -d' ' -f1; }

serve server real.log
rt query pioneer base_pose >"$tmp/first" 2>&1
check "first use pins the server key and says so: $(cat "$tmp/first")" \
  grep -q "first connection to robot 'pioneer': trusting its server key $(fp server)" "$tmp/first"
check "the pin file names the robot, the network and the key" \
  grep -qx "pioneer udpm://239.255.76.67:7610 $(cut -d' ' -f1 "$tmp/server.pub")" "$pins"
rt query pioneer base_pose >"$tmp/second" 2>&1
check "the second time says nothing: $(cat "$tmp/second")" bash -c "! grep -q 'first connection' '$tmp/second'"

# Item 3: a forged ANNOUNCE (another server, a year of uptime) is logged; nothing
# else, once the server's 2 s start-up window (when the duplicate rule applies) is over.
sleep 2
"$forge" "$url" announce pioneer 20
sleep 1.2
rt query pioneer base_pose >"$tmp/after_announce" 2>&1
check "after a forged ANNOUNCE the robot still answers: $(cat "$tmp/after_announce")" \
  grep -q SUCCESS "$tmp/after_announce"
check "the server logged the conflict and kept the robot" grep -q "keeps serving it" "$tmp/real.log"
check "the server refused nothing" bash -c "! grep -q 'refuses it' '$tmp/real.log'"
rt robots --listen 1.2 >"$tmp/robots" 2>&1
check "robots shows the pinned key: $(cat "$tmp/robots")" grep -q "$(fp server) (pinned)" "$tmp/robots"
# A flood of forged names (1,100 of them, four times): the list stops at 1,024
# robots and says so.
"$forge" "$url" announce-names flood 1100 4 &
flood_pid=$!
rt robots --listen 1.5 >"$tmp/flood_robots" 2>"$tmp/flood_robots.err"
wait "$flood_pid"
check "a flood of names is listed up to 1,024 robots: $(($(wc -l <"$tmp/flood_robots") - 1)) listed" \
  test "$(($(wc -l <"$tmp/flood_robots") - 1))" -le 1024
check "and robots warns of the names it did not list: $(cat "$tmp/flood_robots.err")" \
  grep -q "listing the first 1024 robots heard; [1-9][0-9]* announcements named others" "$tmp/flood_robots.err"

# Item 7: forged STATE (unsigned, and signed by another key) is not printed by a keyed watch.
rt watch pioneer --period 0.05 --duration 3 >"$tmp/watch" 2>"$tmp/watch.err" &
watch_pid=$!
sleep 1
"$forge" "$url" state pioneer 4 40
wait "$watch_pid"
check "watch printed the real samples: $(wc -l <"$tmp/watch")" test "$(wc -l <"$tmp/watch")" -ge 10
check "watch printed no forged sample: $(grep -c ' 42.0000 42.0000' "$tmp/watch")" \
  bash -c "! grep -q ' 42.0000 42.0000' '$tmp/watch'"
check "watch says how many it dropped: $(cat "$tmp/watch.err")" grep -q "dropped [0-9]* STATE/CONFIG messages" "$tmp/watch.err"

# A keyed watch counts only announcements its server signed: forged ones
# (unsigned, another server) do not keep it watching a server that is gone
# (here stopped with SIGSTOP, a hung host).
# watch_a_stopped_server NAME FORGE_AFTER STOP_AFTER FORGE_ARGS...: a keyed
# `watch` of pioneer (out and err in $tmp/NAME, $tmp/NAME.err); FORGE_AFTER s
# later the forger runs FORGE_ARGS, STOP_AFTER s after that the server is
# stopped (SIGSTOP, a hung host). The watch's exit status, or 137 when it was
# still watching 6 s later, is in $status.
watch_a_stopped_server() {
  local name=$1 forge_after=$2 stop_after=$3
  shift 3
  rt watch pioneer --period 0.05 --duration 30 >"$tmp/$name" 2>"$tmp/$name.err" &
  watch_pid=$!
  sleep "$forge_after"
  "$forge" "$url" "$@" 2>"$tmp/$name.forge" &
  forge_pid=$!
  sleep "$stop_after"
  kill -STOP "$server_pid"
  for _ in $(seq 60); do kill -0 "$watch_pid" 2>/dev/null || break; sleep 0.1; done
  kill -KILL "$watch_pid" 2>/dev/null  # still watching after 6 s: the forger kept it
  wait "$watch_pid"
  status=$?
  kill "$forge_pid" 2>/dev/null  # the watch's verdict is in: the rest of the forgery (up to 8 s) tells nothing
  wait "$forge_pid"
  kill -CONT "$server_pid"
}
watch_a_stopped_server watch_gone 1 0 announce pioneer 600  # 6 s of forged ANNOUNCEs naming pioneer
check "a keyed watch ends with 1 when its server is gone, forged announcements or not (got $status)" \
  test "$status" -eq 1
check "and says so: $(tail -2 "$tmp/watch_gone.err")" grep -q "pioneer: no STATE sample and no announcement for 3 s: its server is gone" "$tmp/watch_gone.err"

# A keyed watch counts its server's signed announcements as of their signed
# server time: a recording of them, replayed once the server is gone (here
# stopped with SIGSTOP), is stale and keeps nothing alive (review8: it did).
watch_a_stopped_server watch_replay 0 1.7 replay-announce pioneer 1.5 8  # 1.5 s recorded, 8 s replayed
check "the forger recorded the server's announcements: $(cat "$tmp/watch_replay.forge")" \
  grep -q "recorded [1-9]" "$tmp/watch_replay.forge"
check "a keyed watch ends with 1 when its server is gone, its announcements replayed or not (got $status)" \
  test "$status" -eq 1
check "and says the replayed ones were stale: $(grep stale "$tmp/watch_replay.err")" \
  grep -q "refused [0-9]* announcements signed by the server but stale" "$tmp/watch_replay.err"

# Item 12: a second server for pioneer (its only robot) refuses it and exits 1.
"$server_bin" --robot "pioneer=kinematic:$models/pioneer2dx_pantilt.urdf" --url "$url" --duration 20 \
  >"$tmp/second_server.log" 2>&1
status=$?
check "a server that serves no robot exits 1 ($status): $(tail -2 "$tmp/second_server.log")" test "$status" -eq 1
check "and names the server that serves it" grep -q "robot 'pioneer' is served by server" "$tmp/second_server.log"
check "its refusals on lines of their own, no escaped line break" sh -c "! grep -q 'x0a' '$tmp/second_server.log'"

# Item 4: the real server is gone; an impersonator with another key answers.
kill "$server_pid"; wait "$server_pid" 2>/dev/null; server_pid=""
serve mallory fake.log
rt send pioneer goto 1 0 0 >"$tmp/fake" 2>&1
status=$?
check "a server with another key is refused ($status): $(cat "$tmp/fake")" test "$status" -ne 0
check "the refusal names both keys" grep -q "pinned.*$(fp server)" "$tmp/fake"
check "... and the key offered" grep -q "this server's key: $(fp mallory)" "$tmp/fake"
check "the impersonator ran nothing" bash -c "! grep -q 'GOTO' '$tmp/fake.log'"
rt --server-key "$tmp/mallory.pub" query pioneer base_pose >"$tmp/explicit" 2>&1
check "--server-key overrides the pin: $(cat "$tmp/explicit")" grep -q SUCCESS "$tmp/explicit"

echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
