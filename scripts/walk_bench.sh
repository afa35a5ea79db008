#!/usr/bin/env bash
# The walking humanoid's benchmark in one command (docs/ode_sim.md, "Walking"):
# builds robotalk-walk-bench, walks 20 seeded GOTO goals (up to 2 m, any
# heading) with models/simple_humanoid.urdf on the ode driver (walk=true) at
# 1 kHz, prints per goal the answer, end error, speed and falls and the
# real-time factor, then the steady SETSPEED speed forward, back, sideways
# and turning (--speeds 4), and plots the top view of one walk (footsteps, ZMP, CoM)
# with python3-matplotlib when it is installed (scripts/setup.sh installs it).
#
#   scripts/walk_bench.sh [--goals N] [--seed S] [--trace-goal K]
# Environment: ROBOTALK_BUILD_DIR (default build), WALK_PLOT (default
# docs/figures/walk_topview.png); WALK_SWEEP=1 also runs robotalk-walk-sweep:
# the phase sweep of every transition (WALK_SWEEP_EVERY ms, default 20),
# the push survival standing and walking with and without the stabilizer
# (WALK_PUSH_RESOLUTION N·s, default 5), the arm swing, and the CPU per
# physics step with and without the stabilizer (issue 26; an hour or more of
# CPU at 20 ms). WALK_ATLAS=1 also walks Atlas (WALK_ATLAS_URDF, default
# ../shared/robots/atlas.urdf, base=floating) through the same seeded goals on
# its derived gait (docs/ode_sim.md, "Published humanoids"; ~10 min of CPU).
# Exit status 0 only for N/N successes, no fall (and, with WALK_SWEEP=1, no
# fall in the sweep; with WALK_ATLAS=1, Atlas's too).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${ROBOTALK_BUILD_DIR:-build}
PLOT=${WALK_PLOT:-docs/figures/walk_topview.png}
TRACE=$(mktemp --suffix=.csv)
trap 'rm -f "$TRACE"' EXIT
flock /tmp/rt-build.lock cmake --build "$BUILD_DIR" --target robotalk-walk-bench robotalk-walk-sweep -j2 >/dev/null
status=0
"$BUILD_DIR/bench/robotalk-walk-bench" --goals 20 --seed 1 --trace "$TRACE" "$@" || status=$?
# The steady SETSPEED speeds per direction (the gait's limits walked).
"$BUILD_DIR/bench/robotalk-walk-bench" --speeds 4 || status=$?
PY=python3
[ -x /usr/bin/python3 ] && PY=/usr/bin/python3  # Debian's, where python3-matplotlib lives
if "$PY" -c 'import matplotlib' 2>/dev/null; then
  mkdir -p "$(dirname "$PLOT")"
  "$PY" scripts/plot_walk.py "$TRACE" "$PLOT" && echo "top view: $PLOT"
else
  echo "python3-matplotlib not installed: no plot (scripts/setup.sh installs it)"
fi
if [ "${WALK_ATLAS:-0}" = 1 ]; then
  "$BUILD_DIR/bench/robotalk-walk-bench" --model "${WALK_ATLAS_URDF:-../shared/robots/atlas.urdf}" \
    --option base=floating --goals 20 --seed 1 || status=$?
fi
if [ "${WALK_SWEEP:-0}" = 1 ]; then
  "$BUILD_DIR/bench/robotalk-walk-sweep" --every "${WALK_SWEEP_EVERY:-20}" --after 3 || status=$?
  # Pushes in 8 directions, standing and walking, with and without the
  # stabilizer, then the arm swing (both settings): one table.
  "$BUILD_DIR/bench/robotalk-walk-sweep" --push all --after 8 --resolution "${WALK_PUSH_RESOLUTION:-5}"
  "$BUILD_DIR/bench/robotalk-walk-sweep" --rtf 10
fi
exit $status
