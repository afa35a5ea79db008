#!/usr/bin/env bash
# Installs the build into a temporary prefix and compiles every header the
# install put under include/ on its own, in a fresh translation unit against
# the installed package (tests/package/headers): a header that includes one
# the install left out, or that needs an include it does not make, fails.
# The list of headers is the install's own manifest (its "Installing:" lines).
#   installed_headers_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1 source=$2
. "$(dirname "$0")/../lib.sh"  # $tmp, check
cmake --install "$build" --prefix "$tmp/prefix" >"$tmp/install.log"
# (It names folders too: only files are headers.)
sed -n 's/^-- \(Installing\|Up-to-date\): //p' "$tmp/install.log" | grep "^$tmp/prefix/include/" | sort |
  while read -r f; do [ ! -f "$f" ] || echo "$f"; done >"$tmp/headers"
check "the install puts headers under include/" test -s "$tmp/headers"
check "no header straight into include/" sh -c "! grep -q '^$tmp/prefix/include/[^/]*$' '$tmp/headers'"
cmake -S "$source/tests/package/headers" -B "$tmp/headers_build" -DCMAKE_PREFIX_PATH="$tmp/prefix" \
  -DROBOTALK_HEADER_LIST="$tmp/headers" >"$tmp/configure.log" 2>&1 || { cat "$tmp/configure.log"; exit 1; }
# Every translation unit at once, on every core (one make, not one per header:
# each call of its own paid make's start-up and the cores stood idle); a
# header whose object is missing afterwards (a failure, or the ones make left
# when it stopped) is built again on its own: its verdict and its log.
cmake --build "$tmp/headers_build" -j"$(nproc)" >"$tmp/build_all.log" 2>&1 || true
n=0
while read -r header; do
  name=${header#"$tmp/prefix/include/"}
  if compgen -G "$tmp/headers_build/CMakeFiles/hdr_$n.dir/hdr_$n.*.o" >/dev/null ||
    cmake --build "$tmp/headers_build" --target "hdr_$n" >"$tmp/build_$n.log" 2>&1; then
    pass=$((pass + 1))
  else
    echo "FAIL: $name does not compile on its own"; failures=$((failures + 1))
    grep -m 5 "error" "$tmp/build_$n.log" || true
  fi
  n=$((n + 1))
done <"$tmp/headers"
echo "$n headers; $pass checks passed, $failures failed"
[ "$failures" -eq 0 ]
