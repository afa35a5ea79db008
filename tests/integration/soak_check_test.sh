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

make_run "$tmp/refused" "refused client 00000000000000a1 command 4 SETSPEED -> BUSY (SETSPEED: GOTO in progress (command 3))" BUSY
"$soak" --check-only "$tmp/refused" >"$tmp/refused.out" 2>&1
check "a late SETSPEED refused with BUSY passes" test $? -eq 0
check "it is refused, not run" grep -q "BUSY (refused by the driver) *1" "$tmp/refused.out"
check "nothing out of order" grep -q "^out of order *0" "$tmp/refused.out"
check "one executed" grep -q "^executed *1 " "$tmp/refused.out"

make_run "$tmp/ran" "executed client 00000000000000a1 command 4 SETSPEED -> SUCCESS" SUCCESS
"$soak" --check-only "$tmp/ran" >"$tmp/ran.out" 2>&1
check "a late SETSPEED that ran after a newer one fails" test $? -eq 1
check "it is out of order" grep -q "^out of order *1" "$tmp/ran.out"

# What the server printed before issue 19: a refusal logged as executed.
make_run "$tmp/old" "executed client 00000000000000a1 command 4 SETSPEED -> BUSY" BUSY
"$soak" --check-only "$tmp/old" >"$tmp/old.out" 2>&1
check "a refusal logged as executed fails" test $? -eq 1
check "and is named" grep -q "AUDIT: client 00000000000000a1 command 4 is logged as executed with BUSY" "$tmp/old.out"

make_run "$tmp/mismatch" "refused client 00000000000000a1 command 4 SETSPEED -> BUSY (GOTO in progress)" SUCCESS
"$soak" --check-only "$tmp/mismatch" >"$tmp/mismatch.out" 2>&1
check "a refused command answered SUCCESS fails" test $? -eq 1
check "as a mismatch" grep -q "ANSWER MISMATCH" "$tmp/mismatch.out"

make_run "$tmp/twice" "refused client 00000000000000a1 command 5 SETSPEED -> BUSY (again)" BUSY
"$soak" --check-only "$tmp/twice" >"$tmp/twice.out" 2>&1
check "a command that reached the driver twice fails" test $? -eq 1
check "as executed twice" grep -q "^executed twice *1" "$tmp/twice.out"

echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
