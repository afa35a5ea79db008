#!/usr/bin/env python3
"""The watchdog matrix (issue 19): every motion command type x both drivers x
three ways a client vanishes. The motion of the vanished session stops within
the session timeout (plus the watchdog's poll and a sample period), and only
that session's motion: a second client's motion on another actuator of the
same robot runs on. For the broadcast case the vanished client's fast stream
stops and the observer's own stream runs on.

    watchdog_matrix_test.py SERVER CLI RELAY MODELS_DIR

Run it inside a private network namespace (CTest wraps it with
scripts/netns_run.sh). One robotalk-server serves 18 robots (9 cases x
{kinematic, ode}), so the cases of one vanish mode run at once; the modes run
one after the other:
  kill       kill -9 of the client process
  stop       SIGSTOP of the client process (frozen, socket open)
  partition  the client talks through robotalk-lcm-relay, which is killed
The clients are robotalk CLI processes (send ... --hold, send --file in
direct / delay / playback mode, watch). Every robot has an observer (robotalk
watch --json on the server's side) whose samples carry the server's clock,
CLOCK_MONOTONIC as time.monotonic() here: the test measures from them.
Bounded: about 30 s; every process is killed at the end.
"""
import json
import math
import os
import signal
import subprocess
import sys
import tempfile
import time

server_bin, cli_bin, relay_bin, models = sys.argv[1:5]
TIMEOUT = 1.5  # --session-timeout: short, yet a live client under load (heartbeats every 0.25 s) keeps its session
SLACK = 0.6  # the watchdog's poll, a sample period, a driver period, a loaded machine, ode braking
# A motion that ended sooner than this after the vanish ended by itself (the
# last heartbeat is about 0.25 s old): the case would test nothing.
EARLIEST = TIMEOUT / 2
URL_B = "udpm://239.255.76.67:7813?ttl=0"  # the server's side
URL_A = "udpm://239.255.76.67:7913?ttl=0"  # the clients' side of the relay (66 ports apart)
PIONEER = os.path.join(models, "pioneer2dx_pantilt.urdf")
HUMANOID = os.path.join(models, "simple_humanoid.urdf")
PIONEER_WHEEL, PIONEER_PAN, PIONEER_TILT = 0, 2, 3  # dofs: left wheel, right wheel, pan, tilt
HUMANOID_PAN = 0  # the neck's yaw (the waist is fixed)
tmp = tempfile.mkdtemp(prefix="robotalk-watchdog-")
procs = []


def seq_file(name, lines):
    path = os.path.join(tmp, name)
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    return path


# Set-points that swing the pan from side to side for 60 s, a new one every
# 0.2 s, the target flipping every second: the pan never reaches a target, so
# it moves until something stops it. Sent whole in delay mode (queued on the
# server ahead of time) or in playback mode: after the client vanishes the
# queued set-points run on until the watchdog drops them and stops the pan.
swing = seq_file("swing.txt", ["%.1f joint_setpoint pan %g" % (i / 5, 2.7 if (i // 5) % 2 == 0 else -2.7)
                               for i in range(300)])
c, s = math.cos(math.pi / 4), math.sin(math.pi / 4)
look = seq_file("look.txt", ["%.1f frame_setpoint camera 0.05 %g 0.39 %g 0 0 %g" %
                             (i / 5, 0.05 if (i // 5) % 2 == 0 else -0.05, c, s if (i // 5) % 2 == 0 else -s)
                             for i in range(300)])
drive = seq_file("drive.txt", ["%.1f setspeed 0.3 0.2" % (i / 10) for i in range(600)])

# name: (model, the vanishing client's arguments, what it moves, the second
# client's arguments, what that one moves). `{sign}` flips every round so that
# no joint reaches its limit over three rounds.
BASE, PAN, CAMERA, NECK, WHEEL, STREAM = "base", "pan", "camera", "neck", "wheel", "stream"
CASES = {
    "goto": (PIONEER, ["send", "{r}", "goto", "{goal}", "0", "0"], BASE,
             ["send", "{r}", "joint_speed", "pan", "{sign}0.2", "--hold"], PAN),
    "setspeed": (PIONEER, ["send", "{r}", "setspeed", "0.3", "0.2", "--hold"], BASE,
                 ["send", "{r}", "joint_speed", "pan", "{sign}0.2", "--hold"], PAN),
    "joint_speed": (PIONEER, ["send", "{r}", "joint_speed", "pan", "{sign}0.5", "--hold"], PAN,
                    ["send", "{r}", "setspeed", "0", "0.3", "--hold"], BASE),
    "joint_setpoint": (PIONEER, ["send", "{r}", "--file", swing, "--mode", "delay", "--delay", "0.5"], PAN,
                       ["send", "{r}", "setspeed", "0", "0.3", "--hold"], BASE),
    # The camera's targets are world poses: the second client turns a wheel,
    # which leaves the kinematic base in place (the ode base pivots slowly).
    "frame_setpoint": (PIONEER, ["send", "{r}", "--file", look, "--mode", "delay", "--delay", "0.5"], CAMERA,
                       ["send", "{r}", "joint_speed", "left_wheel_joint", "{sign}1", "--hold"], WHEEL),
    "joint_force": (HUMANOID, ["send", "{r}", "joint_force", "pan", "{sign}0.0025", "--hold"], NECK,
                    ["send", "{r}", "setspeed", "0.1", "0", "--hold"], BASE),
    "delay": (PIONEER, ["send", "{r}", "--file", drive, "--mode", "delay", "--delay", "0.3", "--paced"], BASE,
              ["send", "{r}", "joint_speed", "pan", "{sign}0.2", "--hold"], PAN),
    "playback": (PIONEER, ["send", "{r}", "--file", swing, "--mode", "playback"], PAN,
                 ["send", "{r}", "setspeed", "0", "0.3", "--hold"], BASE),
    "broadcast": (PIONEER, ["watch", "{r}", "--period", "0.05", "--duration", "60"], STREAM, None, None),
}
DRIVERS = ["kinematic", "ode"]
MODES = ["kill", "stop", "partition"]


def spawn(args, out, err=subprocess.DEVNULL):
    p = subprocess.Popen(args, stdout=out, stderr=err, stdin=subprocess.DEVNULL)
    procs.append(p)
    return p


def rt(url, args, out=subprocess.DEVNULL, err=subprocess.DEVNULL):
    return spawn([cli_bin, "--url", url, "--timeout", "5"] + args, out, err)


def speed(sample, what, driver):
    """How fast `what` moves in one STATE sample (m/s or rad/s)."""
    v = sample["velocity"]
    if what == BASE:
        return math.hypot(sample["base"][3], sample["base"][4])
    if what == PAN:
        return abs(v[PIONEER_PAN])
    if what == CAMERA:
        return max(abs(v[PIONEER_PAN]), abs(v[PIONEER_TILT]))
    if what == WHEEL:
        return abs(v[PIONEER_WHEEL])
    if what == NECK:
        return abs(v[HUMANOID_PAN])
    raise ValueError(what)


def eps(driver):
    return 1e-6 if driver == "kinematic" else 0.03


def samples(robot, t0, t1):
    out = []
    with open(os.path.join(tmp, "observe-%s.jsonl" % robot), errors="replace") as f:
        for line in f:
            try:
                e = json.loads(line)
            except ValueError:
                continue
            t = e["server_time_us"] / 1e6
            if t0 <= t <= t1:
                out.append((t, e))
    return out


def main():
    robots = ["%s_%s" % (d[0], name) for d in DRIVERS for name in CASES]
    args = [server_bin, "--url", URL_B, "--session-timeout", str(TIMEOUT), "--duration", "120"]
    for d in DRIVERS:
        for name, case in CASES.items():
            args += ["--robot", "%s_%s=%s:%s" % (d[0], name, d, case[0])]
    log = open(os.path.join(tmp, "server.log"), "w")
    spawn(args, subprocess.DEVNULL, log)
    deadline = time.monotonic() + 20
    while "serving robot 'o_broadcast'" not in open(os.path.join(tmp, "server.log")).read():
        if time.monotonic() > deadline:
            print("FAIL: the server did not start:\n" + open(os.path.join(tmp, "server.log")).read())
            return 1
        time.sleep(0.1)
    for r in robots:  # the observers: the server's own side, never vanish
        period = "0.5" if r.endswith("broadcast") else "0.05"
        rt(URL_B, ["watch", r, "--period", period, "--json", "--duration", "110"],
           open(os.path.join(tmp, "observe-%s.jsonl" % r), "w"))
    time.sleep(1.0)

    failures, figures, detail = [], {}, []
    for round_no, mode in enumerate(MODES):
        sign = "" if round_no % 2 == 0 else "-"
        relay = None
        url = URL_B
        if mode == "partition":
            relay = spawn([relay_bin, "--a", URL_A, "--b", URL_B, "--duration", "60"], subprocess.DEVNULL)
            url = URL_A
            time.sleep(0.5)
        vanishers, seconds = {}, []
        for d in DRIVERS:
            for name, (_, vargs, _, sargs, _) in CASES.items():
                r = "%s_%s" % (d[0], name)
                fill = lambda a: [x.format(r=r, sign=sign, goal=6 if round_no % 2 == 0 else -6) for x in a]
                out = open(os.path.join(tmp, "vanisher-%s-%s.out" % (mode, r)), "w")
                vanishers[r] = rt(url, fill(vargs), out, subprocess.STDOUT)
                if sargs:
                    seconds.append(rt(URL_B, fill(sargs)))
        time.sleep(3.0)  # every motion under way (playback waits for its delay estimate)
        t_vanish = time.monotonic()
        for p in vanishers.values():
            if mode == "kill":
                p.send_signal(signal.SIGKILL)
            elif mode == "stop":
                p.send_signal(signal.SIGSTOP)
        if relay:
            relay.send_signal(signal.SIGKILL)
        time.sleep(TIMEOUT + 2.5)
        t_end = time.monotonic()

        for d in DRIVERS:
            for name, (_, _, what, _, second) in CASES.items():
                r = "%s_%s" % (d[0], name)
                case = "%s / %s / %s" % (name, d, mode)
                got = samples(r, t_vanish - 1.0, t_end)
                if not got:
                    failures.append("%s: the observer got no sample" % case)
                    continue
                before = [e for t, e in got if t_vanish - 0.5 <= t <= t_vanish]
                after = [(t, e) for t, e in got if t > t_vanish]
                if what == STREAM:
                    fast = sum(1 for t, _ in got if t_vanish - 0.5 <= t <= t_vanish)
                    late = [t for t, _ in got if t > t_vanish + TIMEOUT + SLACK]
                    gaps = [b - a for a, b in zip(late, late[1:])]
                    if fast < 6:
                        failures.append("%s: the vanishing client's 0.05 s stream was not running "
                                        "(%d samples in the last 0.5 s)" % (case, fast))
                    if not late:
                        failures.append("%s: the observer's own stream stopped too" % case)
                    elif gaps and min(gaps) < 0.3:
                        failures.append("%s: the vanished client's stream still runs (a gap of %.3f s)"
                                        % (case, min(gaps)))
                    fast_after = [t for t, _ in got if t > t_vanish]
                    stopped = max([b for a, b in zip(fast_after, fast_after[1:]) if b - a < 0.3],
                                  default=t_vanish)
                    figures.setdefault((d, mode), []).append(stopped - t_vanish)
                    detail.append("  %-40s fast stream ended %.2f s after the client vanished" %
                                  (case, stopped - t_vanish))
                    continue
                if name == "joint_force" and d == "kinematic":
                    # The kinematic driver refuses JOINT_FORCE (NA): nothing ran, nothing is owned.
                    out = open(os.path.join(tmp, "vanisher-%s-%s.out" % (mode, r))).read()
                    if "NA" not in out:
                        failures.append("%s: expected NA, got %r" % (case, out[-200:]))
                    if any(speed(e, what, d) > eps(d) for _, e in got):
                        failures.append("%s: the neck moved although JOINT_FORCE was refused" % case)
                else:
                    if not before or max(speed(e, what, d) for e in before) <= eps(d):
                        failures.append("%s: %s was not moving before the client vanished" % (case, what))
                        continue
                    moving = [t for t, e in after if speed(e, what, d) > eps(d)]
                    latency = (max(moving) if moving else t_vanish) - t_vanish
                    figures.setdefault((d, mode), []).append(latency)
                    detail.append("  %-40s stopped %.2f s after the client vanished" % (case, latency))
                    if latency < EARLIEST:
                        failures.append("%s: %s stopped %.2f s after the client vanished, before its "
                                        "session could expire: the case tests nothing" % (case, what, latency))
                    if latency > TIMEOUT + SLACK:
                        failures.append("%s: %s still moved %.2f s after the client vanished "
                                        "(the session timeout is %.1f s)" % (case, what, latency, TIMEOUT))
                tail = [e for t, e in got if t_end - 0.5 <= t]
                if second and (not tail or max(speed(e, second, d) for e in tail) <= eps(d)):
                    failures.append("%s: the second client's %s stopped too" % (case, second))

        for p in vanishers.values():
            p.send_signal(signal.SIGKILL)
            p.wait()
        for p in seconds:  # SIGTERM: the CLI sends STOP
            p.send_signal(signal.SIGTERM)
        for p in seconds:
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()
        time.sleep(TIMEOUT + 0.5)  # their sessions expire before the next round

    server_log = open(os.path.join(tmp, "server.log")).read()
    for d in DRIVERS:
        for mode in MODES:
            lat = figures.get((d, mode), [])
            if lat:
                print("%-9s %-9s: %d cases, the motion stopped %.2f .. %.2f s after the client vanished "
                      "(session timeout %.1f s)" % (d, mode, len(lat), min(lat), max(lat), TIMEOUT))
    if os.environ.get("VERBOSE") == "1" or failures:
        print("\n".join(detail))
    if "vanished; stopping what it moved" not in server_log:
        failures.append("the server never logged a watchdog stop")
    cases = len(CASES) * len(DRIVERS) * len(MODES)
    for f in failures:
        print("FAIL: " + f)
    print("%d passed, %d failed" % (cases - len(set(f.split(":")[0] for f in failures)), len(failures)))
    return 1 if failures else 0


if __name__ == "__main__":
    try:
        rc = main()
    finally:
        for p in procs:
            if p.poll() is None:
                p.send_signal(signal.SIGCONT)
                p.kill()
        for p in procs:
            p.wait()
        if os.environ.get("KEEP") != "1":
            subprocess.call(["rm", "-rf", tmp])
        else:
            print("files kept in " + tmp)
    sys.exit(rc)
