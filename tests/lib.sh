# Shared by the shell tests (source it: . "$(dirname "$0")/../lib.sh"):
#   $tmp          a temporary folder, removed at exit
#   $server_pid   set it to a server's pid: it is stopped at exit
#   $client_pid   set it to a client's pid: it is stopped at exit (resumed first if stopped)
#   pids+=($!)    any other background process: killed at exit
#   check NAME COMMAND...   runs COMMAND; counts a pass, or prints "FAIL: NAME"
#   $pass, $failures        the counts
#   value_of FILE KEY       the value of the first "KEY=value" line of FILE
#   wait_for FILE PATTERN [TRIES [PAUSE]]  until grep finds PATTERN in FILE (a log
#                           line such as "serving robot"): TRIES looks (50), PAUSE s
#                           apart (0.1); status 1 if it never did
#   start_pioneer LOG [ARGS...]  "$server_bin" serving the kinematic Pioneer of
#                           "$models" with ARGS, stderr to LOG, in $server_pid;
#                           returns once it serves (wait_for's status)
#   ends_within WHAT STATUS PID  PID (a child of this shell) ends within 5 s
#                           (else killed) with exit status STATUS: two checks
#   ROBOTALK_KNOWN_SERVERS  keyed clients pin server keys in $tmp, not in ~/.robotalk
#   deadline SECONDS [FROM]  the clock (date +%s%N) SECONDS after FROM (a deadline or
#                           a `date +%s%N`; now by default)
#   poll_until DEADLINE COMMAND...  runs COMMAND every 0.1 s until it succeeds
#                           (status 0) or once more at or after DEADLINE (status 1):
#                           a `sleep N; check ... COMMAND` that ends when COMMAND holds
tmp=$(mktemp -d)
export ROBOTALK_KNOWN_SERVERS="$tmp/known_servers"
server_pid="" client_pid=""
pids=()
cleanup() {
  local p
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done
  [ -n "$client_pid" ] && kill -CONT "$client_pid" 2>/dev/null && kill "$client_pid" 2>/dev/null
  [ -n "$server_pid" ] && kill "$server_pid" 2>/dev/null && wait "$server_pid" 2>/dev/null
  for p in "${pids[@]}"; do wait "$p" 2>/dev/null; done
  rm -rf "$tmp"
}
trap cleanup EXIT
pass=0 failures=0
check() {  # check NAME COMMAND...
  local name=$1; shift
  if "$@"; then pass=$((pass + 1)); else echo "FAIL: $name"; failures=$((failures + 1)); fi
}
value_of() { sed -n "s/^$2=//p" "$1" | head -1; }
wait_for() {  # wait_for FILE PATTERN [TRIES [PAUSE]]
  local _
  for _ in $(seq "${3:-50}"); do grep -q "$2" "$1" 2>/dev/null && return 0; sleep "${4:-0.1}"; done
  return 1
}
deadline() {  # deadline SECONDS [FROM]
  echo $((${2:-$(date +%s%N)} + $(awk -v s="$1" 'BEGIN { printf "%d", s * 1e9 }')))
}
poll_until() {  # poll_until DEADLINE COMMAND...
  local end=$1
  shift
  until "$@"; do
    [ "$(date +%s%N)" -lt "$end" ] || return 1
    sleep 0.1
  done
}
start_pioneer() {  # start_pioneer LOG [ARGS...]
  local log=$1
  shift
  "$server_bin" --robot "pioneer=kinematic:$models/pioneer2dx_pantilt.urdf" "$@" 2>"$log" &
  server_pid=$!
  wait_for "$log" "serving robot"
}
# signal_server SIGNAL: sends SIGNAL to $server_pid and waits 10 s at most for
# it to end (then kill -9); sets $server_status (its exit status) and
# $server_ended (1 when it ended by itself) and clears $server_pid.
signal_server() {
  kill -s "$1" "$server_pid" 2>/dev/null
  server_ended=0
  for _ in $(seq 100); do
    kill -0 "$server_pid" 2>/dev/null || { server_ended=1; break; }
    sleep 0.1
  done
  [ "$server_ended" = 1 ] || kill -9 "$server_pid" 2>/dev/null
  wait "$server_pid"
  server_status=$?
  server_pid=""
}
# last_motion WATCH_JSON: "v w moving" of the last STATE sample in a `watch
# --json` output ("none none none" when there is none).
last_motion() {
  python3 -c 'import json, sys
lines = [l for l in open(sys.argv[1]) if l.startswith("{")]
s = json.loads(lines[-1]) if lines else {"base": [0, 0, 0, "none", "none"], "moving": "none"}
print(s["base"][3], s["base"][4], str(s["moving"]).lower())' "$1"
}
# fails_whatever_stderr STATUS PATTERN WHAT CMD...: CMD, which cannot start,
# ends with STATUS within 5 s when its stdout and stderr are $tmp/full (a
# pipe that takes nothing), and with a stderr that takes everything it ends
# with STATUS saying PATTERN (grep).
fails_whatever_stderr() {
  local status=$1 pattern=$2 what=$3 rc
  shift 3
  "$@" >"$tmp/full" 2>"$tmp/full" &
  ends_within "full stderr, $what" "$status" $!
  "$@" >/dev/null 2>"$tmp/err.log"
  rc=$?
  check "$what: exit status $status (status $rc) and says why: $(head -c 300 "$tmp/err.log")" \
    sh -c 'test "$1" -eq "$2" && grep -q -- "$3" "$4"' _ "$rc" "$status" "$pattern" "$tmp/err.log"
}
ends_within() {  # ends_within WHAT STATUS PID
  local rc
  for _ in $(seq 50); do kill -0 "$3" 2>/dev/null || break; sleep 0.1; done
  if kill -0 "$3" 2>/dev/null; then
    check "$1: ends within 5 s" false
    kill -9 "$3" 2>/dev/null
  fi
  wait "$3"
  rc=$?
  check "$1: exit status $2 (status $rc)" test "$rc" -eq "$2"
}
