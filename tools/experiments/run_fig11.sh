#!/usr/bin/env bash
# The paper's Fig. 11 experiment from one command (docs/experiment.md):
#
#   tools/experiments/run_fig11.sh [--quick] [--build DIR] [--out DIR] [--pause S] [--seed N]
#
# For each condition {no congestion, congestion} and each mode {direct,
# delay 10 s, delay 2 s, playback} it starts a fresh robotalk-server (the
# robot starts at the origin), runs robotalk-fig11 against it, and stops the
# server; then plot_fig11.py draws the figure and the metrics table.
# Everything runs inside a private network namespace (scripts/netns_run.sh).
#
#   --quick      the short profile (14.4 s, 3 m) instead of the full one (30.4 s, 6 m);
#                writes fig11_quick.png / fig11_quick_metrics.csv
#   --build DIR  the CMake build directory (default: build/ beside this checkout)
#   --out DIR    where the figure and tables go (default docs/figures)
#   --pause S    the congestion injector's maximum pause (default 0.4: see docs/experiment.md)
#   --seed N     the injector's seed (default 1)
#   --only L,..  run only these labels (e.g. congestion_direct), keep the other runs' files
#
# Exit status: 0 all runs succeeded; 1 a run failed; 2 usage; 77 no namespace.
set -u
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)

if [ "${FIG11_IN_NETNS:-}" != 1 ]; then
  FIG11_IN_NETNS=1 exec "$root/scripts/netns_run.sh" "$0" "$@"
fi

quick=0 build="$root/build" out="$root/docs/figures" pause=0.4 seed=1 only=
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) quick=1 ;;
    --build) build=$2; shift ;;
    --out) out=$2; shift ;;
    --pause) pause=$2; shift ;;
    --seed) seed=$2; shift ;;
    --only) only=",$2,"; shift ;;
    -h|--help) sed -n '2,21p' "$0"; exit 0 ;;
    *) echo "run_fig11.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
  shift
done

server="$build/robotalk-server/robotalk-server"
client="${FIG11_CLIENT:-$build/tools/experiments/robotalk-fig11}"
for exe in "$server" "$client"; do
  [ -x "$exe" ] || { echo "run_fig11.sh: $exe not built (cmake --build $build --target robotalk-server robotalk-fig11)" >&2; exit 2; }
done

if [ $quick = 1 ]; then
  name=fig11_quick length=3 duration=14.4
else
  name=fig11 length=6 duration=30.4
fi
runs="$out/$name"
mkdir -p "$runs"
url='udpm://239.255.76.67:7667?ttl=0'
logs=$(mktemp -d)
trap 'rm -rf "$logs"' EXIT

# The client never resends within a run: the link is lossless loopback, and
# the client's fixed 100 ms retransmission would multiply the congested
# link's load (docs/experiment.md, "Retransmission under congestion").
# The paper's delay mode has no deadlines: a late frame runs late (issue 23's
# default 0.1 s deadline would refuse them; run_fig11_stall.sh compares both).
client_net=(--retransmit-interval 120 --give-up 600 --max-late never)

status=0
for condition in none congestion; do
  if [ $condition = none ]; then
    server_args=() congestion=none
  else
    server_args=(--congestion-max-pause "$pause" --seed "$seed") congestion="injector U[0 ${pause}] s seed $seed"
  fi
  for run in direct delay10 delay2 playback; do
    case $run in
      direct) mode_args=(--mode direct) ;;
      delay10) mode_args=(--mode delay --delay 10) ;;
      delay2) mode_args=(--mode delay --delay 2) ;;
      playback) mode_args=(--mode playback) ;;
    esac
    label="${condition}_$run"
    if [ -n "$only" ] && [[ "$only" != *",$label,"* ]]; then continue; fi
    # Bounds: under congestion delay and playback take about 2x the profile
    # plus their delay; direct mode, whose every frame waits for a reply
    # (and heartbeats join the queue while it waits), about 5.5x.
    factor=3
    [ $run = direct ] && factor=8
    limit=$(awk -v d="$duration" -v f=$factor 'BEGIN { printf "%d", f * d + 60 }')
    "$server" --robot pioneer=kinematic:"$root"/models/pioneer2dx_pantilt.urdf --url "$url" \
      --duration $((limit + 10)) "${server_args[@]}" 2>"$logs/server_$label.log" &
    spid=$!
    for _ in $(seq 100); do
      grep -q "serving robot" "$logs/server_$label.log" 2>/dev/null && break
      sleep 0.1
    done
    echo "== $label: server ${server_args[*]:-(no congestion)}; client ${mode_args[*]}" >&2
    timeout $((limit + 5)) "$client" --url "$url" "${mode_args[@]}" --length $length --duration $duration \
      --label "$label" --congestion "$congestion" --out "$runs/$label" --max-seconds "$limit" "${client_net[@]}"
    rc=$?
    if [ $rc != 0 ]; then
      echo "run_fig11.sh: $label failed (exit $rc); server log:" >&2
      tail -5 "$logs/server_$label.log" >&2
      status=1
    fi
    kill "$spid" 2>/dev/null
    wait "$spid" 2>/dev/null
  done
done

"$client" --print-ideal "$runs/ideal.csv" --length $length --duration $duration >&2 || status=1
# Debian's python3-matplotlib (scripts/setup.sh) lives under /usr/bin/python3,
# which another python3 earlier on PATH (pyenv, a venv) may not see.
python=python3
python3 -c 'import matplotlib' 2>/dev/null || python=/usr/bin/python3
"$python" "$here/plot_fig11.py" --runs "$runs" --png "$out/$name.png" --table "$out/${name}_metrics.csv" || status=1
exit $status
