#!/usr/bin/env bash
# Fig. 11 extended (issue 23): a teleoperation stall. The quick Fig. 11
# SETSPEED profile (14.4 s, 3 m) in delay mode with a 1 s budget, through
# robotalk-lcm-relay whose client -> server direction stalls for 5 s (3 s
# after the client's first message) and then delivers what it held in a
# burst: once without deadlines (--max-late never: the paper's "run late",
# the burst runs at once) and once with the robot's default deadline (0.1 s:
# the burst's late frames expire, INTERRUPTED, and do not run).
#
#   tools/experiments/run_fig11_stall.sh [--build DIR] [--out DIR]
#
# Writes DIR/fig11_stall.png and DIR/fig11_stall_metrics.csv (default
# docs/figures) and the runs under DIR/fig11_stall/. The server's session
# timeout is 10 s so the session outlives the stall (with the default 2 s the
# watchdog would stop the robot and end the session: docs/server.md).
# About 50 s. Exit status: 0 ok; 1 a run failed; 2 usage; 77 no namespace.
set -u
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
if [ "${FIG11_IN_NETNS:-}" != 1 ]; then
  FIG11_IN_NETNS=1 exec "$root/scripts/netns_run.sh" "$0" "$@"
fi
build="$root/build" out="$root/docs/figures"
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build=$2; shift ;;
    --out) out=$2; shift ;;
    -h|--help) sed -n '2,18p' "$0"; exit 0 ;;
    *) echo "run_fig11_stall.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
  shift
done
server="$build/robotalk-server/robotalk-server"
client="$build/tools/experiments/robotalk-fig11"
relay="$build/tools/lcm_relay/robotalk-lcm-relay"
for exe in "$server" "$client" "$relay"; do
  [ -x "$exe" ] || { echo "run_fig11_stall.sh: $exe not built" >&2; exit 2; }
done
runs="$out/fig11_stall"
mkdir -p "$runs"
A='udpm://239.255.76.67:7967?ttl=0' B='udpm://239.255.76.67:8067?ttl=0'
logs=$(mktemp -d)
trap 'rm -rf "$logs"' EXIT
status=0
for run in nodeadline deadline; do
  case $run in
    nodeadline) late=never ;;
    deadline) late=default ;;
  esac
  label="stall_$run"
  "$server" --robot pioneer=kinematic:"$root"/models/pioneer2dx_pantilt.urdf --url "$B" --duration 90 \
    --session-timeout 10 --no-panic-latch 2>"$logs/server_$label.log" &
  spid=$!
  "$relay" --a "$A" --b "$B" --a2b-outage-at-ms 3000 --a2b-outage-ms 5000 --latency-ms 2 --duration 85 \
    --stats >"$runs/${label}_relay.txt" 2>"$logs/relay_$label.log" &
  rpid=$!
  for _ in $(seq 100); do grep -q "serving robot" "$logs/server_$label.log" 2>/dev/null && break; sleep 0.1; done
  echo "== $label: delay 1 s, --max-late $late, a 5 s client -> server stall" >&2
  timeout 80 "$client" --url "$A" --mode delay --delay 1 --max-late "$late" --length 3 --duration 14.4 \
    --label "$label" --congestion "5 s stall then a burst" --out "$runs/$label" --max-seconds 75 \
    --retransmit-interval 0.3 --give-up 30 || { echo "run_fig11_stall.sh: $label failed" >&2; status=1; }
  kill -INT "$rpid" 2>/dev/null; wait "$rpid" 2>/dev/null
  kill "$spid" 2>/dev/null; wait "$spid" 2>/dev/null
done
"$client" --print-ideal "$runs/ideal.csv" --length 3 --duration 14.4 >&2 || status=1
python=python3
python3 -c 'import matplotlib' 2>/dev/null || python=/usr/bin/python3
"$python" "$here/plot_fig11_stall.py" --runs "$runs" --png "$out/fig11_stall.png" \
  --table "$out/fig11_stall_metrics.csv" || status=1
exit $status
