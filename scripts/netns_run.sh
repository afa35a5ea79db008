#!/usr/bin/env bash
# Runs a command inside a private network namespace whose loopback carries
# multicast (DESIGN.md §4), so LCM tests never send traffic anywhere else:
#   scripts/netns_run.sh COMMAND [ARGS...]
# Use LCM URLs like udpm://239.255.76.67:PORT?ttl=0 inside. Exits 77 (CTest's
# SKIP_RETURN_CODE) when namespaces cannot be created (not root, no unshare).
set -u
if ! command -v unshare >/dev/null || ! command -v ip >/dev/null; then
  echo "SKIP: unshare or ip (iproute2) not found" >&2
  exit 77
fi
if ! unshare -n true 2>/dev/null; then
  echo "SKIP: cannot create a network namespace here (needs root or CAP_SYS_ADMIN)" >&2
  exit 77
fi
exec unshare -n sh -c 'ip link set lo up && ip route add 224.0.0.0/4 dev lo && exec "$@"' netns_run "$@"
