#!/usr/bin/env python3
"""Drive the Pioneer: GOTO, the pan-tilt head, a timed sequence, the state.

    PYTHONPATH=build/python python3 examples/python/drive_pioneer.py [--url URL] [--robot pioneer]

against the demo's server (scripts/demo.sh) or any robotalk-server serving
the kinematic Pioneer (models/pioneer2dx_pantilt.urdf). Ctrl-C during the
GOTO sends STOP before the program exits.
"""

from __future__ import annotations

import argparse
import sys

import robotalk


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--url", default=None, help="LCM URL (default: $LCM_DEFAULT_URL or LCM's)")
    parser.add_argument("--robot", default="pioneer")
    args = parser.parse_args()

    with robotalk.connect(args.robot, args.url) as robot:
        print(f"connected: {robot!r}; joints {robot.model.dof_names}")
        reply = robot.goto(1.0, 0.0, 0.0)
        print(f"GOTO 1 0 0: {reply.signal} {reply.message}")
        print(f"head: {robot.set_joint('pan', [0.3]).signal} {robot.set_joint('tilt', [-0.2]).signal}")

        # A timed sequence in delay mode: the head nods every 0.25 s, on the
        # server's clock 0.5 s ahead (the frames keep their spacing however
        # the network behaves, within that budget).
        frames = [robotalk.TimedCommand(0.25 * i, robotalk.Command("JOINT_SETPOINT", "tilt", [(-0.2, 0.2)[i % 2]]))
                  for i in range(6)]
        result = robot.run_sequence(frames, "delay", delay=0.5)
        print(f"sequence: {result!r}; " + " ".join(r.signal for r in result.replies))

        x, y, theta, v, omega = robot.base_pose()
        print(f"pose: x={x:.3f} y={y:.3f} theta={theta:.3f}")
        state = robot.joint_state()
        print("joints: " + " ".join(f"{n}={q:.3f}" for n, q in zip(robot.model.dof_names, state.positions)))
        robot.goto(0.0, 0.0, 0.0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
