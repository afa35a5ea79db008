#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, then runs a
# robotalk-server with a simulated Pioneer and drives it with the robotalk CLI
# from other processes (scripts/demo_session.sh). It runs inside a private
# network namespace when it can (root), so no multicast leaves the machine;
# otherwise on this host with ttl=0.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
if [ "${ROBOTALK_DEMO_NETNS:-1}" != 0 ] && unshare -n true 2>/dev/null; then  # ROBOTALK_DEMO_NETNS=0: on this host, for the browser view
  exec scripts/netns_run.sh scripts/demo_session.sh
fi
echo "(no network namespace available: running on this host with ttl=0)"
exec scripts/demo_session.sh
