#!/usr/bin/env bash
# The README's main command: installs what is missing, builds what the demo
# runs (robotalk-server, the robotalk CLI, robotalk-web; scripts/test.sh
# builds the rest), then runs a robotalk-server with a simulated Pioneer and
# drives it with the robotalk CLI from other processes (scripts/demo_session.sh).
# It runs inside a private network namespace when it can (root), so no
# multicast leaves the machine; otherwise on this host with ttl=0.
set -euo pipefail
cd "$(dirname "$0")/.."

usage() {
  cat <<'EOF'
usage: scripts/demo.sh [--keep | --once]
Builds the server, the CLI and the web view, then runs a simulated Pioneer
(ODE physics) and drives it with the robotalk CLI, step by step.
  --keep     afterwards, leave the server, robotalk-web and a slow scripted
             motion running until Ctrl-C (the default when stdin is a terminal)
  --once     stop everything after the walkthrough (the default otherwise, e.g. in CI)
  -h, --help print this help and exit
Environment: ROBOTALK_DEMO_NETNS=0 runs the session on this host (ttl=0)
instead of a private network namespace; ROBOTALK_WEB_PORT (default 8080, or
the next free one) is the browser's port; ROBOTALK_BUILD_DIR (default build).
EOF
}
keep=0
[ -t 0 ] && keep=1
for arg in "$@"; do
  case $arg in
    --keep) keep=1 ;;
    --once) keep=0 ;;
    -h | --help) usage; exit 0 ;;
    *) echo "demo.sh: unknown option '$arg' (see --help)" >&2; exit 2 ;;
  esac
done
export ROBOTALK_DEMO_KEEP=$keep

# Build output as one progress line (a terminal) or a line every 10 %, not
# make's target lists; everything else (apt, npm, warnings, errors) as is.
quiet_build() {
  awk -v tty="$([ -t 1 ] && echo 1 || echo 0)" '
    function flush_line() { if (pending) { printf "\n"; pending = 0 } }
    /^\[ *[0-9]+%\]/ {
      pct = $0; sub(/^\[ */, "", pct); sub(/%.*/, "", pct)
      what = $0; sub(/^\[ *[0-9]+%\] /, "", what)
      if (what ~ /^(Built target|Scanning dependencies|Consolidate compiler)/) what = ""
      sub(/^(Building|Linking) [A-Z+]+ (object|executable|static library) /, "", what)
      sub(/\.dir\//, " ", what)
      if (tty) {
        printf "\r\033[Kbuilding %3d%% %s", pct, substr(what, 1, 60); pending = 1; fflush()
      } else if (int(pct / 10) != last) {
        last = int(pct / 10); printf "building %d%%\n", pct; fflush()
      }
      next
    }
    /^(make|gmake)(\[[0-9]+\])?: /  { if ($0 !~ /Error|error/) next }
    { flush_line(); print; fflush() }
    END { if (pending) printf "\r\033[K" }'
}
started=$SECONDS
ROBOTALK_BUILD_TARGETS="robotalk-server robotalk robotalk-web" scripts/setup.sh 2>&1 | quiet_build
echo "robotalk: built robotalk-server, robotalk and robotalk-web ($((SECONDS - started)) s)"

if [ "${ROBOTALK_DEMO_NETNS:-1}" != 0 ] && unshare -n true 2>/dev/null; then
  # This namespace, kept open for scripts/demo_forward.py: it offers
  # robotalk-web's page on this machine's loopback from inside the private one.
  exec 9</proc/self/ns/net
  export ROBOTALK_DEMO_HOST_NETNS_FD=9
  exec scripts/netns_run.sh scripts/demo_session.sh
fi
[ "${ROBOTALK_DEMO_NETNS:-1}" = 0 ] || echo "(no network namespace available: running on this host with ttl=0)"
exec scripts/demo_session.sh
