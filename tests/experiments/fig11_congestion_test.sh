#!/usr/bin/env bash
# The Fig. 11 experiment as a test (docs/experiment.md, "The test variant"):
# a short profile (12.8 s, 3 m) under the server's congestion injector, run in
# direct, delay and playback mode at once (one server per mode, each on its
# own port, all inside the private network namespace this script is run in by
# scripts/netns_run.sh). Asserts:
#   delay (budget 8 s, above the backlog): every frame runs at its start time
#       (lateness < 50 ms: a frame that missed the budget would be seconds late)
#       and the path stays within 1 cm of the ideal;
#   playback: the same lateness bound, path within 2 cm of the ideal;
#   direct: measurably worse than delay and playback (max deviation > 10 cm
#       and more than 5x theirs).
#   fig11_congestion_test.sh SERVER CLIENT MODELS_DIR [MODES...]   (MODES default: direct delay playback)
# Environment: FIG11_TEST_PAUSE (0.25), FIG11_TEST_SEED (1), FIG11_TEST_KEEP=DIR keeps the CSVs.
set -u
server=$1 client=$2 models=$3
shift 3
modes=("$@")
[ ${#modes[@]} -gt 0 ] || modes=(direct delay playback)
pause=${FIG11_TEST_PAUSE:-0.25}
seed=${FIG11_TEST_SEED:-1}
work=${FIG11_TEST_KEEP:-$(mktemp -d)}
mkdir -p "$work"
[ -n "${FIG11_TEST_KEEP:-}" ] || trap 'rm -rf "$work"' EXIT

port=7681
pids=()
for mode in "${modes[@]}"; do
  url="udpm://239.255.76.67:$port?ttl=0"
  port=$((port + 100))  # the split traffic layout uses 66 ports from each URL's (docs/protocol.md)
  case $mode in
    direct) args=(--mode direct) ;;
    delay) args=(--mode delay --delay 8) ;;
    playback) args=(--mode playback) ;;
    *) echo "unknown mode $mode" >&2; exit 2 ;;
  esac
  (
    "$server" --robot pioneer=kinematic:"$models"/pioneer2dx_pantilt.urdf --url "$url" --duration 70 \
      --congestion-max-pause "$pause" --seed "$seed" 2>"$work/server_$mode.log" &
    spid=$!
    for _ in $(seq 100); do grep -q "serving robot" "$work/server_$mode.log" 2>/dev/null && break; sleep 0.1; done
    timeout 65 "$client" --url "$url" "${args[@]}" --length 3 --duration 12.8 --label "$mode" \
      --congestion "injector U[0 $pause] s seed $seed" --out "$work/$mode" --max-seconds 60 \
      --retransmit-interval 120 --give-up 600 >"$work/client_$mode.log" 2>&1
    echo $? >"$work/rc_$mode"
    kill $spid 2>/dev/null
    wait $spid 2>/dev/null
  ) &
  pids+=($!)
done
for p in "${pids[@]}"; do wait "$p"; done

fail=0
metric() {  # metric MODE COLUMN
  awk -F, -v col="$2" 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == col) c = i } NR == 2 { print $c }' "$work/$1_metrics.csv"
}
check() {  # check DESCRIPTION AWK-CONDITION
  if awk "BEGIN { exit !($2) }"; then echo "ok: $1"; else echo "FAIL: $1 ($2)"; fail=1; fi
}
for mode in "${modes[@]}"; do
  cat "$work/client_$mode.log"
  if [ "$(cat "$work/rc_$mode")" != 0 ] || [ ! -s "$work/${mode}_metrics.csv" ]; then
    echo "FAIL: $mode run failed (exit $(cat "$work/rc_$mode"))"; tail -5 "$work/server_$mode.log"; fail=1
  fi
done
[ $fail = 0 ] || exit 1
for mode in "${modes[@]}"; do
  eval "${mode}_max=$(metric "$mode" max_dev_m) ${mode}_mean=$(metric "$mode" mean_dev_m)"
  eval "${mode}_late=$(metric "$mode" late_frames) ${mode}_lateness=$(metric "$mode" max_lateness_s)"
done
for mode in "${modes[@]}"; do
  case $mode in
    delay)
      check "delay: every frame at its start time (max lateness ${delay_lateness} s < 0.05 s; $delay_late over 5 ms)" "$delay_lateness < 0.05"
      check "delay: max deviation $delay_max m < 0.01 m" "$delay_max < 0.01" ;;
    playback)
      check "playback: every frame on schedule (max lateness ${playback_lateness} s < 0.05 s; $playback_late over 5 ms)" "$playback_lateness < 0.05"
      check "playback: max deviation $playback_max m < 0.02 m" "$playback_max < 0.02" ;;
    direct)
      check "direct: max deviation $direct_max m > 0.10 m" "$direct_max > 0.10"
      for other in delay playback; do
        [[ " ${modes[*]} " == *" $other "* ]] || continue
        eval "o=\$${other}_max"
        check "direct: max deviation $direct_max m > 5 x $other's $o m" "$direct_max > 5 * $o"
      done ;;
  esac
done
exit $fail
