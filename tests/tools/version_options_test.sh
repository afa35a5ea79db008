#!/bin/sh
# Every tool binary answers --version with "NAME X.Y.Z" (the CMake project
# version) and names an unknown option as such (exit 2). No network.
# usage: version_options_test.sh VERSION BINARY...
set -u
version=$1; shift
fail=0
for bin in "$@"; do
  name=$(basename "$bin")
  out=$("$bin" --version 2>&1); got=$?
  [ "$got" = 0 ] && [ "$out" = "$name $version" ] || { echo "FAIL: $name --version -> $got: '$out'"; fail=1; }
  out=$("$bin" --bogus x 2>&1); got=$?
  [ "$got" = 2 ] || { echo "FAIL: $name --bogus -> $got, want 2"; fail=1; }
  case "$out" in *"unknown option '--bogus'"*) ;; *) echo "FAIL: $name --bogus says: $out"; fail=1 ;; esac
done
[ $fail = 0 ] && echo "version and options: all passed"
exit $fail
