#!/usr/bin/env python3
"""Stream a sine to the iiwa14 in delay mode and plot its tracking.

    PYTHONPATH=build/python python3 examples/python/iiwa_sine.py [--url URL] [--robot iiwa] [-o tracking.png]

Needs a server serving the iiwa14 (../shared/robots/iiwa14.urdf), e.g.
    robotalk-server --robot iiwa=kinematic:../shared/robots/iiwa14.urdf
Joint 4 follows q(t) = 0.5 sin(2 pi 0.5 t) at 100 Hz for 4 s (--seconds): each set-point
is stamped `delay` ahead on the synchronised server clock; the state stream
records what the robot did, and matplotlib plots command and response to a
PNG (python3-matplotlib).
"""

from __future__ import annotations

import argparse
import math
import sys
import threading
from typing import List, Tuple

import matplotlib

matplotlib.use("Agg")  # a file, no display
import matplotlib.pyplot as plt  # noqa: E402

import robotalk  # noqa: E402

JOINT = "iiwa_joint_4"
RATE_HZ = 100.0
AMPLITUDE = 0.5
FREQUENCY_HZ = 0.5


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--url", default=None)
    parser.add_argument("--robot", default="iiwa")
    parser.add_argument("--delay", type=float, default=0.2, help="delay mode's head start, s")
    parser.add_argument("--seconds", type=float, default=4.0, help="how long the sine runs")
    parser.add_argument("-o", "--output", default="iiwa_tracking.png")
    args = parser.parse_args()

    with robotalk.connect(args.robot, args.url) as robot:
        joint = robot.model.dof_offset(JOINT)
        robot.set_joint(JOINT, [0.0])
        samples: List[Tuple[float, float]] = []
        lock = threading.Lock()

        def record(sample: robotalk.StateSample) -> None:  # on the stream's own thread
            with lock:
                samples.append((sample.server_time, float(sample.positions[joint])))

        n = int(args.seconds * RATE_HZ)
        frames = [
            robotalk.TimedCommand(i / RATE_HZ, robotalk.Command(
                "JOINT_SETPOINT", JOINT, [AMPLITUDE * math.sin(2 * math.pi * FREQUENCY_HZ * i / RATE_HZ)]))
            for i in range(n)
        ]
        with robot.state_stream(0.01, record) as stream:
            result = robot.run_sequence(frames, "delay", delay=args.delay)
        failed = [r for r in result.replies if not r.succeeded]
        start = result.server_start if result.server_start is not None else 0.0
        print(f"{n} set-points in delay mode ({args.delay} s ahead): {n - len(failed)} succeeded; "
              f"state samples {stream.received}, dropped {stream.dropped}")
        late = sorted(r.lateness for r in result.replies)
        print(f"lateness: median {late[len(late) // 2] * 1e3:.3f} ms, max {late[-1] * 1e3:.3f} ms")

    with lock:
        t = [s - start for s, _ in samples]
        q = [v for _, v in samples]
    ct = [f.offset for f in frames]
    cq = [float(f.command.values[0]) for f in frames]
    fig, ax = plt.subplots(figsize=(8, 4))
    ax.plot(ct, cq, label="command (set-points)")
    ax.plot(t, q, label="state stream", linestyle="--")
    ax.set_xlim(-0.2, args.seconds + 0.5)
    ax.set_xlabel("s since the sequence start (server clock)")
    ax.set_ylabel(f"{JOINT} (rad)")
    ax.set_title(f"{args.robot}: a {FREQUENCY_HZ} Hz sine at {RATE_HZ:g} Hz, delay mode")
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.output)
    print(f"wrote {args.output}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
