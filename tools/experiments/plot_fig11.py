#!/usr/bin/env python3
"""Draws the paper's Fig. 11 from robotalk-fig11 runs (docs/experiment.md).

    plot_fig11.py --runs DIR --png FIG.png --table METRICS.csv

DIR holds ideal.csv and, per run, LABEL_traj.csv and LABEL_metrics.csv
(LABEL = CONDITION_RUN, e.g. congestion_playback). One panel per run: the
ideal path (grey, dashed) and the path the robot drove; rows are conditions,
columns modes. The metrics of every run are gathered into one CSV, and a
Markdown version of the table is printed on stdout.
"""
import argparse
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

CONDITIONS = [("none", "no congestion"), ("congestion", "congestion")]
RUNS = [("direct", "direct"), ("delay10", "delay 10 s"), ("delay2", "delay 2 s"), ("playback", "playback")]


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def parse_args(doc):
    """--runs DIR --png FIG.png --table METRICS.csv, as every Fig. 11 plot takes them."""
    ap = argparse.ArgumentParser(description=doc.splitlines()[0])
    ap.add_argument("--runs", required=True)
    ap.add_argument("--png", required=True)
    ap.add_argument("--table", required=True)
    return ap.parse_args()


def write_metrics(path, header, rows):
    """The runs' metrics rows (dicts with the keys `header`) as one CSV."""
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=header, lineterminator="\n")
        w.writeheader()
        for r in rows:
            w.writerow(r)


def main():
    args = parse_args(__doc__)

    ideal = read_csv(os.path.join(args.runs, "ideal.csv"))
    ix = [float(r["x"]) for r in ideal]
    iy = [float(r["y"]) for r in ideal]

    rows, header = [], None
    fig, axes = plt.subplots(len(CONDITIONS), len(RUNS), figsize=(4 * len(RUNS), 4.6 * len(CONDITIONS)),
                             squeeze=False)
    for ci, (cond, cond_title) in enumerate(CONDITIONS):
        for ri, (run, run_title) in enumerate(RUNS):
            ax = axes[ci][ri]
            label = f"{cond}_{run}"
            ax.plot(ix, iy, "--", color="0.6", lw=1.5, label="ideal")
            ax.set_aspect("equal", adjustable="datalim")
            ax.grid(True, lw=0.3)
            ax.set_xlabel("x (m)")
            if ri == 0:
                ax.set_ylabel(f"{cond_title}\ny (m)")
            mpath = os.path.join(args.runs, f"{label}_metrics.csv")
            tpath = os.path.join(args.runs, f"{label}_traj.csv")
            if not (os.path.exists(mpath) and os.path.exists(tpath)):
                ax.set_title(f"{run_title}, {cond_title}\n(run failed)", fontsize=9)
                continue
            m = read_csv(mpath)[0]
            header = list(m.keys())
            rows.append(m)
            traj = read_csv(tpath)
            ax.plot([float(r["x"]) for r in traj], [float(r["y"]) for r in traj], "-", color="C0" if cond == "none" else "C3",
                    lw=1.2, label="robot")
            ax.plot([0], [0], "ko", ms=4)
            ax.set_title(
                f"{run_title}, {cond_title}\n"
                f"dev mean {100 * float(m['mean_dev_m']):.1f} cm, max {100 * float(m['max_dev_m']):.1f} cm, "
                f"end {100 * float(m['end_error_m']):.1f} cm\n"
                f"start latency {float(m['start_latency_s']):.2f} s, ran {float(m['actual_s']):.1f} s",
                fontsize=8.5)
    axes[0][0].legend(loc="upper right", fontsize=8)
    fig.suptitle("Fig. 11 reproduced: SETSPEED profile every 0.1 s, kinematic Pioneer (grey: ideal path)")
    fig.tight_layout()
    fig.savefig(args.png, dpi=110)
    print(f"wrote {args.png}", file=sys.stderr)

    if header is None:
        print("no runs found", file=sys.stderr)
        return 1
    write_metrics(args.table, header, rows)
    print(f"wrote {args.table}", file=sys.stderr)

    cols = [("label", "run"), ("start_latency_s", "start latency (s)"), ("playback_delay_s", "playback delay (s)"),
            ("actual_s", "ran (s)"), ("late_frames", "late frames"), ("max_lateness_s", "max lateness (s)"),
            ("mean_dev_m", "mean dev (cm)"), ("max_dev_m", "max dev (cm)"), ("end_error_m", "end error (cm)")]
    print("| " + " | ".join(c[1] for c in cols) + " |")
    print("|" + "---|" * len(cols))
    for r in rows:
        cells = []
        for key, _ in cols:
            v = r[key]
            if key.endswith("_m"):
                v = f"{100 * float(v):.2f}"
            elif key.endswith("_s"):
                v = f"{float(v):.2f}"
            cells.append(v)
        print("| " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
