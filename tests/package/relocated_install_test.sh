#!/usr/bin/env bash
# An installation works wherever it is moved (issue 21): installs the build
# into a temporary prefix, MOVES the whole tree elsewhere, and then, from the
# moved tree only:
#   - nothing in it names the prefix it was installed to;
#   - robotalk-spy answers --version and puts the moved types jar on lcm-spy's
#     class path (a stand-in JAVA prints the command line);
#   - robotalk-web serves its installed page and npm modules (curl on loopback);
#   - robotalk-describe reads the installed Pioneer model;
#   - find_package(robotalk) against the moved prefix names its files, and the
#     C, Java and Lua client examples built against it run against the moved
#     robotalk-server (tests/examples/client_example_test.sh).
# Runs inside a private network namespace (CTest wraps it with netns_run.sh).
#   relocated_install_test.sh BUILD_DIR SOURCE_DIR VERSION
set -u
build=$1 source=$2 version=$3
. "$(dirname "$0")/../lib.sh"  # $tmp, pids, check
url="udpm://239.255.76.67:7771?ttl=0"
first=$tmp/installed
prefix=$tmp/moved/elsewhere
cmake --install "$build" --prefix "$first" >"$tmp/install.log" 2>&1 || { cat "$tmp/install.log"; exit 1; }
mkdir -p "$tmp/moved"
mv "$first" "$prefix"
check "nothing in the moved installation names the prefix it was installed to" \
  sh -c "! grep -rlF '$first' '$prefix'"
bin=$prefix/bin

# --- robotalk-spy -------------------------------------------------------------
check "robotalk-spy --version" test "$("$bin/robotalk-spy" --version)" = "robotalk-spy $version"
printf '#!/bin/sh\nprintf "%%s\\n" "$@"\n' >"$tmp/fake-java"
chmod +x "$tmp/fake-java"
JAVA=$tmp/fake-java "$bin/robotalk-spy" --url "$url" >"$tmp/spy.args" 2>&1
classpath=$(sed -n '/^-cp$/{n;p;}' "$tmp/spy.args")
types_jar=$(echo "$classpath" | tr ':' '\n' | grep robotalk_lcmtypes.jar)
check "robotalk-spy's class path holds the moved types jar ($types_jar)" \
  test "$(readlink -f "$types_jar")" = "$(readlink -f "$prefix/share/java/robotalk_lcmtypes.jar")"
for jar in $(echo "$classpath" | tr ':' ' '); do check "robotalk-spy's class path entry $jar exists" test -f "$jar"; done
check "robotalk-spy passes the URL to lcm-spy" grep -qxF -- "--lcm-url=$url" "$tmp/spy.args"

# --- robotalk-web ---------------------------------------------------------------
# A mark in the installed page: what is served comes from the moved tree, not the sources.
echo '<!-- the moved installation -->' >>"$prefix/share/robotalk/web/www/index.html"
"$bin/robotalk-web" --lcm-url "$url" --port 0 >"$tmp/web.out" 2>&1 &
pids+=($!)
wait_for "$tmp/web.out" "open http" 100
port=$(grep -o 'open http://[^ ]*' "$tmp/web.out" | sed 's#.*:\([0-9]*\)/$#\1#')
check "robotalk-web starts from the moved tree ($(head -1 "$tmp/web.out"))" test -n "$port"
check "robotalk-web serves the installed page" \
  sh -c "curl -sf 'http://127.0.0.1:$port/' | grep -q 'the moved installation'"
for path in /app.js /style.css /modules/three/build/three.module.js /modules/three/build/three.core.js \
  /modules/three/examples/jsm/controls/OrbitControls.js /modules/urdf-loader/src/URDFLoader.js; do
  check "robotalk-web serves $path" curl -sf -o /dev/null "http://127.0.0.1:$port$path"
done

# --- robotalk-describe, the installed model ---------------------------------
model=$prefix/share/robotalk/models/pioneer2dx_pantilt.urdf
check "robotalk-describe reads the installed model" sh -c "'$bin/robotalk-describe' '$model' | grep -q pioneer2dx_pantilt"

# --- the examples, built against the moved prefix, against its server -------
mkdir -p "$tmp/vars"
cat >"$tmp/vars/CMakeLists.txt" <<'EOF'
cmake_minimum_required(VERSION 3.22)
project(vars C)
find_package(robotalk REQUIRED)
message(STATUS "ROBOTALK_LCMTYPES_JAR=${ROBOTALK_LCMTYPES_JAR}")
message(STATUS "ROBOTALK_LCM_JAR=${ROBOTALK_LCM_JAR}")
EOF
cmake -S "$tmp/vars" -B "$tmp/vars/build" -DCMAKE_PREFIX_PATH="$prefix" >"$tmp/vars.log" 2>&1
check "find_package(robotalk) names the moved types jar" \
  grep -qF "ROBOTALK_LCMTYPES_JAR=$prefix/share/java/robotalk_lcmtypes.jar" "$tmp/vars.log"
lcm_jar=$(grep -o 'ROBOTALK_LCM_JAR=.*' "$tmp/vars.log" | cut -d= -f2-)
# The three are built at once, and run at once (each on a port of its own).
declare -A job=()
for lang in c java lua; do
  { cmake -S "$source/examples/${lang}_client" -B "$tmp/$lang" -DCMAKE_PREFIX_PATH="$prefix" >"$tmp/$lang.log" 2>&1 &&
    cmake --build "$tmp/$lang" >>"$tmp/$lang.log" 2>&1; } &
  job[$lang]=$!
  pids+=("${job[$lang]}")
done
for lang in c java lua; do
  wait "${job[$lang]}"
  check "examples/${lang}_client builds against the moved installation" test $? -eq 0
done
run_example() {  # run_example NAME PORT COMMAND...: starts it; ran NAME checks it
  local name=$1 port=$2
  shift 2
  "$source/tests/examples/client_example_test.sh" "$bin/robotalk-server" "$bin/robotalk" \
    "$prefix/share/robotalk/models" "$port" default "$@" >"$tmp/run_$name.log" 2>&1 &
  job[run_$name]=$!
  pids+=("${job[run_$name]}")
}
ran() {  # ran NAME: the example NAME started by run_example passed
  [ -n "${job[run_$1]:-}" ] || return 0
  wait "${job[run_$1]}"
  check "the $1 example runs against the moved robotalk-server" test $? -eq 0
}
run_example c 7772 "$tmp/c/robotalk_c_example"
if command -v java >/dev/null && command -v javac >/dev/null; then
  check "the Java client jar was built" test -f "$tmp/java/robotalk_java_client.jar"
  run_example java 7773 java -Djava.net.preferIPv4Stack=true \
    -cp "$lcm_jar:$prefix/share/java/robotalk_lcmtypes.jar:$tmp/java/robotalk_java_client.jar" robotalk.client.Example
else
  echo "SKIP: the Java example (no java or javac: scripts/setup.sh installs default-jdk-headless)"
fi
if [ -x "$tmp/lua/run_example.sh" ]; then
  check "the Lua launcher uses the moved modules" grep -qF "$prefix/share/lua/5.2/?.lua" "$tmp/lua/run_example.sh"
  run_example lua 7774 "$tmp/lua/run_example.sh"
else
  echo "SKIP: the Lua example (no lua5.2 or LCM Lua module: scripts/setup.sh installs them)"
fi
for name in c java lua; do ran "$name"; done

if [ "$failures" -ne 0 ]; then
  for f in "$tmp"/web.out "$tmp"/spy.args "$tmp"/vars.log "$tmp"/{c,java,lua}.log "$tmp"/run_*.log; do
    [ -f "$f" ] && { echo "--- $f"; tail -30 "$f"; }
  done
fi
echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
