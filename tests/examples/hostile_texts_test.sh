#!/usr/bin/env bash
# review14: a client example writes texts from the wire into its error line
# (anyone's in open mode): the robot names forged ANNOUNCEs carry ("no robot
# 'pioneer' announced ... (heard: NAMES)"), as its hello's refusal and a
# CONFIG answer. None may reach the terminal with a control character: no
# ESC, BEL, CR, C1 CSI, and no line break that forges a second "error:" line
# (a forged hello refusal is not tested here: these clients wait for an
# ANNOUNCE, and forge_broadcast's refusal did not reach them in this setup).
# Run inside a private network namespace.
#   hostile_texts_test.sh FORGE PORT CLIENT_COMMAND...
set -u
forge=$1 port=$2
shift 2
url="udpm://239.255.76.67:$port?ttl=0"
. "$(dirname "$0")/../lib.sh"  # $tmp, pids, check
clean() {  # clean WHAT FILE: FILE has no control character but line breaks, and no forged line
  check "$1: no control character in: $(head -c 400 "$2" | od -c | head -8)" \
    sh -c '! LC_ALL=C grep -q "$(printf "[\001-\011\013-\037\177]")" "$1" && ! LC_ALL=C grep -q "$(printf "\302[\200-\237]")" "$1"' _ "$2"
  check "$1: no forged line" sh -c '! grep -q "^ *error: forged" "$1"' _ "$2"
}
# Only a forged name announced, the robot never: the names heard.
"$forge" "$url" announce "$(printf 'x\033[2J\a\r\302\233\n  error: forged')" 600 &
pids+=($!)
sleep 0.3
timeout 30 "$@" --url "$url" --robot pioneer >"$tmp/out2" 2>"$tmp/err2"
status=$?
check "no robot: exit 1 (got $status)" test "$status" -eq 1
check "it says the robot was not announced: $(head -c 300 "$tmp/err2")" grep -q "announced" "$tmp/err2"
clean "the names heard" "$tmp/err2"
[ "$failures" -eq 0 ] || cat -v "$tmp/err2" >&2
echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
