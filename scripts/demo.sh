#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, and shows
# RoboTalk on the project's own robot model.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
BUILD_DIR=${ROBOTALK_BUILD_DIR:-build}
MODEL=models/pioneer2dx_pantilt.urdf

echo "== The motion specification of $MODEL (robotalk-describe)"
"$BUILD_DIR"/tools/describe/robotalk-describe "$MODEL"
echo
echo "== The same robot with its pan-tilt chain merged into one 2-dof joint (--merge-chains)"
"$BUILD_DIR"/tools/describe/robotalk-describe --merge-chains "$MODEL" | sed -n '/^Joints/,/^$/p'
