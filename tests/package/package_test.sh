#!/usr/bin/env bash
# Installs the build into a temporary prefix and builds a separate CMake
# project against it with find_package(robotalk).
#   package_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1 source=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cmake --install "$build" --prefix "$tmp/prefix" >"$tmp/install.log"
cmake -S "$source/tests/package/consumer" -B "$tmp/consumer" -DCMAKE_PREFIX_PATH="$tmp/prefix" >"$tmp/configure.log"
cmake --build "$tmp/consumer" >"$tmp/build.log"
"$tmp/consumer/consumer" "$source/models/pioneer2dx_pantilt.urdf" | grep -q "pioneer2dx_pantilt 4 dofs"
echo "1 passed, 0 failed"
