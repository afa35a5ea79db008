#!/bin/sh
# The robotalk CLI end to end over UDP multicast against robotalk_fake_server,
# inside a private network namespace (DESIGN.md §4).
# usage: cli_fake_server_test.sh robotalk robotalk_fake_server models_dir
set -u
cli=$1; server=$2; models=$3
if ! unshare -n true 2>/dev/null; then echo "SKIP: unshare -n not permitted"; exit 77; fi
exec unshare -n sh -s "$cli" "$server" "$models" <<'INNER'
set -u
cli=$1; server=$2; models=$3
ip link set lo up && ip route add 224.0.0.0/4 dev lo || exit 1
url='udpm://239.255.76.67:7671?ttl=0'
"$server" "$url" "$models/pioneer2dx_pantilt.urdf" 20 &
spid=$!
fail=0
check() {  # check STATUS PATTERN ARGS...
  want=$1; pattern=$2; shift 2
  out=$("$cli" --url "$url" --timeout 2 "$@" 2>&1); got=$?
  if [ "$got" != "$want" ]; then echo "FAIL: robotalk $* -> $got, want $want: $out"; fail=1; return; fi
  case "$out" in *$pattern*) ;; *) echo "FAIL: robotalk $*: no '$pattern' in: $out"; fail=1 ;; esac
}
check 0 "pioneer" robots --listen 0.6
check 0 "tilt" describe pioneer
check 0 '"name"' describe pioneer --json
check 0 "SUCCESS" query pioneer joint_state
check 0 'SUCCESS "cmd' send pioneer goto 1 0 0
check 0 "SUCCESS" send pioneer stop --at 0.3
seq=$(mktemp)
printf '# test\n0 setspeed 0.1 0\n0.2 joint_setpoint pan 0.3\n0.4 stop\n' > "$seq"
check 0 "SUCCESS" send pioneer --file "$seq"
n=$("$cli" --url "$url" send pioneer --file "$seq" | grep -c SUCCESS)
[ "$n" = 3 ] || { echo "FAIL: sequence printed $n replies"; fail=1; }
rm -f "$seq"
check 0 "acknowledged" panic pioneer
check 1 "PANIC" send pioneer goto 1 0 0
check 0 "SUCCESS" reset pioneer
check 0 "SUCCESS" send pioneer goto 1 0 0
check 1 "no robot 'nobody' on this network (heard: pioneer)" --timeout 0.5 query nobody joint_state
kill $spid 2>/dev/null; wait $spid 2>/dev/null
[ $fail = 0 ] && echo "cli end to end: all passed"
exit $fail
INNER
