#!/usr/bin/env bash
# robotalk-web's command line: --help, --version, errors named, exit codes.
set -u
web=$1
fail=0
expect() {  # expect WHAT STATUS PATTERN -- ARGS...
  local what=$1 status=$2 pattern=$3; shift 4
  out=$("$web" "$@" 2>&1); rc=$?
  if [ "$rc" -ne "$status" ] || ! grep -q -- "$pattern" <<<"$out"; then
    echo "FAIL: $what: exit $rc, output: $out"; fail=1
  else
    echo "ok   $what"
  fi
}
expect "--help prints the usage" 0 "usage: robotalk-web" -- --help
expect "--help says it binds to loopback by default" 0 "default 127.0.0.1" -- --help
expect "--version prints the version" 0 "^robotalk-web [0-9]" -- --version
expect "an unknown option is named" 2 "unknown option '--colour'" -- --colour
expect "a bad port is named" 2 "--port: 'x' is not a whole number in \[0, 65535\]" -- --port x
expect "a missing URDF file is named" 2 "--urdf arm=/nonexistent.urdf: no such file" -- --urdf arm=/nonexistent.urdf
expect "--help offers --package-path and ROS_PACKAGE_PATH" 0 "package-path DIRS.*" -- --help
expect "an empty --package-path is named" 2 "--package-path: ':' names no folder" -- --package-path :
expect "--help offers keyed mode's --key and --server-key" 0 "server-key FILE" -- --help
expect "a missing --server-key file is named" 1 "public key file /nonexistent.pub: cannot open" -- --port 0 --server-key /nonexistent.pub
expect "missing npm modules say how to install them" 1 "run scripts/setup.sh" -- --node-modules /nonexistent
exit $fail
