#!/usr/bin/env bash
# Builds RoboTalk under a sanitizer and runs the test suite there.
#   scripts/sanitize.sh asan [ctest args]   ASan + UBSan (vptr off), into build-asan/
#   scripts/sanitize.sh tsan [ctest args]   TSan, into build-tsan/
# e.g. scripts/sanitize.sh asan -R urdf. Installs what is missing (scripts/setup.sh).
# The build runs under nice; on 2 cores a first build takes about half an hour.
# Any sanitizer report fails the test that produced it (halt_on_error).
set -euo pipefail
cd "$(dirname "$0")/.."

kind=${1:-}
case "$kind" in
  asan) sanitize=address ;;
  tsan) sanitize=thread ;;
  *)
    echo "usage: scripts/sanitize.sh asan|tsan [ctest args]" >&2
    exit 2
    ;;
esac
shift
BUILD_DIR=build-$kind
JOBS=${ROBOTALK_JOBS:-$(nproc)}

configure() {
  cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DROBOTALK_WERROR=ON \
    -DROBOTALK_SANITIZE="$sanitize" >/dev/null
}

# setup.sh installs the missing Debian packages and builds its build dir; when
# the sanitizer cache already exists it keeps ROBOTALK_SANITIZE.
if command -v cmake >/dev/null; then configure; fi
ROBOTALK_BUILD_DIR=$BUILD_DIR nice -n 19 scripts/setup.sh
configure
nice -n 19 cmake --build "$BUILD_DIR" -j"$JOBS"

# Why each option: halt_on_error makes a UBSan report fail its test (UBSan
# only prints by default); LCM and the JVM of the binding tests are not built
# with the sanitizer, so their own leaks are suppressed by library name.
supp=$(mktemp)
trap 'rm -f "$supp"' EXIT
printf 'leak:liblcm\nleak:libglib\nleak:libjvm\n' >"$supp"
# TSan: LCM 1.3.1 locks GStaticRecMutexes that glib allocates on first use
# and publishes with atomics TSan cannot see (glib is not instrumented), so
# every LCM program with a second thread reports a race inside
# g_static_rec_mutex_lock (robotalk-lcm-relay's main thread against LCM's own
# receive thread, with no RoboTalk code on either stack).
tsan_supp=$(mktemp)
trap 'rm -f "$supp" "$tsan_supp"' EXIT
printf 'race:g_static_rec_mutex_lock\n' >"$tsan_supp"
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0:strict_string_checks=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$supp:print_suppressions=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
export TSAN_OPTIONS=${TSAN_OPTIONS:-halt_on_error=1:second_deadlock_stack=1:suppressions=$tsan_supp}
# Sanitized programs run 2-3x (ASan) to 5-10x (TSan) slower: tests whose waits
# are bounded in real time for a live simulation (the browser test) scale them.
if [ "$kind" = asan ]; then export ROBOTALK_TEST_TIME_SCALE=3; else export ROBOTALK_TEST_TIME_SCALE=6; fi

run=()
if [ "$kind" = tsan ] && setarch "$(uname -m)" -R true 2>/dev/null; then
  # TSan's shadow memory needs a fixed layout. Kernels with more than 28 bits
  # of mmap randomisation (vm.mmap_rnd_bits, 32 on some 6.x distros) make
  # GCC 12's TSan die with "unexpected memory mapping"; setarch -R turns the
  # randomisation off for ctest and every child (servers, CLIs). Measured on
  # this machine (6.18 kernel, mmap_rnd_bits=28): TSan runs either way.
  run=(setarch "$(uname -m)" -R)
fi
"${run[@]}" nice -n 19 ctest --test-dir "$BUILD_DIR" --output-on-failure -j"$JOBS" --timeout 900 "$@"
