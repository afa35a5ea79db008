#!/usr/bin/env bash
# The soak's checker (scripts/soak.sh --check-only) on made-up runs: a command
# the driver refused ("refused" audit line, answered BUSY) is counted as
# refused, never as run, so a late SETSPEED answered BUSY after a newer one is
# not "out of order" (issue 19 item 9); the same order with the late one run
# is; a refused command answered SUCCESS is a mismatch.
#   soak_check_test.sh SOAK_SCRIPT
set -u
soak=$1
. "$(dirname "$0")/../lib.sh"  # $tmp, check

# make_run DIR LINE_OF_COMMAND_4 ANSWER_OF_4: client a1 sent SETSPEED 4
# (start 1 s) and 5 (start 2 s); 5 ran first, then 4 reached the driver.
make_run() {
  mkdir -p "$1"
  : >"$1/killed"
  printf 'a2b received=1 lost=0 duplicated=0 reordered=0\nb2a received=1 lost=0 duplicated=0 reordered=0\n' >"$1/relay.out"
  {
    echo "robotalk-server: robot 'pioneer': executed client 00000000000000a1 command 5 SETSPEED -> SUCCESS"
    echo "robotalk-server: robot 'pioneer': $2"
  } >"$1/server1.log"
  cat >"$1/client1.jsonl" <<EOF
{"ev":"hello","client":"00000000000000a1","mode":"delay","seed":1}
{"ev":"sent","id":4,"type":"SETSPEED","target":"","start_us":1000000}
{"ev":"sent","id":5,"type":"SETSPEED","target":"","start_us":2000000}
{"ev":"final","id":5,"outcome":"SUCCESS","msg":"","late_us":0}
{"ev":"final","id":4,"outcome":"$3","msg":"SETSPEED: GOTO in progress","late_us":1500000}
EOF
}

# scenario NAME AUDIT_LINE_OF_4 ANSWER_OF_4 EXIT_STATUS WHAT [PATTERN...]: the
# checker's exit status, then each PATTERN found in its report.
scenario() {
  local name=$1 line=$2 answer=$3 rc=$4 what=$5 p; shift 5
  make_run "$tmp/$name" "$line" "$answer"
  "$soak" --check-only "$tmp/$name" >"$tmp/$name.out" 2>&1
  check "$what (exit $rc)" test $? -eq "$rc"
  for p in "$@"; do check "$what: '$p'" grep -q "$p" "$tmp/$name.out"; done
}

scenario refused "refused client 00000000000000a1 command 4 SETSPEED -> BUSY (SETSPEED: GOTO in progress (command 3))" \
  BUSY 0 "a late SETSPEED refused with BUSY passes" \
  "BUSY (refused by the driver) *1" "^out of order *0" "^executed *1 "
scenario ran "executed client 00000000000000a1 command 4 SETSPEED -> SUCCESS" SUCCESS 1 \
  "a late SETSPEED that ran after a newer one fails" "^out of order *1"
# What the server printed before issue 19: a refusal logged as executed.
scenario old "executed client 00000000000000a1 command 4 SETSPEED -> BUSY" BUSY 1 \
  "a refusal logged as executed fails" "AUDIT: client 00000000000000a1 command 4 is logged as executed with BUSY"
scenario mismatch "refused client 00000000000000a1 command 4 SETSPEED -> BUSY (GOTO in progress)" SUCCESS 1 \
  "a refused command answered SUCCESS fails" "ANSWER MISMATCH"
# Command 5 ran; a second audit line for it (refused) means it reached the driver twice.
scenario twice "refused client 00000000000000a1 command 5 SETSPEED -> BUSY (again)" BUSY 1 \
  "a command that reached the driver twice fails" "^executed twice *1"

echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
