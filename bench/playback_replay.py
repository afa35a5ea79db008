#!/usr/bin/env python3
"""Issue 23 item 3, tenth session: replays the adaptive schedule (robotalk-server's
playback_schedule.cpp, the thin buffer included) on the arrival logs of recorded relay runs, with the
start and the playout delay each run's server chose (its --log-playback decision), so a schedule rule
can be judged on hundreds of recorded links before any relay run. The relay does not depend on the
schedule (the server acknowledges each package when it arrives), so the arrivals replay exactly; the
start does not change (the rule here is the schedule's only).

    /usr/bin/python3 bench/playback_replay.py [--thin F] [--lead C] [--fifo-only] RESULTS.json ...

Per profile: runs without a gap past the stated bound (max(0.10, F) + 1 ms at 10 Hz), runs with a gap
past 10 % + 1 ms, and the median whole-sequence stretch. --thin 0.1 (or less): the schedule before the
thin buffer. Runs without a decision (older builds) or not decided adaptively are skipped."""
import argparse
import json
from collections import defaultdict


def frames(run):
    """(arrival after frame 0's, offset, one-way delay above the least seen), in arrival order, ms."""
    h, dec = run["arrivals"], run["decision"]
    lag, transit, offset = h["lag_ms"], h["transit_ms"], h["offset_ms"]
    f0 = dec.get("frame0", 0.0)
    return sorted((offset[i] + lag[i], offset[i], transit[i] - transit[0] + f0) for i in range(len(lag)))


def fifo(dec):
    """Every package the start saw arrived in the order it was sent (the estimator's ArrivedInSendOrder)."""
    sent, delays = dec.get("sent"), dec.get("delays")
    if not sent or not delays or None in sent:
        return False
    order = sorted((s + d, s) for s, d in zip(sent, delays))
    return all(order[i][1] >= order[i - 1][1] for i in range(1, len(order)))


def replay(run, thin, lead, fifo_only, stretch=0.10, margin=2.0):
    """PlaybackSchedule::Place for each frame: [(offset, played at)], ms after frame 0's arrival."""
    dec = run["decision"]
    spread = max(dec.get("channel") or [0.0])
    thin_lead = lead * spread if (fifo(dec) or not fifo_only) else 0.0
    playout = dec["playout"]
    knot_o, knot_at = 0.0, run["robotalk"]["chosen_delay_s"] * 1e3
    out = []
    for arrival, o, d in frames(run):
        ready = arrival + margin
        if o <= knot_o:
            out.append((o, knot_at - (knot_o - o)))
            continue
        gap = o - knot_o
        earliest = knot_at + gap
        latest = earliest + gap * stretch
        want = ready
        if thin > stretch and arrival + max(thin_lead, margin) > latest:
            latest = earliest + gap * thin
            want = max(want, arrival + thin_lead)
        playout = max(playout, d + margin)
        want = max(want, arrival - d + playout)
        at = min(max(want, earliest), latest)
        if ready > latest:
            at = ready
        out.append((o, at))
        knot_o, knot_at = o, at
    return sorted(out)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--thin", type=float, default=0.25)
    ap.add_argument("--lead", type=float, default=0.25)
    ap.add_argument("--fifo-only", action="store_true")
    ap.add_argument("files", nargs="+")
    a = ap.parse_args()
    bound = max(0.10, a.thin)
    table = defaultdict(lambda: [0, 0, 0, []])
    for path in a.files:
        for run in json.load(open(path)).get("runs", []):
            dec, h = run.get("decision"), run.get("arrivals") or {}
            if not dec or not dec.get("adaptive") or not h.get("lag_ms") or run["robotalk"].get("chosen_delay_s") is None:
                continue
            if len(h["lag_ms"]) != len(h.get("transit_ms", [])):
                continue
            played = replay(run, a.thin, a.lead, a.fifo_only)
            over = [(b[1] - p[1]) - (b[0] - p[0]) for p, b in zip(played, played[1:]) if b[0] > p[0]]
            t = table[run["profile"]]
            t[0] += 1
            t[1] += all(x <= bound * 100 + 1.0 for x in over)
            t[2] += any(x > 10 + 1.0 for x in over)
            t[3].append(played[-1][1] - played[0][1] - played[-1][0])
    print(f"thin {a.thin}, lead {a.lead} x spread{' (FIFO links only)' if a.fifo_only else ''}; bound {bound:.2f}")
    print("| profile | runs | no gap past the bound | a gap past 10 % | median whole-sequence stretch |")
    print("|---|---|---|---|---|")
    for prof, (n, ok, past10, total) in sorted(table.items()):
        total.sort()
        print(f"| {prof} | {n} | {ok} | {past10} | {total[len(total) // 2]:.0f} ms |")


if __name__ == "__main__":
    main()
