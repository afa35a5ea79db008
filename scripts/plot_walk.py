#!/usr/bin/env python3
"""Top view of one walk from robotalk-walk-bench --trace: the planned
footsteps (sole rectangles where each foot was set down), the reference ZMP,
the planned CoM and the CoM measured on the physics, the pelvis path.

    plot_walk.py TRACE.csv OUT.png
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


def main():
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
