#!/usr/bin/env python3
"""Replay a recorded session's joint traces into numpy (no pandas).

    PYTHONPATH=build/python python3 examples/python/log_to_numpy.py SESSION.lcmlog [--robot NAME] [-o traces.npz]

SESSION.lcmlog is an LCM log of a RoboTalk session (`robotalk-logplay record`,
docs/logplay.md) with the state stream in it. Prints what the log holds (as
`robotalk-logplay info` does, from plain Python data), each joint's range, and
saves the traces as a .npz: time (s since the first sample), positions (n x
dofs), base (n x 5) and the joint names.
"""

from __future__ import annotations

import argparse
import sys
from collections import Counter

import numpy as np

import robotalk


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("log")
    parser.add_argument("--robot", default=None, help="which robot's state (needed when several)")
    parser.add_argument("-o", "--output", default="traces.npz")
    args = parser.parse_args()

    info = robotalk.log_info(args.log)
    span = info["last_time"] - info["first_time"]
    print(f"{args.log}: {info['events']} events over {span:.1f} s; robots "
          + ", ".join(r["name"] for r in info["robots"]))
    for client in info["clients"]:
        commands = [c for c in info["commands"] if c["client"] == client["id"] and not c["panic"]]
        types = Counter(c["command"].type for c in commands)
        signals = Counter(c["reply"].signal for c in commands if c["reply"] is not None)
        print(f"  client {client['id'] & 0xFFFFFFFFFFFFFFFF:016x} ({client['robot']}): {len(commands)} commands "
              f"{dict(types)}, replies {dict(signals)}, modes {client['modes']}")

    states = robotalk.log_states(args.log, args.robot)
    time = states["server_time"] - states["server_time"][0]
    positions = states["positions"]
    print(f"state of '{states['robot']}': {len(time)} samples over {time[-1]:.2f} s")
    for k, name in enumerate(states["joint_names"]):
        unit = states["units"][k] or "?"
        print(f"  {name}: {positions[:, k].min():+.4f} .. {positions[:, k].max():+.4f} {unit}")
    np.savez(args.output, time=time, positions=positions, base=states["base"],
             joint_names=np.array(states["joint_names"]))
    print(f"wrote {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
