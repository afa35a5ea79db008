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
[ $fail = 0 ] && echo "cli usage: all passed"
exit $fail
