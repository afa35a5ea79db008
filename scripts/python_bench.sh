#!/usr/bin/env bash
# The Python client's figures beside the C++ client's, in one run
# (docs/performance.md, "The Python client"):
#   scripts/python_bench.sh [--runs N] [--stream-seconds S] [--query-count N]
# Builds what it runs, then bench/python_bench.py inside a private network
# namespace (scripts/netns_run.sh; exits 77 where none can be made).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${ROBOTALK_BUILD_DIR:-build}
cmake --build "$BUILD_DIR" -j"$(nproc)" --target robotalk-server robotalk-bench-client robotalk-bench-raw \
  robotalk_python_module >/dev/null
exec scripts/netns_run.sh /usr/bin/python3 bench/python_bench.py --build "$BUILD_DIR" "$@"
