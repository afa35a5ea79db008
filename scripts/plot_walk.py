#!/usr/bin/env python3
"""Top view of one walk from robotalk-walk-bench --trace: the planned
footsteps (sole rectangles where each foot was set down), the reference ZMP,
the planned CoM and the CoM measured on the physics, the pelvis path.

    plot_walk.py TRACE.csv OUT.png

Or the paths of robots from `robotalk watch` (examples/fig10.sh, the
paper's Fig. 10: the same GOTO sequence driven and walked):

    plot_walk.py --paths OUT.png NAME=WATCH.txt...
"""
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Polygon  # noqa: E402

FRONT, BACK, HALF_WIDTH = 0.15, 0.09, 0.06  # simple_humanoid's sole around the ankle, m


def sole(x, y, th):
    c, s = math.cos(th), math.sin(th)
    pts = [(FRONT, HALF_WIDTH), (-BACK, HALF_WIDTH), (-BACK, -HALF_WIDTH), (FRONT, -HALF_WIDTH)]
    return [(x + c * px - s * py, y + s * px + c * py) for px, py in pts]


def read_watch(path):
    """(x, y, theta) of each `robotalk watch` line: 'N t=T base X Y TH v=.. w=.. q ...'."""
    xs, ys, ths = [], [], []
    for line in open(path):
        parts = line.split()
        if len(parts) >= 6 and parts[2] == "base":
            xs.append(float(parts[3]))
            ys.append(float(parts[4]))
            ths.append(float(parts[5]))
    return xs, ys, ths


def plot_paths(out, specs):
    fig, ax = plt.subplots(figsize=(7, 7))
    corners = [(1, 0, 0), (1, 1, math.pi / 2), (0, 1, math.pi), (0, 0, -math.pi / 2)]
    for x, y, th in corners:
        ax.annotate("", xy=(x + 0.12 * math.cos(th), y + 0.12 * math.sin(th)), xytext=(x, y),
                    arrowprops=dict(arrowstyle="->", color="black"))
    ax.plot([c[0] for c in corners], [c[1] for c in corners], "ko", markersize=4, label="GOTO goals")
    for spec, colour in zip(specs, ("tab:blue", "tab:red", "tab:green")):
        name, path = spec.split("=", 1)
        xs, ys, ths = read_watch(path)
        if not xs:
            print(f"{path}: no samples", file=sys.stderr)
            continue
        ax.plot(xs, ys, color=colour, linewidth=1.2, label=name)
        for i in range(0, len(xs), 50):  # heading every 10 s at 0.2 s samples
            ax.annotate("", xy=(xs[i] + 0.06 * math.cos(ths[i]), ys[i] + 0.06 * math.sin(ths[i])),
                        xytext=(xs[i], ys[i]), arrowprops=dict(arrowstyle="->", color=colour, lw=0.7))
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("Fig. 10 on ODE: one GOTO sequence, a Pioneer drives it, the humanoid walks it")
    ax.legend(loc="center", fontsize=8)
    ax.grid(True, linewidth=0.3)
    fig.savefig(out, dpi=110, bbox_inches="tight")


def main():
    if len(sys.argv) >= 4 and sys.argv[1] == "--paths":
        plot_paths(sys.argv[2], sys.argv[3:])
        return
    rows = list(csv.DictReader(open(sys.argv[1])))
    if not rows:
        sys.exit("empty trace")
    f = lambda k: [float(r[k]) for r in rows]  # noqa: E731
    fig, ax = plt.subplots(figsize=(8, 8))
    for side, colour in (("l", "tab:blue"), ("r", "tab:red")):
        last = None
        for r in rows:
            key = (round(float(r[side + "x"]), 4), round(float(r[side + "y"]), 4))
            if float(r[side + "h"]) == 0.0 and key != last:
                ax.add_patch(Polygon(sole(float(r[side + "x"]), float(r[side + "y"]), float(r[side + "th"])),
                                     closed=True, fill=False, edgecolor=colour, linewidth=0.8))
                last = key
    ax.plot(f("zmp_x"), f("zmp_y"), color="tab:green", linewidth=1, label="reference ZMP")
    ax.plot(f("com_plan_x"), f("com_plan_y"), color="black", linewidth=1, label="planned CoM")
    ax.plot(f("com_x"), f("com_y"), color="tab:orange", linewidth=1, linestyle="--", label="measured CoM")
    if "zmp_meas_x" in rows[0]:
        ax.plot(f("zmp_meas_x"), f("zmp_meas_y"), color="tab:purple", linewidth=0.5, alpha=0.6,
                label="measured ZMP (centre of pressure)")
    ax.plot(f("pelvis_x"), f("pelvis_y"), color="tab:gray", linewidth=0.8, linestyle=":", label="pelvis")
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("simple_humanoid on ODE: footsteps (blue left, red right), ZMP and CoM")
    ax.legend(loc="best", fontsize=8)
    ax.grid(True, linewidth=0.3)
    fig.savefig(sys.argv[2], dpi=110, bbox_inches="tight")


if __name__ == "__main__":
    main()
