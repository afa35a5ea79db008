#!/usr/bin/env python3
"""tools/logplay/plot_log.py: what the export's PNG shows (issue 21).

The joints are named as in state.csv's header, each on an axis of its own
(a Pioneer's 45 rad wheels apart from its +-0.5 rad pan and tilt); past
MAX_AXES joints they are grouped by robot, unit and range; a robot named
from no configuration says so. Checked on the figure itself (matplotlib's
axes, titles, lines) and on --summary's output.
  plot_log_test.py PATH/TO/plot_log.py
"""
import contextlib
import importlib.util
import io
import math
import os
import sys
import tempfile

spec = importlib.util.spec_from_file_location("plot_log", sys.argv[1])
plot_log = importlib.util.module_from_spec(spec)
spec.loader.exec_module(plot_log)
failures = 0


def check(ok, what, detail=""):
    global failures
    print(f"{'ok  ' if ok else 'FAIL'} {what}{': ' + str(detail) if detail else ''}")
    failures += 0 if ok else 1


def write(path, text):
    with open(path, "w") as f:
        f.write(text)


BASE = "robot,log_time_us,server_time_us,panic,moving,x,y,theta,v,omega"
tmp = tempfile.mkdtemp(prefix="plot_log_test.")
commands = os.path.join(tmp, "commands.csv")
write(commands, "client,robot,sequence,mode,id,type,target,start_us,send_time_us,log_time_us,signal,"
      "exec_time_us,values\n00000000000000ab,pioneer,1,delay,1,GOTO,,0,0,0,SUCCESS,0,1 0.4 0.8\n")

# A Pioneer: two wheels turning 45 rad, pan and tilt within +-0.5 rad.
state = os.path.join(tmp, "state.csv")
joints = os.path.join(tmp, "joints.csv")
rows = [BASE + ",left_wheel_joint,right_wheel_joint,pan,tilt"]
for i in range(50):
    t = i * 0.1
    rows.append(f"pioneer,{i},{int(t * 1e6)},0,1,{t * 0.1},0,0,0,0,{t * 9},{t * 9.2},{0.1 * math.sin(t)},-0.3")
write(state, "\n".join(rows) + "\n")
write(joints, "robot,dof,column,unit,named_from\n" + "".join(
    f"pioneer,{i},{n},rad,config\n" for i, n in enumerate(["left_wheel_joint", "right_wheel_joint", "pan", "tilt"])))
fig, groups = plot_log.build_figure(commands, state, joints)
check(len(groups) == 4 and all(len(names) == 1 for _, names, _ in groups), "one axis per joint",
      [names for _, names, _ in groups])
titles = [ax.get_title(loc="left") for ax in fig.axes]
for name in ["left_wheel_joint", "right_wheel_joint", "pan", "tilt"]:
    check(any(t == f"pioneer: {name}" for t in titles), f"an axis is titled by the joint's name {name}", titles)
check(len(fig.axes) == 5, "the figure has the path axis and 4 joint axes", len(fig.axes))
pan_ax = next(ax for ax in fig.axes if ax.get_title(loc="left") == "pioneer: pan")
low, high = pan_ax.get_ylim()
check(high - low < 1.0, "pan's axis spans its own range, not the wheels' 45 rad", (low, high))
check(pan_ax.get_ylabel() == "rad", "the unit from joints.csv labels the axis", pan_ax.get_ylabel())
check(not any("q0" in t for t in titles), "no joint is called q0", titles)
out = io.StringIO()
with contextlib.redirect_stdout(out):
    plot_log.main(["--summary", commands, state, os.path.join(tmp, "a.png"), joints])
check("joint axis 2: pioneer: pan (rad)" in out.getvalue(), "--summary lists the axes", out.getvalue())
check(os.path.getsize(os.path.join(tmp, "a.png")) > 1000, "the PNG is written")

# An arm with 20 joints: past MAX_AXES they are grouped by unit and range.
names = [f"j{i}" for i in range(18)] + ["slide", "wheel"]
rows = [BASE + "," + ",".join(names)]
for i in range(20):
    vals = [0.4 * math.sin(i * 0.1 + k) for k in range(18)] + [0.02 * i, 3.0 * i]
    rows.append(f"arm,{i},{i * 100000},0,0,0,0,0,0,0," + ",".join(str(v) for v in vals))
write(state, "\n".join(rows) + "\n")
write(joints, "robot,dof,column,unit,named_from\n" + "".join(
    f"arm,{i},{n},{'m' if n == 'slide' else 'rad'},config\n" for i, n in enumerate(names)))
fig, groups = plot_log.build_figure(commands, state, joints)
check(len(groups) <= plot_log.MAX_AXES, "20 joints fit in at most MAX_AXES axes", len(groups))
by_joint = {n: (unit, tuple(group)) for _, group, unit in groups for n in group}
check(by_joint["slide"][0] == "m" and by_joint["slide"][1] == ("slide",), "a prismatic joint is not mixed with rad",
      by_joint["slide"])
check("wheel" not in by_joint["j0"][1], "a 57 rad wheel is not on the axis of +-0.4 rad joints", by_joint["j0"])
check(sorted(n for _, g, _ in groups for n in g) == sorted(names), "every joint is plotted once")

# No configuration in the log: q0.. and a note on each axis; an export from
# before issue 21 (one space-separated q column) still plots.
write(state, BASE + ",q0,q1\npioneer,1,1000000,0,0,0,0,0,0,0,0.5,1.5\npioneer,2,2000000,0,0,0,0,0,0,0,0.6,1.6\n")
write(joints, "robot,dof,column,unit,named_from\npioneer,0,q0,,none\npioneer,1,q1,,none\n")
fig, groups = plot_log.build_figure(commands, state, joints)
titles = [ax.get_title(loc="left") for ax in fig.axes]
check(any("q0" in t and "no configuration in the log" in t for t in titles),
      "unnamed joints say the log had no configuration", titles)
write(state, BASE + ",q\npioneer,1,1000000,0,0,0,0,0,0,0,0.5 1.5\n")
fig, groups = plot_log.build_figure(commands, state)
check([g[1] for g in groups] == [["q0"], ["q1"]], "an old export's q column still plots", groups)

print("PASS" if failures == 0 else f"{failures} FAILED")
sys.exit(1 if failures else 0)
