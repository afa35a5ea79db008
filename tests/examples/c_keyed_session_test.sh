#!/usr/bin/env bash
# The C example in keyed mode against a keyed robotalk-server: with a listed
# key it runs its whole session (hello signed, packages sealed, replies and
# CONFIG verified), with or without the server key given; an unlisted key is
# refused, a wrong server key ignores the real server's answers and says whose
# they were, no key is told to give one; none of those opens a session. Run
# inside a private network namespace (CTest: scripts/netns_run.sh).
#   c_keyed_session_test.sh SERVER KEYGEN MODELS_DIR PORT C_EXAMPLE
set -u
server_bin=$1 keygen=$2 models=$3 port=$4 example=$5
url="udpm://239.255.76.67:$port?ttl=0"
. "$(dirname "$0")/../lib.sh"  # $tmp, $server_pid, check
. "$(dirname "$0")/keyed_server.sh"  # start_keyed_server
start_keyed_server "$server_bin" "$keygen" "$models" "$url" 90 mallory
run() {  # run NAME ARGS...: the example's exit status in $tmp/NAME.status
  local name=$1
  shift
  timeout 60 "$@" --url "$url" --robot pioneer >"$tmp/$name.out" 2>"$tmp/$name.err"
  echo $? >"$tmp/$name.status"
}
# The three refused ones open no session (the impostor waits out its 5 s hello
# timeout): they run meanwhile, in the background; each is waited for before
# its checks.
declare -A job=()
run unlisted env -u ROBOTALK_KEY "$example" --key "$tmp/mallory" &
job[unlisted]=$!
run impostor env -u ROBOTALK_KEY "$example" --key "$tmp/alice" --server-key "$tmp/mallory.pub" &
job[impostor]=$!
run nokey env -u ROBOTALK_KEY "$example" &
job[nokey]=$!
pids+=("${job[@]}")

run pinned env -u ROBOTALK_KEY "$example" --key "$tmp/alice" --server-key "$tmp/server.pub"
check "with a listed key and the server's key it exits 0" grep -qx 0 "$tmp/pinned.status"
check "it connected keyed" grep -q "^connected: robot=pioneer .* keyed$" "$tmp/pinned.out"
check "its GOTO succeeded" grep -q "GOTO 0.5 0 0: SUCCESS" "$tmp/pinned.out"
check "its sequence ran (4 set-points, SUCCESS)" test "$(grep -c "sequence +.*SUCCESS" "$tmp/pinned.out")" -eq 4
check "the CONFIG it verified is the robot's" grep -q "^config: robot=pioneer links=7 joints=6" "$tmp/pinned.out"
x=$(grep -o -m1 "^pose: x=[-0-9.]*" "$tmp/pinned.out" | cut -d= -f2)
check "the robot reached the GOTO goal (x = ${x:-?})" awk -v x="$x" 'BEGIN { exit !(x != "" && x >= 0.48 && x <= 0.52) }'


run tofu env ROBOTALK_KEY="$tmp/alice" "$example"
check "ROBOTALK_KEY, no server key (the first answer's trusted): exits 0" grep -qx 0 "$tmp/tofu.status"
check "... and says done" grep -q "^done$" "$tmp/tofu.out"
fingerprint=$("$keygen" --fingerprint "$tmp/server.pub" | grep -o 'rt:[0-9a-f:]*' | head -1)
check "... naming the server key it trusted ($fingerprint)" \
  grep -q "trusting server key $fingerprint (not pinned" "$tmp/tofu.err"

wait "${job[unlisted]}"
check "an unlisted key exits 1" grep -qx 1 "$tmp/unlisted.status"
check "... saying the hello was refused for its key" \
  grep -q "error: hello refused by 'pioneer': .*key not in the access list" "$tmp/unlisted.err"

wait "${job[impostor]}"
check "another server key: exits 1" grep -qx 1 "$tmp/impostor.status"
check "... naming the key that answered and the one expected" \
  grep -q "error: no answer to hello from 'pioneer' .*answer signed by $fingerprint, expected server key rt:" \
  "$tmp/impostor.err"

wait "${job[nokey]}"
check "no key: exits 1" grep -qx 1 "$tmp/nokey.status"
check "... saying the server requires keys and how to give one" \
  grep -q "requires keys (keyed mode, docs/security.md); give this client one (--key FILE or ROBOTALK_KEY)" \
  "$tmp/nokey.err"
for n in pinned tofu unlisted impostor nokey; do
  [ "$failures" -eq 0 ] || { echo "--- $n (exit $(cat "$tmp/$n.status"))"; cat "$tmp/$n.out" "$tmp/$n.err"; }
done
[ "$failures" -eq 0 ] || { echo "--- server log"; cat "$tmp/server.log"; }
echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
