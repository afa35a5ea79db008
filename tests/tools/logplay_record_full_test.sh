#!/usr/bin/env bash
# A recording that cannot be written is never reported as written: with the
# disk full (/dev/full: every write fails with ENOSPC) `robotalk-logplay
# record` exits 1 naming the file and the error, and never says it wrote
# events (before: "wrote 4 events" and exit 0, the stdio buffer's flushes
# failing unchecked, nothing on disk). A server's ANNOUNCEs (1 Hz) are the
# events. Runs inside a private network namespace (CTest wraps it with
# netns_run.sh).
#   logplay_record_full_test.sh SERVER LOGPLAY MODELS_DIR
set -u
server_bin=$1 logplay=$2 models=$3
url="udpm://239.255.76.67:7834?ttl=0"
. "$(dirname "$0")/../lib.sh"

start_pioneer "$tmp/server.log" --url "$url" --duration 60

"$logplay" record -o /dev/full --lcm-url "$url" --duration 2.5 2>"$tmp/record.log"
status=$?
check "record to a full disk exits 1 (status $status): $(tr '\n' '|' <"$tmp/record.log")" test "$status" -eq 1
check "it names the file and the error" grep -q "writing '/dev/full' failed.*No space left on device" "$tmp/record.log"
check "it never says it wrote the events" sh -c "! grep -q 'wrote [1-9]' '$tmp/record.log'"

echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
