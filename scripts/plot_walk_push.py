#!/usr/bin/env python3
"""Push recovery of the walking humanoid from robotalk-walk-sweep --probe
... --trace PREFIX (PREFIX.on.csv with the DCM stabilizer, PREFIX.off.csv
without): per run, the lateral (or forward) coordinate over time of the
measured CoM, the measured DCM and the planned one, the measured centre of
pressure, the plan's ZMP and the stabilizer's ZMP command, with the feet's
positions (filled while a foot is in the air) and the push marked.

    plot_walk_push.py PREFIX OUT.png [--axis y|x] [--push T] [--title TEXT]
"""
import argparse
import csv
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def load(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]} if rows else {}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("prefix")
    ap.add_argument("out")
    ap.add_argument("--axis", default="y", choices=["x", "y"])
    ap.add_argument("--push", type=float, default=None, help="time of the push, s")
    ap.add_argument("--title", default="")
    a = ap.parse_args()
    runs = [(name, a.prefix + "." + name + ".csv") for name in ("off", "on")]
    runs = [(n, p) for n, p in runs if os.path.exists(p)]
    fig, axes = plt.subplots(len(runs), 1, figsize=(9, 3.6 * len(runs)), sharex=True, squeeze=False)
    k = a.axis
    for ax, (name, path) in zip(axes[:, 0], runs):
        d = load(path)
        t = d["t"]
        start = next((i for i, v in enumerate(t) if v >= (a.push or t[0]) - 1.0), 0)
        sl = slice(start, None)
        tt = t[sl]
        for foot, colour in (("lfoot", "tab:green"), ("rfoot", "tab:olive")):
            pos = d[foot + "_" + k][sl]
            air = [h > 1e-3 for h in d[foot + "_h"][sl]]
            ax.plot(tt, pos, color=colour, lw=6, alpha=0.25, label=("left" if foot == "lfoot" else "right") + " foot")
            ax.scatter([x for x, up in zip(tt, air) if up], [p for p, up in zip(pos, air) if up], s=4, color=colour)
        ax.plot(tt, d["com_" + k][sl], color="black", label="CoM (measured)")
        ax.plot(tt, d["cop_" + k][sl], color="tab:red", lw=0.8, label="CoP (measured)")
        ax.plot(tt, d["zmp_ref_" + k][sl], color="tab:blue", ls="--", label="ZMP (plan)")
        if name == "on":
            ax.plot(tt, d["dcm_" + k][sl], color="tab:purple", label="DCM (measured)")
            ax.plot(tt, d["dcm_ref_" + k][sl], color="tab:purple", ls=":", label="DCM (plan)")
            ax.plot(tt, d["zmp_cmd_" + k][sl], color="tab:orange", lw=0.8, label="ZMP command")
        if a.push is not None:
            ax.axvspan(a.push, a.push + 0.1, color="gold", alpha=0.4, label="push (0.1 s)")
        fell = max(d["tilt"]) > 0.6
        ax.set_title(
            ("with the DCM stabilizer" if name == "on" else "open loop (stabilizer=false)")
            + (": fell" if fell else ": recovered")
            + ("; " + a.title if a.title else "")
        )
        ax.set_ylabel(k + " (m, world)")
        ax.set_ylim(-0.45, 0.45) if k == "y" else None
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, ncol=3, loc="lower left")
    axes[-1, 0].set_xlabel("time (s)")
    fig.tight_layout()
    fig.savefig(a.out, dpi=110)


if __name__ == "__main__":
    main()
