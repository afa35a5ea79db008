#!/usr/bin/env bash
# Texts from the wire on the CLI's stderr (review 13): a server's (in open
# mode anyone's) text inside an error the CLI prints (a hello's refusal here;
# a CONFIG's error, a refused panic's reason alike) is written on one line,
# its control characters as \xNN, as PrintReply writes a reply's message:
# no forged line, no terminal escape.
#   cli_hostile_texts_test.sh CLI FORGE
set -u
cli=$1 forge=$2
url="udpm://239.255.76.67:7613?ttl=0"
. "$(dirname "$0")/../lib.sh"  # $tmp, check

text=$'no\nrobotalk: a forged line\x1b]0;owned\x07\xc2\x9b2J'
"$forge" "$url" refuse-hellos fake 10 "$text" &
pids+=($!)
sleep 0.5
for cmd in describe panic; do
  "$cli" --url "$url" --timeout 3 $cmd fake >"$tmp/out" 2>"$tmp/err"
  status=$?
  shown=$(cat -v "$tmp/err")
  check "$cmd: exit 1 (was $status)" [ "$status" = 1 ]
  check "$cmd: the refusal is said: $shown" grep -q "refused this client's hello: no" "$tmp/err"
  check "$cmd: on one line: $shown" [ "$(wc -l <"$tmp/err")" = 1 ]
  check "$cmd: no ESC, BEL or C1 CSI reaches the terminal: $shown" \
    bash -c "! LC_ALL=C grep -q \$'\x1b\|\x07\|\xc2\x9b' '$tmp/err'"
  check "$cmd: written escaped: $shown" grep -qF 'no\x0arobotalk: a forged line\x1b]0;owned\x07\xc2\x9b2J' "$tmp/err"
done
echo "cli_hostile_texts: $pass passed, $failures failed"
[ "$failures" = 0 ]
