#!/usr/bin/env bash
# Installs the build into a temporary prefix; checks that find_package(robotalk)
# sets ROBOTALK_LCMTYPES_JAR, ROBOTALK_LCMTYPES_LUA_DIR, ROBOTALK_LCM_JAR and
# ROBOTALK_LCM_LUA_CPATH_DIR to files that are there and work; and builds the
# three client examples on their own against the installation. No network.
#   installed_bindings_test.sh BUILD_DIR SOURCE_DIR
set -u
build=$1 source=$2
. "$(dirname "$0")/../lib.sh"  # $tmp, check, $pass, $failures
prefix=$tmp/prefix
cmake --install "$build" --prefix "$prefix" >"$tmp/install.log" 2>&1 || { cat "$tmp/install.log"; exit 1; }

# A project that only prints the variables.
mkdir -p "$tmp/vars"
cat >"$tmp/vars/CMakeLists.txt" <<'EOF'
cmake_minimum_required(VERSION 3.22)
project(vars C)
find_package(robotalk REQUIRED)
foreach(v ROBOTALK_LCMTYPES_JAR ROBOTALK_LCMTYPES_LUA_DIR ROBOTALK_LCM_JAR ROBOTALK_LCM_LUA_CPATH_DIR)
  message(STATUS "${v}=${${v}}")
endforeach()
if(TARGET robotalk::lcmtypes_c)
  message(STATUS "TARGET robotalk::lcmtypes_c")
endif()
EOF
cmake -S "$tmp/vars" -B "$tmp/vars/build" -DCMAKE_PREFIX_PATH="$prefix" >"$tmp/vars.log" 2>&1
var() { grep -o "$1=.*" "$tmp/vars.log" | head -1 | cut -d= -f2-; }
jar=$(var ROBOTALK_LCMTYPES_JAR) lua_dir=$(var ROBOTALK_LCMTYPES_LUA_DIR)
lcm_jar=$(var ROBOTALK_LCM_JAR) lcm_cpath=$(var ROBOTALK_LCM_LUA_CPATH_DIR)
check "the jar variable names the installed jar ($jar)" test "$jar" = "$prefix/share/java/robotalk_lcmtypes.jar" -a -f "$jar"
check "the Lua variable names the installed modules ($lua_dir)" test "$lua_dir" = "$prefix/share/lua/5.2" -a -f "$lua_dir/robotalk_msgs/hello_t.lua"
check "LCM's jar is named ($lcm_jar)" test -f "$lcm_jar"
check "LCM's Lua module folder is named ($lcm_cpath)" test -f "$lcm_cpath/lcm.so"
check "the C bindings are an imported target" grep -q "TARGET robotalk::lcmtypes_c" "$tmp/vars.log"
check "the installed jar holds the protocol 2 types" sh -c "/usr/bin/python3 -m zipfile -l '$jar' | grep -q robotalk_msgs/hello_answer_t.class"
# The installed Lua modules encode and decode with LCM's Lua module, from LUA_PATH alone.
roundtrip=$(LUA_PATH="$lua_dir/?.lua;$lua_dir/?/init.lua;;" LUA_CPATH="$lcm_cpath/?.so;;" lua5.2 -e "
  local m = require('robotalk_msgs')
  local h = m.hello_t:new(); h.protocol_version = 2; h.client_id = 12345
  local d = m.hello_t.decode(h:encode()); print(d.protocol_version, d.client_id)" 2>&1)
check "the installed Lua modules round-trip a hello_t ($roundtrip)" test "$roundtrip" = "2	12345"

# Each example builds on its own against the installation.
for lang in c java lua; do
  cmake -S "$source/examples/${lang}_client" -B "$tmp/$lang" -DCMAKE_PREFIX_PATH="$prefix" >"$tmp/$lang.log" 2>&1 &&
    cmake --build "$tmp/$lang" >>"$tmp/$lang.log" 2>&1
  check "examples/${lang}_client builds against the installation" test $? -eq 0
done
check "the C example was built" test -x "$tmp/c/robotalk_c_example"
check "the Java client jar was built" test -f "$tmp/java/robotalk_java_client.jar"
check "the Lua launcher uses the installed modules" grep -q "LUA_PATH=\"$prefix/share/lua/5.2/?.lua" "$tmp/lua/run_example.sh"
check "the C example says what it takes" sh -c "'$tmp/c/robotalk_c_example' --bogus 2>&1 | grep -q usage"

[ "$failures" -eq 0 ] || { for f in vars c java lua; do echo "--- $f"; cat "$tmp/$f.log"; done; }
echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
