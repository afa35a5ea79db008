#!/usr/bin/env bash
# gaps13 (safety.md's Known gaps): LCM writes why it cannot start (a bad
# --url) to stderr itself, with fprintf, bypassing the process's writer of
# stderr (LogWriter::Stderr()). With a stderr that takes nothing (a full pipe
# nobody reads) robotalk-server and robotalk-web waited in that write for
# ever. Now, when stderr cannot take a line as LCM starts, descriptor 2 is a
# pipe of the transport's own meanwhile: LCM's text becomes part of the
# error ("LCM says: ..."), written through the writer that waits 0.2 s at
# most, and the program ends with its status. A stderr that takes lines is
# left alone (final13: the dup2 is the whole process's; other threads' lines
# were taken for LCM's): LCM writes its own line, the error follows.
# Usage: lcm_stderr_test.sh ROBOTALK_SERVER ROBOTALK_WEB MODELS_DIR WWW_DIR
set -u
server=$1
web=$2
models=$3
www=$4
tmp=$(mktemp -d)
pids=()
trap 'for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null; done; rm -rf "$tmp"' EXIT
fail=0
check() {
  local what=$1
  shift
  if "$@"; then echo "ok: $what"; else echo "FAIL: $what"; fail=1; fi
}
mkdir -p "$tmp/node_modules/three" "$tmp/node_modules/urdf-loader"
run_server() { "$server" --url 'bogus://x' --robot "pioneer=kinematic:$models/pioneer2dx_pantilt.urdf"; }
run_web() { "$web" --port 0 --lcm-url 'bogus://x' --www "$www" --node-modules "$tmp/node_modules"; }

for prog in server web; do
  # A stderr that takes lines: LCM's own line, then the program's error.
  "run_$prog" >/dev/null 2>"$tmp/$prog.err"
  status=$?
  check "robotalk-$prog with a bad --url exits 1 (status $status)" test "$status" -eq 1
  check "LCM's reason is written ($(tr '\n' '|' <"$tmp/$prog.err"))" \
    grep -q 'Error: LCM provider "bogus" not found' "$tmp/$prog.err"
  check "then the error naming the URL" grep -q "LCM could not start on 'bogus://x'" "$tmp/$prog.err"

  # A stderr that takes nothing: a full pipe whose reader reads nothing.
  mkfifo "$tmp/full_$prog"
  sleep 1000 <"$tmp/full_$prog" &
  pids+=($!)
  exec 5>"$tmp/full_$prog"
  head -c 65536 /dev/zero >&5  # the pipe's capacity: full
  "run_$prog" >/dev/null 2>&5 &
  pid=$!
  pids+=("$pid")
  exec 5>&-
  ended=0
  for _ in $(seq 50); do
    if ! kill -0 "$pid" 2>/dev/null; then ended=1; break; fi
    sleep 0.1
  done
  check "robotalk-$prog with a bad --url and a stderr that takes nothing ends within 5 s" test "$ended" -eq 1
  if [ "$ended" -eq 1 ]; then
    wait "$pid"
    status=$?
    check "with status 1 (status $status)" test "$status" -eq 1
  fi
done
exit $fail
