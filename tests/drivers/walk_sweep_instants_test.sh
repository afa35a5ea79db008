#!/usr/bin/env bash
# robotalk-walk-sweep --instants: each push is a fork of its instant's walk,
# and its outcome is the outcome of a fresh run pushed the same way
# (--probe). One instant, 20 N s, every direction; two checked by --probe
# (at this instant 45 deg falls and 90 deg is survived).
# Usage: walk_sweep_instants_test.sh ROBOTALK_WALK_SWEEP
set -euo pipefail
sweep=$1
# A flag without its value (a trailing --help, --every) is refused at once,
# naming it (before: silently ignored, and the whole default run started).
status=0
err=$(timeout 20 "$sweep" --seed 1 --help 2>&1 >/dev/null) || status=$?
[ "$status" -eq 2 ] || { echo "FAIL: a trailing flag: exit status $status, expected 2"; exit 1; }
grep -q -- "--help needs a value" <<<"$err" || { echo "FAIL: a trailing flag not named: $err"; exit 1; }
# --push goto takes goto or goto,DEG,N_S (the pushed GOTO, docs/ode_sim.md).
status=0
err=$(timeout 20 "$sweep" --push goto,90 2>&1 >/dev/null) || status=$?
[ "$status" -eq 2 ] || { echo "FAIL: --push goto,90: exit status $status, expected 2"; exit 1; }
grep -q -- "goto,DEG,N_S" <<<"$err" || { echo "FAIL: --push goto,90 not explained: $err"; exit 1; }
out=$("$sweep" --push walking --instants 1 --levels 20 --after 3 --cycle 0.05 --stabilizer off 2>&1)
echo "$out"
at=$(sed -n 's/^push instants (s into the walk): //p' <<<"$out")
[ -n "$at" ] || { echo "FAIL: no push instant printed"; exit 1; }
grep -q '^survived [0-9]* of 8 pushes' <<<"$out" || { echo "FAIL: no total"; exit 1; }
for deg in 45 90; do
  cell=$(sed -n "s/^cell $deg 20 \([SF]\)$/\1/p" <<<"$out")
  [ -n "$cell" ] || { echo "FAIL: no cell for $deg deg"; exit 1; }
  probe=$("$sweep" --probe "walking,$deg,20,$at" --after 3 --stabilizer off 2>&1 | tail -1)
  echo "$probe"
  case "$probe" in
    *survived) want=S ;;
    *FELL) want=F ;;
    *) echo "FAIL: probe said '$probe'"; exit 1 ;;
  esac
  [ "$cell" = "$want" ] || { echo "FAIL: $deg deg: the fork's $cell, a fresh run's $want"; exit 1; }
done
echo PASS
