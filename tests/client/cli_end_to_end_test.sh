#!/usr/bin/env bash
# The robotalk CLI end to end over UDP multicast against a real robotalk-server
# (kinematic Pioneer): robots, describe, query, send (now, --at, a sequence
# file), panic and reset, an unknown robot. Runs inside a private network
# namespace (CTest wraps it with netns_run.sh).
#   cli_end_to_end_test.sh SERVER CLI MODELS_DIR
set -u
server_bin=$1 cli=$2 models=$3
url="udpm://239.255.76.67:7671?ttl=0"
. "$(dirname "$0")/../lib.sh"  # $tmp, $server_pid, check
start_pioneer "$tmp/server.log" --url "$url" --duration 60

cli_says() {  # cli_says STATUS PATTERN ARGS...: robotalk ARGS exits STATUS and prints PATTERN
  local want=$1 pattern=$2 out got
  shift 2
  out=$("$cli" --url "$url" --timeout 2 "$@" 2>&1); got=$?
  [ "$got" = "$want" ] || { echo "robotalk $* -> $got, want $want: $out"; return 1; }
  case "$out" in *"$pattern"*) ;; *) echo "robotalk $*: no '$pattern' in: $out"; return 1 ;; esac
}
check "robots lists pioneer" cli_says 0 "pioneer" robots --listen 1.2
check "describe names the tilt joint" cli_says 0 "tilt" describe pioneer
check "describe --json" cli_says 0 '"name"' describe pioneer --json
check "query joint_state" cli_says 0 "SUCCESS" query pioneer joint_state
check "send goto" cli_says 0 "SUCCESS" send pioneer goto 0.3 0 0
check "send stop --at" cli_says 0 "SUCCESS" send pioneer stop --at 0.3
printf '# test\n0 setspeed 0.1 0\n0.2 joint_setpoint pan 0.3\n0.4 stop\n' >"$tmp/seq.txt"
n=$("$cli" --url "$url" send pioneer --file "$tmp/seq.txt" | grep -c SUCCESS)
check "a sequence file prints one SUCCESS per frame (got $n)" test "$n" = 3
check "panic is taken" cli_says 0 "panic taken by pioneer" panic pioneer
check "a command in panic answers PANIC and exits 1" cli_says 1 "PANIC" send pioneer joint_setpoint pan 0.1
check "reset lifts the panic" cli_says 0 "SUCCESS" reset pioneer
check "a command after reset succeeds" cli_says 0 "SUCCESS" send pioneer joint_setpoint pan 0.1
check "an unknown robot names the robots heard" \
  cli_says 1 "no robot 'nobody' on this network (heard: pioneer)" query nobody joint_state
echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
