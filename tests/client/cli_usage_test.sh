#!/bin/sh
# The robotalk CLI's usage errors (exit 2) and help (exit 0); no network needed.
# usage: cli_usage_test.sh path/to/robotalk path/to/examples
set -u
cli=$1
examples=$2
fail=0
expect() {  # expect STATUS ARGS...
  want=$1; shift
  "$cli" "$@" >/dev/null 2>&1
  got=$?
  if [ "$got" != "$want" ]; then echo "FAIL: robotalk $* -> $got, want $want"; fail=1; fi
}
expect 0 --help
expect 0 send --help
expect 2
expect 2 fly pioneer
expect 2 send pioneer goto 1 2
expect 2 send pioneer jump
expect 2 send pioneer stop --at soon
expect 2 query pioneer everything
expect 2 describe
expect 2 --timeout -1 robots
expect 2 send pioneer --file /nonexistent/seq.txt
tmp=$(mktemp)
printf '0 stop\n1 goto 1\n' > "$tmp"
msg=$("$cli" send pioneer --file "$tmp" 2>&1)
[ $? = 2 ] || { echo "FAIL: bad sequence file status"; fail=1; }
case "$msg" in *"$tmp:2: GOTO takes 3 values"*) ;; *) echo "FAIL: message '$msg'"; fail=1 ;; esac
rm -f "$tmp"
# Unknown options are named as such, before or after the command.
expect_msg() {  # expect_msg STATUS TEXT ARGS...
  want=$1 text=$2; shift 2
  out=$("$cli" "$@" 2>&1); got=$?
  [ "$got" = "$want" ] || { echo "FAIL: robotalk $* -> $got, want $want"; fail=1; }
  case "$out" in *"$text"*) ;; *) echo "FAIL: robotalk $*: no \"$text\" in: $out"; fail=1 ;; esac
}
expect_msg 2 "unknown option '--bogus'" --bogus robots
expect_msg 2 "unknown option '--bogus'" send pioneer goto 1 0 0 --bogus
expect_msg 2 "unknown option '-x'" query pioneer base_pose -x
expect_msg 2 "--hold goes with setspeed" send pioneer goto 1 0 0 --hold
# Interpolation (issue 22): the flag's and the file's bad words are named with the accepted ones.
seq=$(mktemp)
printf 'interpolation cubic\n0 joint_setpoint pan 0.1 velocity 0.2\n' > "$seq"
expect_msg 2 "--interpolation: 'cubc' is not an interpolation (step, linear, cubic, quintic)" \
  send pioneer --file "$seq" --interpolation cubc
expect_msg 2 "interpolation cubic needs --mode delay or playback" send pioneer --file "$seq" --mode direct
expect_msg 2 "--mode, --delay, --paced and --interpolation go with --file" send pioneer goto 1 0 0 --interpolation cubic
expect_msg 2 "velocity and acceleration are a waypoint's" send pioneer joint_setpoint pan 0.1 velocity 0.2
printf 'interpolation smooth\n0 stop\n' > "$seq"
expect_msg 2 "$seq:1: interpolation: 'smooth' is not an interpolation (step, linear, cubic, quintic)" \
  send pioneer --file "$seq"
rm -f "$seq"
# Times out of range are usage errors naming the option (review 10: --timeout 1e12, --max-late 1e12 and
# --listen 1e12 ended with "FromSeconds: ... out of range" and status 1, naming no option; --listen -1
# listened "within -1 s"; --period, --at, --delay and a file's start time 1e12 failed only after connecting).
# memq:// keeps what is not refused off the network.
LCM_DEFAULT_URL=memq:// expect_msg 2 "--timeout" --timeout 1e12 robots
LCM_DEFAULT_URL=memq:// expect_msg 2 "--max-late" --max-late 1e12 robots
LCM_DEFAULT_URL=memq:// expect_msg 2 "--listen" robots --listen 1e12
LCM_DEFAULT_URL=memq:// expect_msg 2 "--listen" robots --listen -1
LCM_DEFAULT_URL=memq:// expect_msg 2 "--period" watch pioneer --period 1e12
LCM_DEFAULT_URL=memq:// expect_msg 2 "--duration" watch pioneer --duration 1e12
# A count is a whole number ('--count 2.5' was taken, read as "3 samples").
LCM_DEFAULT_URL=memq:// expect_msg 2 "--count: '2.5' is not a whole number" watch pioneer --count 2.5
LCM_DEFAULT_URL=memq:// expect_msg 2 "--count: '0' is not a whole number" watch pioneer --count 0
LCM_DEFAULT_URL=memq:// expect_msg 2 "--at" send pioneer stop --at 1e12
seq=$(mktemp)
printf '0 stop\n1e12 stop\n' > "$seq"
LCM_DEFAULT_URL=memq:// expect_msg 2 "$seq:2: start time" send pioneer --file "$seq"
printf '0 stop\n' > "$seq"
LCM_DEFAULT_URL=memq:// expect_msg 2 "--delay" send pioneer --file "$seq" --delay 1e12
rm -f "$seq"
expect_msg 0 "robotalk " --version
"$cli" --version | grep -Eq '^robotalk [0-9]+\.[0-9]+\.[0-9]+$' || { echo "FAIL: --version format"; fail=1; }
[ $fail = 0 ] && echo "cli usage: all passed"
exit $fail
