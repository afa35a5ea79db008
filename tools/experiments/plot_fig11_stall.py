#!/usr/bin/env python3
"""Draws Fig. 11's teleoperation stall (issue 23) from run_fig11_stall.sh's runs.

    plot_fig11_stall.py --runs DIR --png FIG.png --table METRICS.csv

Top row: the path the robot drove against the ideal, without and with
deadlines. Bottom row: when each frame ran (server time after the first frame
was sent) against its offset in the profile: on schedule a frame sits on the
diagonal; the stall's burst is the flat run of frames executed at once; an
expired frame (not executed) is a red cross at its offset.
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from plot_fig11 import parse_args, read_csv, write_metrics  # noqa: E402  (beside this script)

RUNS = [("stall_nodeadline", "no deadline (--max-late never)"), ("stall_deadline", "deadline 0.1 s (default)")]


def main():
    args = parse_args(__doc__)
    ideal = read_csv(os.path.join(args.runs, "ideal.csv"))
    fig, axes = plt.subplots(2, len(RUNS), figsize=(5.5 * len(RUNS), 9.5), squeeze=False)
    rows, header = [], None
    for i, (label, title) in enumerate(RUNS):
        top, bottom = axes[0][i], axes[1][i]
        top.plot([float(r["x"]) for r in ideal], [float(r["y"]) for r in ideal], "--", color="0.6", label="ideal")
        top.set_aspect("equal", adjustable="datalim")
        top.grid(True, lw=0.3)
        mpath, tpath, fpath = (os.path.join(args.runs, f"{label}_{k}.csv") for k in ("metrics", "traj", "frames"))
        if not all(os.path.exists(p) for p in (mpath, tpath, fpath)):
            top.set_title(f"{title}\n(run failed)")
            continue
        m = read_csv(mpath)[0]
        header = list(m.keys())
        rows.append(m)
        traj = read_csv(tpath)
        top.plot([float(r["x"]) for r in traj], [float(r["y"]) for r in traj], "-", color="C3", lw=1.2, label="robot")
        top.set_title(f"{title}\nmax dev {100 * float(m['max_dev_m']):.1f} cm, end {100 * float(m['end_error_m']):.1f} cm, "
                      f"{m['expired_frames']} frames expired", fontsize=9)
        top.set_xlabel("x (m)")
        top.set_ylabel("y (m)")
        frames = read_csv(fpath)
        ran = [r for r in frames if r["signal"] in ("SUCCESS", "MODIFIED")]
        expired = [r for r in frames if r["signal"] == "INTERRUPTED"]
        offs = [float(r["offset_s"]) for r in frames]
        base = min(float(r["exec_s"]) - float(r["offset_s"]) for r in ran) if ran else 0.0
        bottom.plot([0, max(offs)], [base, base + max(offs)], "--", color="0.6", label="on schedule")
        bottom.plot([float(r["offset_s"]) for r in ran], [float(r["exec_s"]) for r in ran], ".", ms=3, color="C0",
                    label="executed")
        if expired:
            bottom.plot([float(r["offset_s"]) for r in expired], [base + float(r["offset_s"]) for r in expired], "x",
                        ms=4, color="C3", label="expired (not executed)")
        bottom.set_xlabel("frame offset in the profile (s)")
        bottom.set_ylabel("executed at (s after the first frame was sent)")
        bottom.grid(True, lw=0.3)
        bottom.legend(loc="upper left", fontsize=8)
        late = max((float(r["lateness_s"]) for r in ran), default=0.0)
        bottom.set_title(f"{len(ran)} frames executed, max lateness {late:.2f} s", fontsize=9)
    axes[0][0].legend(loc="upper right", fontsize=8)
    fig.suptitle("Fig. 11 extended: a 5 s client -> server stall, then a burst (delay mode, 1 s budget)")
    fig.tight_layout()
    fig.savefig(args.png, dpi=100)
    print(f"wrote {args.png}", file=sys.stderr)
    if header is None:
        return 1
    write_metrics(args.table, header, rows)
    for r in rows:
        print(f"| {r['label']} | {r['late_frames']} late (max {float(r['max_lateness_s']):.2f} s) | "
              f"{r['expired_frames']} expired | max dev {100 * float(r['max_dev_m']):.1f} cm |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
