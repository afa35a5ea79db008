#!/usr/bin/env bash
# CTest entry of the browser test (page_test.mjs), run inside a private
# network namespace by scripts/netns_run.sh:
#   run_page_test.sh SCENARIO SERVER CLI WEB MODELS_DIR SHARED_ROBOTS OUT_DIR
# Needs node, Debian's chromium and chromium-driver, and tools/web/node_modules
# (all installed by scripts/setup.sh): missing ones fail the test, they are
# part of the project. The arms scenario skips (exit 77) without ../shared/robots.
set -u
scenario=$1
export ROBOTALK_SERVER=$2 ROBOTALK_CLI=$3 ROBOTALK_WEB=$4 MODELS_DIR=$5 SHARED_ROBOTS=$6 OUT_DIR=$7
export CHROMIUM=${CHROMIUM:-/usr/bin/chromium} CHROMEDRIVER=${CHROMEDRIVER:-/usr/bin/chromedriver}
export LCM_URL="udpm://239.255.76.67:7851?ttl=0"
here=$(cd "$(dirname "$0")" && pwd)
for tool in node "$CHROMIUM" "$CHROMEDRIVER"; do
  command -v "$tool" >/dev/null || { echo "FAIL: $tool not found (scripts/setup.sh installs it)"; exit 1; }
done
if [ "$scenario" = arms ] && [ ! -f "$SHARED_ROBOTS/iiwa14.urdf" ]; then
  echo "SKIP: $SHARED_ROBOTS/iiwa14.urdf not found"
  exit 77
fi
# Chromium wants a writable home for its profile; keep it out of the user's.
export HOME=$(mktemp -d /tmp/robotalk-web-test.XXXXXX)
trap 'rm -rf "$HOME"' EXIT
node "$here/page_test.mjs" "$scenario"
