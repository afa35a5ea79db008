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
# (A bash loop, not awk: mawk reads a pipe in blocks, so its progress would lag.)
quiet_build() {
  local tty=0 line pct what last=-1 pending=0
  [ -t 1 ] && tty=1
  while IFS= read -r line; do
    if [[ $line =~ ^\[\ *([0-9]+)%\]\ (.*)$ ]]; then
      pct=${BASH_REMATCH[1]} what=${BASH_REMATCH[2]}
      case $what in "Built target"* | "Scanning dependencies"* | "Consolidate compiler"*) what="" ;; esac
      what=${what#Linking CXX executable } what=${what#Linking CXX static library }
      what=${what##*/} what=${what%.o}  # the file being compiled or linked
      if [ "$tty" = 1 ]; then
        printf '\r\033[Kbuilding %3d%% %s' "$pct" "${what:0:50}"
        pending=1
      elif ((pct / 10 != last)); then
        last=$((pct / 10))
        echo "building $pct%"
      fi
      continue
    fi
    [[ $line =~ ^g?make(\[[0-9]+\])?:\  && ! $line =~ [Ee]rror ]] && continue
    if ((pending)); then echo; pending=0; fi
    printf '%s\n' "$line"
  done
  if ((pending)); then printf '\r\033[K'; fi
  return 0
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
