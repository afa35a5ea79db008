#!/usr/bin/env python3
"""Issue 23 item 3's verdict per run of bench/run_bench.py's playback_estimators figure: goal met
(start / (hindsight minimum + the variant's hand-over margin) <= 1.25, no late frame, no frame not
run, no pause past the variant's stated bound, and again with every gap judged at 10 % and at 25 %) per
profile and variant, and why each other run missed.

    /usr/bin/python3 bench/playback_verdicts.py RESULTS.json [MORE.json ...]

A start of 0.45 s or more after the first frame is counted as the paper's estimate (it waits for 5
frames at 10 Hz, 0.4 s, and adds 100 ms); the adaptive start decides at the first frame."""
import json
import sys
from collections import defaultdict


def verdict(run, judged_at=None):
    """judged_at: 0.10 counts the gaps past 10 % (+ 1 ms) whatever the variant's stated bound (runs that
    recorded gaps_over_10pct; the others as recorded); 0.25 a run with any gap past 25 % (+ 1 ms at
    10 Hz: its largest gap stretch above 0.26) as one pause, else none."""
    a, h = run.get("robotalk") or {}, run.get("arrivals") or {}
    chosen, floor = a.get("chosen_delay_s"), h.get("hindsight_min_s")
    margin = (run.get("margin_ms") or 0.0) / 1e3
    why = []
    if not isinstance(a, dict) or a.get("error") or chosen is None or floor is None:
        return False, ["no result: " + str(a.get("error") if isinstance(a, dict) else a)[:80]], None
    ratio = chosen / (floor + margin) if floor + margin > 0 else None
    if chosen >= 0.45:
        why.append(f"paper's estimate ({chosen * 1e3:.0f} ms)")
    if ratio is None or ratio > 1.25:
        why.append(f"ratio {ratio:.2f} (start {chosen * 1e3:.1f} ms, floor {floor * 1e3:.1f} + "
                   f"{margin * 1e3:.0f} ms)" if ratio is not None else "no ratio")
    late, not_run, paused = int(a.get("late_frames") or 0), int(a.get("not_run") or 0), int(a.get("gaps_over_bound") or 0)
    if judged_at == 0.10 and a.get("gaps_over_10pct") is not None:
        paused = int(a["gaps_over_10pct"])
    elif judged_at == 0.25:
        paused = int((a.get("max_gap_stretch") or 0) > 0.26)
    if late:
        why.append(f"{late} late frame(s)")
    if not_run:
        why.append(f"{not_run} frame(s) not run (lost, superseded)")
    if paused:
        why.append(f"{paused} pause(s) past the bound")
    return not why, why, ratio


def main():
    runs = []
    for path in sys.argv[1:]:
        r = json.load(open(path))
        print(f"{path}: load average at start {r.get('loadavg_start')}, at the end {r.get('loadavg')}, "
              f"{r.get('wall_s')} s, {len(r.get('runs', []))} runs")
        runs += r.get("runs", [])
    table = defaultdict(list)
    for run in runs:
        table[(run["profile"], run["estimator"])].append(run)
    print("\n| profile | variant | goal met | every gap judged at 10 % | at 25 % | median ratio to hindsight + hand-over "
          "| paper's estimate | runs with second copies | runs whose client counted a loss (before the sequence) |")
    print("|---|---|---|---|---|---|---|---|---|")
    misses = []
    for (prof, est), rs in table.items():
        vs = [verdict(x) for x in rs]
        ratios = sorted(v[2] for v in vs if v[2] is not None)
        med = ratios[len(ratios) // 2] if ratios else float("nan")
        paper = sum(1 for x in rs if ((x.get("robotalk") or {}).get("chosen_delay_s") or 0) >= 0.45)
        stat = lambda x, k: (x.get("robotalk") or {}).get(k) or 0  # noqa: E731
        copied = sum(1 for x in rs if stat(x, "playback_copies") > 0)
        lossy = sum(1 for x in rs if stat(x, "messages_lost") > 0)
        before = sum(1 for x in rs if stat(x, "messages_lost_before") > 0)
        at10, at25 = (sum(verdict(x, b)[0] for x in rs) for b in (0.10, 0.25))
        print(f"| {prof} | {est} | {sum(v[0] for v in vs)} of {len(rs)} | {at10} of {len(rs)} | {at25} of {len(rs)} "
              f"| {med:.2f} | {paper} | {copied} | {lossy} ({before}) |")
        misses += [(prof, est, x["seed"], v[1] + [f"second copies {stat(x, 'playback_copies'):.0f}, client "
                                                   f"counted {stat(x, 'messages_lost'):.0f} lost"])
                   for x, v in zip(rs, vs) if not v[0]]
    print("\nMisses:")
    for prof, est, seed, why in misses:
        print(f"- {prof}, {est}, seed {seed}: " + "; ".join(why))


if __name__ == "__main__":
    main()
