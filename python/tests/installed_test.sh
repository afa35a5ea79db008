#!/usr/bin/env bash
# The Python package installed like any Python package: `cmake --install
# --component python` into a fresh prefix, then imported from there (not from
# the build tree) with PYTHONPATH=<prefix>/<install dir>.
#   installed_test.sh BUILD_DIR PYTHON INSTALL_DIR MODELS_DIR
set -u
build=$1 python=$2 dir=$3 models=$4
. "$(dirname "$0")/../../tests/lib.sh"  # $tmp, check
cmake --install "$build" --prefix "$tmp/prefix" --component python >"$tmp/install.log" 2>&1
check "cmake --install --component python succeeds" test $? -eq 0
check "the module is in <prefix>/$dir/robotalk" sh -c "ls '$tmp/prefix/$dir/robotalk/'_robotalk*.so"
check "the stubs and py.typed are installed" test -f "$tmp/prefix/$dir/robotalk/_robotalk.pyi" -a -f "$tmp/prefix/$dir/robotalk/py.typed"
out=$(cd "$tmp" && PYTHONPATH="$tmp/prefix/$dir" "$python" -c "
import robotalk
print(robotalk.__file__)
print(robotalk.load_urdf('$models/pioneer2dx_pantilt.urdf').num_dofs)" 2>&1)
check "it imports from the prefix ($out)" sh -c "echo '$out' | head -1 | grep -q '^$tmp/prefix/$dir/robotalk/__init__.py'"
check "and works there" sh -c "echo '$out' | tail -1 | grep -qx 4"
[ "$failures" -eq 0 ] || cat "$tmp/install.log"
echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
