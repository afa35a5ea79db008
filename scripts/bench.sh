#!/usr/bin/env bash
# RoboTalk's benchmark suite, one command (docs/performance.md):
#   scripts/bench.sh [--quick] [--only FIGURE,...] [--no-setup] [--freeze-before]
# Installs what is missing and builds the programs it runs (scripts/setup.sh), runs every
# multi-process figure inside a private network namespace
# (scripts/netns_run.sh) beside its raw-LCM or bare-timer floor, writes
# bench/results/latest/*.json and regenerates the tables of
# docs/performance.md and docs/figures/perf_*.png. Full: about 10 minutes
# once built; --quick: a ~2 minute smoke run (fewer, shorter runs).
#   --no-setup       use the existing build dir as it is (no apt, no build)
#   --freeze-before  also make this run the BEFORE column (bench/results/before)
# Needs root (or CAP_SYS_ADMIN) for the namespace; exits 77 with "SKIP:" otherwise.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${ROBOTALK_BUILD_DIR:-build}
run_args=() gen_args=() setup=1
while (($#)); do
  case $1 in
    --quick) run_args+=(--quick) ;;
    --only) run_args+=(--only "$2"); shift ;;
    --no-setup) setup=0 ;;
    --freeze-before) gen_args+=(--freeze-before) ;;
    -h|--help) sed -n 2,11p "$0"; exit 0 ;;
    *) echo "bench.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
  shift
done
# Debian's interpreter: it is the one that sees python3-matplotlib (a pyenv or
# venv python3 earlier in PATH may not).
PY=/usr/bin/python3
[ -x "$PY" ] || PY=python3
start=$(date +%s)
# Only what the suite runs: the whole project (its tests, Java, the web page)
# would double the time a clean clone needs before the first figure.
bench_targets="robotalk-server robotalk robotalk-lcm-relay robotalk-bench-raw robotalk-bench-timer
  robotalk-bench-client robotalk-bench-link robotalk-kinematics-bench robotalk-codec-bench robotalk-ode-bench
  robotalk-trajectory-bench robotalk-receding-client"
if ((setup)); then ROBOTALK_BUILD_TARGETS=$(echo $bench_targets) scripts/setup.sh; fi
echo "bench: built in $(( $(date +%s) - start )) s; running the suite" >&2
rc=0
scripts/netns_run.sh "$PY" bench/run_bench.py --build "$BUILD_DIR" "${run_args[@]}" || rc=$?
if ((rc == 77)); then echo "SKIP: no private network namespace here; nothing measured" >&2; exit 77; fi
((rc == 0)) || { echo "bench: run_bench.py failed ($rc)" >&2; exit "$rc"; }
"$PY" bench/gen_performance.py "${gen_args[@]}"
echo "bench: done in $(( $(date +%s) - start )) s; see docs/performance.md" >&2
