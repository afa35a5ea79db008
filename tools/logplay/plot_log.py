#!/usr/bin/env python3
"""Plots a RoboTalk session exported by `robotalk-logplay export`.

usage: plot_log.py [--summary] commands.csv state.csv out.png [joints.csv]

Left: each robot's base path (x, y) from its broadcast state, with the GOTO
goals the log holds. Right: the joint positions over time, each joint on an
axis of its own (named as in state.csv's header; units from joints.csv), so
a wheel that turned 45 rad does not flatten a pan joint's +-0.5 rad. Past
MAX_AXES joints, the joints of one robot share an axis when they have the
same unit and an observed range of the same order of magnitude.

--summary also prints one line per joint axis: "joint axis N: ROBOT: NAME[,
NAME...] (UNIT)". A robot whose joints are named q0, q1, ... had no
configuration in the log: its axes say so.
"""
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

MAX_AXES = 12
BASE_COLUMNS = ["robot", "log_time_us", "server_time_us", "panic", "moving", "x", "y", "theta", "v", "omega"]


def read_states(state_csv):
    """robot -> {"t": [...], "x": [...], "y": [...], "joints": {name: [...]}} (joint order kept)."""
    states = {}
    with open(state_csv, newline="") as f:
        reader = csv.DictReader(f)
        joint_columns = [c for c in reader.fieldnames or [] if c not in BASE_COLUMNS]
        for row in reader:
            s = states.setdefault(row["robot"], {"t": [], "x": [], "y": [], "joints": {}})
            s["t"].append(int(row["server_time_us"]) * 1e-6)
            s["x"].append(float(row["x"]))
            s["y"].append(float(row["y"]))
            if joint_columns == ["q"]:  # an export from before the joints were named
                values = {f"q{i}": float(v) for i, v in enumerate(row["q"].split())}
            else:
                values = {c: float(row[c]) for c in joint_columns if row[c] not in ("", None)}
            for name, v in values.items():
                s["joints"].setdefault(name, [math.nan] * (len(s["t"]) - 1))
            for name, trace in s["joints"].items():
                trace.append(values.get(name, math.nan))
    return states


def read_units(joints_csv):
    """(robot, column) -> unit ("" unknown), and the robots named from no configuration."""
    units, unnamed = {}, set()
    if joints_csv:
        with open(joints_csv, newline="") as f:
            for row in csv.DictReader(f):
                units[(row["robot"], row["column"])] = row["unit"]
                if row["named_from"] != "config":
                    unnamed.add(row["robot"])
    return units, unnamed


def joint_groups(states, units, max_axes=MAX_AXES):
    """[(robot, [joint names], unit)]: one per joint, or grouped by unit and range past max_axes."""
    singles = [(robot, [name], units.get((robot, name), ""))
               for robot, s in sorted(states.items()) for name in s["joints"]]
    if len(singles) <= max_axes:
        return singles
    groups = {}
    for robot, (name,), unit in singles:
        values = [v for v in states[robot]["joints"][name] if math.isfinite(v)]
        span = max(values) - min(values) if values else 0.0
        decade = math.ceil(math.log10(max(span, 1e-3)))
        groups.setdefault((robot, unit, decade), []).append(name)
    return [(robot, names, unit) for (robot, unit, _), names in groups.items()]


def build_figure(commands_csv, state_csv, joints_csv=None):
    """The figure and its joint groups (what the PNG shows), without writing anything."""
    states = read_states(state_csv)
    units, unnamed = read_units(joints_csv)
    gotos = {}
    with open(commands_csv, newline="") as f:
        for row in csv.DictReader(f):
            if row["type"] == "GOTO" and row["values"]:
                x, y = (float(v) for v in row["values"].split()[:2])
                gotos.setdefault(row["robot"], []).append((x, y))
    groups = joint_groups(states, units)
    rows = max(1, len(groups))
    fig = plt.figure(figsize=(13, max(5.0, 1.7 * rows)))
    grid = fig.add_gridspec(rows, 2, width_ratios=[1, 1.3])
    path_ax = fig.add_subplot(grid[:, 0])
    for robot, s in sorted(states.items()):
        path_ax.plot(s["x"], s["y"], label=robot)
    for robot, goals in sorted(gotos.items()):
        path_ax.scatter([g[0] for g in goals], [g[1] for g in goals], marker="x", label=f"{robot} GOTO goals")
    path_ax.set_xlabel("x (m)")
    path_ax.set_ylabel("y (m)")
    path_ax.set_title("base path (broadcast state)")
    path_ax.axis("equal")
    path_ax.grid(True)
    if path_ax.get_legend_handles_labels()[0]:
        path_ax.legend(fontsize="small")
    if not states:
        path_ax.text(0.5, 0.5, "no STATE samples in the log\n(run `robotalk watch` while recording)",
                     ha="center", transform=path_ax.transAxes)
    joint_axes = []
    for i, (robot, names, unit) in enumerate(groups):
        ax = fig.add_subplot(grid[i, 1], sharex=joint_axes[0] if joint_axes else None)
        s = states[robot]
        t0 = s["t"][0]
        for name in names:
            ax.plot([t - t0 for t in s["t"]], s["joints"][name], label=name)
        title = f"{robot}: {', '.join(names)}"
        if robot in unnamed:
            title += " (no configuration in the log: unnamed)"
        ax.set_title(title, fontsize="small", loc="left")
        ax.set_ylabel(unit or "rad | m", fontsize="small")
        ax.grid(True)
        if len(names) > 1:
            ax.legend(fontsize="x-small", ncol=4)
        if i < len(groups) - 1:
            ax.tick_params(labelbottom=False)
        joint_axes.append(ax)
    if joint_axes:
        joint_axes[-1].set_xlabel("time since the robot's first sample (s)")
    fig.tight_layout()
    return fig, groups


def main(argv):
    summary = "--summary" in argv
    args = [a for a in argv if a != "--summary"]
    if len(args) not in (3, 4):
        sys.exit(__doc__)
    commands_csv, state_csv, out_png = args[:3]
    fig, groups = build_figure(commands_csv, state_csv, args[3] if len(args) == 4 else None)
    if summary:
        for i, (robot, names, unit) in enumerate(groups):
            print(f"joint axis {i}: {robot}: {', '.join(names)} ({unit or 'unit unknown'})")
    fig.savefig(out_png, dpi=100)


if __name__ == "__main__":
    main(sys.argv[1:])
