#!/usr/bin/env bash
# Every installed program answers --version and --help on its own (issue 21):
# installs the build into a temporary prefix and runs both on every file of
# its bin/ (so a program added later is covered without touching this test):
#   --version  exit 0, stdout exactly "NAME VERSION", nothing on stderr
#   --help     exit 0, stdout starting with a line "usage: NAME ...", then more
#              (the options), nothing on stderr
# No network: --help and --version must answer before anything is opened.
#   installed_help_version_test.sh BUILD_DIR VERSION
set -u
build=$1 version=$2
. "$(dirname "$0")/../lib.sh"  # $tmp, check
cmake --install "$build" --prefix "$tmp/prefix" >"$tmp/install.log" 2>&1 || { cat "$tmp/install.log"; exit 1; }
count=0
for bin in "$tmp/prefix/bin"/*; do
  name=$(basename "$bin")
  count=$((count + 1))
  out=$(timeout 20 "$bin" --version 2>"$tmp/err") status=$?
  check "$name --version exits 0 (got $status)" test "$status" -eq 0
  check "$name --version prints '$name $version' (got '$out')" test "$out" = "$name $version"
  check "$name --version writes nothing on stderr ($(head -c 200 "$tmp/err"))" test ! -s "$tmp/err"
  timeout 20 "$bin" --help >"$tmp/help" 2>"$tmp/err"
  status=$?
  check "$name --help exits 0 (got $status)" test "$status" -eq 0
  check "$name --help starts with its own usage line (got '$(head -1 "$tmp/help")')" \
    grep -q "^usage: $name\( \|$\)" <(head -1 "$tmp/help")
  check "$name --help says more than the usage line" test "$(wc -l <"$tmp/help")" -ge 2
  check "$name --help writes nothing on stderr ($(head -c 200 "$tmp/err"))" test ! -s "$tmp/err"
done
check "the installation has programs ($count)" test "$count" -ge 5
echo "$count programs; $pass passed, $failures failed"
[ "$failures" -eq 0 ]
