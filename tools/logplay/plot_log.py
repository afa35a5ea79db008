#!/usr/bin/env python3
"""Plots a RoboTalk session exported by `robotalk-logplay export`.

usage: plot_log.py commands.csv state.csv out.png

Left: each robot's base path (x, y) from its broadcast state, with the GOTO
goals the log holds. Right: each robot's joint positions over time.
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(commands_csv, state_csv, out_png):
    states = {}
    with open(state_csv, newline="") as f:
        for row in csv.DictReader(f):
            s = states.setdefault(row["robot"], {"t": [], "x": [], "y": [], "q": []})
            s["t"].append(int(row["server_time_us"]) * 1e-6)
            s["x"].append(float(row["x"]))
            s["y"].append(float(row["y"]))
            s["q"].append([float(v) for v in row["q"].split()] if row["q"] else [])
    gotos = {}
    with open(commands_csv, newline="") as f:
        for row in csv.DictReader(f):
            if row["type"] == "GOTO" and row["values"]:
                x, y = (float(v) for v in row["values"].split()[:2])
                gotos.setdefault(row["robot"], []).append((x, y))

    fig, (path_ax, joint_ax) = plt.subplots(1, 2, figsize=(12, 5))
    for robot, s in sorted(states.items()):
        path_ax.plot(s["x"], s["y"], label=robot)
        t0 = s["t"][0]
        for j in range(max((len(q) for q in s["q"]), default=0)):
            joint_ax.plot([t - t0 for t in s["t"]], [q[j] if j < len(q) else float("nan") for q in s["q"]],
                          label=f"{robot} q{j}")
    for robot, goals in sorted(gotos.items()):
        path_ax.scatter([g[0] for g in goals], [g[1] for g in goals], marker="x", label=f"{robot} GOTO goals")
    path_ax.set_xlabel("x (m)")
    path_ax.set_ylabel("y (m)")
    path_ax.set_title("base path (broadcast state)")
    path_ax.axis("equal")
    path_ax.grid(True)
    joint_ax.set_xlabel("time since the first sample (s)")
    joint_ax.set_ylabel("position (rad | m)")
    joint_ax.set_title("joint positions")
    joint_ax.grid(True)
    for ax in (path_ax, joint_ax):
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize="small")
    if not states:
        path_ax.text(0.5, 0.5, "no STATE samples in the log\n(run `robotalk watch` while recording)",
                     ha="center", transform=path_ax.transAxes)
    fig.tight_layout()
    fig.savefig(out_png, dpi=100)


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    main(*sys.argv[1:])
