#!/usr/bin/env python3
"""Runs RoboTalk's multi-process benchmark suite and writes bench/results/latest/*.json.

Run it inside a private network namespace (scripts/bench.sh does:
scripts/netns_run.sh python3 bench/run_bench.py ...). Every RoboTalk figure is
measured beside its floor (raw LCM, a bare timer loop) in the same run,
interleaved A B A B, N runs; the JSON keeps every run, the generator
(bench/gen_performance.py) takes medians.

    python3 bench/run_bench.py --build build [--quick] [--only NAME,...] [--out DIR]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
URL = "udpm://239.255.76.67:7990?ttl=0"
# Each URL's split traffic layout uses 66 ports from its own (docs/protocol.md): no overlaps.
URL_A = "udpm://239.255.76.67:8100?ttl=0"  # playback: client side of the relay
URL_B = "udpm://239.255.76.67:8200?ttl=0"  # playback: server side
ROBOT = "pioneer"


class Bench:
    def __init__(self, args):
        self.args = args
        self.quick = args.quick
        self.runs = 3 if args.quick else 5
        b = os.path.abspath(args.build)
        self.server_bin = f"{b}/robotalk-server/robotalk-server"
        self.cli_bin = f"{b}/robotalk-client/robotalk"
        self.raw = f"{b}/bench/robotalk-bench-raw"
        self.timer = f"{b}/bench/robotalk-bench-timer"
        self.client = f"{b}/bench/robotalk-bench-client"
        self.relay = f"{b}/tools/lcm_relay/robotalk-lcm-relay"
        self.link = f"{b}/bench/robotalk-bench-link"
        self.model = f"{ROOT}/models/pioneer2dx_pantilt.urdf"
        self.tmp = tempfile.mkdtemp(prefix="robotalk-bench-")
        self.server = None
        self.children = []

    # --- processes -----------------------------------------------------------
    def start(self, cmd, stdout=subprocess.PIPE):
        p = subprocess.Popen(cmd, stdout=stdout, stderr=subprocess.PIPE, text=True)
        self.children.append(p)
        return p

    def playback_decision(self):
        """The last --log-playback line of the server's log (a JSON object), or None (an older build)."""
        try:
            lines = [x for x in open(f"{self.tmp}/server.log") if " start {" in x and "PLAYBACK" in x]
            return json.loads(lines[-1][lines[-1].index(" start {") + 7:]) if lines else None
        except (OSError, ValueError):
            return None

    def late_starts(self):
        """The server log's "late start:" lines (the RobotDaemon's own account of each command it began more
        than 1 ms after its start time, and of each timed item handed over after its start; --log-playback)."""
        try:
            return [x.strip() for x in open(f"{self.tmp}/server.log") if "late start:" in x][:50]
        except OSError:
            return []

    @staticmethod
    def parse(out, what):
        for line in reversed((out or "").strip().splitlines()):
            if line.startswith("{"):
                return json.loads(line)
        raise RuntimeError(f"{what}: no JSON result in output: {out[-500:] if out else ''}")

    def collect(self, p, timeout, what):
        try:
            out, err = p.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            p.kill()
            out, err = p.communicate()
            return {"error": f"{what}: killed after {timeout} s", "stderr": err[-400:]}
        try:
            return self.parse(out, what)
        except RuntimeError as e:
            return {"error": str(e), "stderr": (err or "")[-400:], "rc": p.returncode}

    def run(self, cmd, timeout=120):
        return self.collect(self.start(cmd), timeout, os.path.basename(cmd[0]) + " " + cmd[1])

    def stop(self, p, grace=3):
        if p.poll() is None:
            p.terminate()
            try:
                p.wait(grace)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()

    def start_server(self, url=URL, extra=(), env=None, robot=None):
        """env: extra environment, e.g. ROBOTALK_PRECISE_TIMING=0 (the RobotDaemon's timing option off);
        robot: the --robot value (default: the kinematic pioneer)."""
        self.stop_server()
        log = open(f"{self.tmp}/server.log", "w+")
        self.server = subprocess.Popen(
            [self.server_bin, "--robot", robot or f"{ROBOT}=kinematic:{self.model}", "--url", url,
             "--duration", "3600", *extra], stdout=subprocess.DEVNULL, stderr=log, text=True,
            env={**os.environ, **(env or {})})
        for _ in range(100):
            log.seek(0)
            if "serving robot" in log.read():
                return self.server
            time.sleep(0.05)
        raise RuntimeError("robotalk-server did not start: " + open(log.name).read()[-500:])

    def stop_server(self):
        if self.server:
            self.stop(self.server)
            self.server = None

    def start_echo(self, url=URL):
        return self.start([self.raw, "echo", "--url", url, "--duration", "3600"])

    def cpu_ticks(self, pid):
        with open(f"/proc/{pid}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
        return int(fields[11]) + int(fields[12])  # utime + stime

    @staticmethod
    def machine_cpu():
        """/proc/stat's aggregate line: (user+nice, system, irq+softirq, idle+iowait, total) jiffies."""
        with open("/proc/stat") as f:
            v = [int(x) for x in f.readline().split()[1:8]]
        return (v[0] + v[1], v[2], v[5] + v[6], v[3] + v[4], sum(v))

    def rss_kb(self, pid):
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
        return 0

    def cleanup(self):
        self.stop_server()
        for p in self.children:
            if p.poll() is None:
                self.stop(p, 1)

    # --- figures -------------------------------------------------------------
    def query(self):
        n = 300 if self.quick else 2000
        self.start_server()
        echo = self.start_echo()
        runs = []
        for _ in range(self.runs):
            a = self.run([self.client, "query", "--url", URL, "--count", str(n)])
            b = self.run([self.raw, "ping", "--url", URL, "--count", str(n)])
            runs.append({"robotalk": a, "raw": b})
        self.stop(echo)
        return {"figure": "query", "count": n, "runs": runs}

    def timed_once(self, n):
        # The server with its timing option (RobotDaemonOptions::precise_timing,
        # the default) and without it, each with its CPU over the run.
        r = {}
        for key, env in (("robotalk", None), ("robotalk_plain", {"ROBOTALK_PRECISE_TIMING": "0"})):
            srv = self.start_server(env=env)
            c0, t0 = self.cpu_ticks(srv.pid), time.monotonic()
            r[key] = self.run([self.client, "timed", "--url", URL, "--count", str(n)])
            r[key]["server_cpu_pct"] = (100.0 * (self.cpu_ticks(srv.pid) - c0) / os.sysconf("SC_CLK_TCK")
                                        / (time.monotonic() - t0))
            log = open(f"{self.tmp}/server.log").read()
            r[key]["server_timing"] = next((l.split("timing: ", 1)[1] for l in log.splitlines()
                                            if "RobotDaemon timing: " in l), "")
        r["bare_default"] = self.run([self.timer, "sleeploop", "--count", str(n)])
        r["bare_1ns"] = self.run([self.timer, "sleeploop", "--count", str(n), "--slack-ns", "1"])
        return r

    def timed(self):
        n = 1000 if self.quick else 2000
        idle, loaded = [], []
        for _ in range(self.runs):
            idle.append(self.timed_once(n))
            burn = self.start([self.timer, "burn", "--seconds", "60"])
            time.sleep(0.2)
            loaded.append(self.timed_once(n))
            self.stop(burn)
        return {"figure": "timed", "count": n, "runs": idle, "loaded_runs": loaded}

    def panic(self):
        n = 30 if self.quick else 100
        self.start_server()
        echo = self.start_echo()
        streamers = [self.start([self.client, "stream", "--url", URL, "--seconds", "600", "--rate", "100"])
                     for _ in range(8)]
        time.sleep(2.0)
        runs = []
        for _ in range(self.runs):
            a = self.run([self.client, "panic", "--url", URL, "--count", str(n), "--gap-ms", "20",
                          "--state-period-us", "1000"])
            b = self.run([self.raw, "ping", "--url", URL, "--count", str(n), "--gap-us", "20000",
                          "--req", "64", "--rep", "64", "--warmup", "5"])
            runs.append({"robotalk": a, "raw": b})
        for s in streamers:
            self.stop(s, 1)
        self.stop(echo)
        return {"figure": "panic", "count": n, "streamers": 8, "runs": runs}

    def throughput(self):
        n = 5000 if self.quick else 20000
        sizes = self.run([self.raw, "sizes"])
        req, rep = str(int(sizes["base_pose_request"])), str(int(sizes["base_pose_reply"]))
        self.start_server()
        echo = self.start_echo()
        runs = []
        for _ in range(self.runs):
            a = self.run([self.client, "pipe", "--url", URL, "--inflight", "100", "--count", str(n), "--cap", "60"])
            b = self.run([self.raw, "pipe", "--url", URL, "--inflight", "100", "--count", str(n),
                          "--req", req, "--rep", rep, "--cap", "60"])
            runs.append({"robotalk": a, "raw": b})
        big = []
        cap = 20 if self.quick else 30
        for _ in range(1 if self.quick else 3):
            self.start_server()  # a collapsed run must not leave its backlog to the next
            a = self.run([self.client, "pipe", "--url", URL, "--inflight", "1000", "--count", str(n),
                          "--cap", str(cap)], timeout=cap + 30)
            b = self.run([self.raw, "pipe", "--url", URL, "--inflight", "1000", "--count", str(n),
                          "--req", req, "--rep", rep, "--cap", str(cap)], timeout=cap + 30)
            big.append({"robotalk": a, "raw": b})
        self.stop(echo)
        return {"figure": "throughput", "count": n, "cap_s": cap, "runs": runs, "inflight1000_runs": big}

    def scale(self):
        seconds = self.args.scale_seconds or (5 if self.quick else 30)
        # The traffic layout (docs/protocol.md, Channels): RoboTalk's default
        # split, or everything on one URL with --traffic single.
        url = URL + (f"&traffic={self.args.traffic}" if self.args.traffic else "")
        levels = []
        for n in self.args.scale_clients:
            srv = self.start_server(url=url)
            allowance = 2.0 + 0.1 * n
            start_at = time.monotonic_ns() + int(allowance * 1e9)
            procs = [self.start([self.client, "stream", "--url", url, "--seconds", str(seconds), "--rate", "100",
                                 "--delay-ms", "100", "--start-at", str(start_at)]) for _ in range(n)]
            time.sleep(max(0.0, (start_at - time.monotonic_ns()) / 1e9))
            t0, c0, m0 = time.monotonic(), self.cpu_ticks(srv.pid), self.machine_cpu()
            time.sleep(seconds)
            server_pct = 100.0 * (self.cpu_ticks(srv.pid) - c0) / os.sysconf("SC_CLK_TCK") / (time.monotonic() - t0)
            m = [b - a for a, b in zip(m0, self.machine_cpu())]
            machine = {k: 100.0 * m[i] / m[4] for i, k in enumerate(("user_pct", "sys_pct", "irq_softirq_pct", "idle_pct"))}
            clients = [self.collect(p, seconds + allowance + 20, "stream") for p in procs]
            levels.append({"clients": n, "seconds": seconds, "server_cpu_pct": server_pct, "machine": machine,
                           "per_client": clients})
        return {"figure": "scale", "traffic": self.args.traffic or "split", "levels": levels,
                "precise_timing": os.environ.get("ROBOTALK_PRECISE_TIMING", "") != "0"}

    @staticmethod
    def wall_ms(cmd, bound_s=30):
        """Wall time of one process, start to exit, in ms, and its exit status.
        A blocking waitpid: subprocess.run(timeout=...) polls with sleeps that
        double from 0.5 ms, which rounds every time up to 1.5, 3.5, 7.5, 15.5,
        31.5 ms. A timer kills a process that outlives bound_s."""
        t0 = time.perf_counter_ns()
        p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        killer = threading.Timer(bound_s, p.kill)
        killer.start()
        try:
            _, status = os.waitpid(p.pid, 0)
        finally:
            killer.cancel()
        ms = (time.perf_counter_ns() - t0) / 1e6
        p.returncode = os.waitstatus_to_exitcode(status)
        return ms, p.returncode

    def cli(self):
        k = 5 if self.quick else 10
        self.start_server()
        echo = self.start_echo()
        runs = []
        for _ in range(self.runs):
            a, b = [], []
            for _ in range(k):
                for cmd, dst in (([self.cli_bin, "--url", URL, "query", ROBOT, "base_pose"], a),
                                 ([self.raw, "once", "--url", URL], b)):
                    ms, rc = self.wall_ms(cmd)
                    dst.append(ms if rc == 0 else None)
            runs.append({"robotalk_ms": a, "raw_ms": b})
        self.stop(echo)
        return {"figure": "cli", "runs": runs}

    def memory(self):
        srv = self.start_server()
        time.sleep(1.0)
        base = self.rss_kb(srv.pid)
        levels = []
        # Sessions open with a hello (robotalk-bench-raw sessions); a robot
        # serves at most 256 (SessionOptions::max_sessions).
        for k in ((100,) if self.quick else (100, 250)):
            p = self.start([self.raw, "sessions", "--url", URL, "--robot", ROBOT, "--count", str(k), "--seconds", "4"])
            time.sleep(3.5)
            rss = self.rss_kb(srv.pid)
            r = self.collect(p, 30, "sessions")
            opened = int(r.get("opened", 0))
            levels.append({"sessions": k, "opened": opened, "rss_kb": rss, "base_rss_kb": base,
                           "per_session_kb": (rss - base) / opened if opened else None})
            time.sleep(3.0)  # the sessions expire (2 s watchdog)
        return {"figure": "memory", "levels": levels, "loads": self.memory_loads()}

    def memory_loads(self):
        """Issue 19 item 8: the server's RSS under each well-formed exhaustion
        load, each on a fresh server beside its own idle RSS (same run)."""
        q = self.quick
        cases = [  # (load, sessions, packages per session)
            ("unknown", 5, 64 if q else 256),  # 300 long-named unknown joints a package
            ("playbacks", 4, 1000 if q else 5000),  # finished 5-frame sequences
            ("queue", 250, 40),  # 250 STOPs due in 30 min a package: 10,000 a session
        ]
        out = []
        for load, k, n in cases:
            srv = self.start_server()
            time.sleep(1.0)
            idle = self.rss_kb(srv.pid)
            r = self.run([self.raw, "sessions", "--url", URL, "--robot", ROBOT, "--count", str(k),
                          "--seconds", "120", "--load", load, "--packages", str(n),
                          "--server-pid", str(srv.pid)], timeout=180)
            opened = int(r.get("opened", 0))
            rss = r.get("server_rss_kb", -1)
            out.append({"load": load, "sessions": k, "packages": n, "opened": opened, "idle_rss_kb": idle,
                        "rss_kb": rss, "hwm_kb": r.get("server_hwm_kb"), "load_s": r.get("load_s"),
                        "per_session_kb": (rss - idle) / opened if opened and rss > 0 else None,
                        "new_client_admitted": r.get("new_client_admitted"), "error": r.get("error")})
        self.stop_server()
        return out

    def jitter(self):
        n = 1000 if self.quick else 3000
        self.start_server()
        runs = []
        for _ in range(self.runs):
            a = self.run([self.client, "watch", "--url", URL, "--count", str(n), "--period-us", "1000"])
            w = self.start([self.raw, "watch", "--url", URL, "--count", str(n), "--period-us", "1000"])
            time.sleep(0.2)
            s = self.run([self.raw, "stream", "--url", URL, "--count", str(n + 50), "--period-us", "1000",
                          "--bytes", "700"])
            b = self.collect(w, 60, "watch")
            runs.append({"robotalk": a, "raw": b, "raw_stream": s})
        return {"figure": "jitter", "count": n, "runs": runs}

    def playback(self):
        frames = 20 if self.quick else 40
        levels = (0, 100) if self.quick else (0, 50, 100, 150)
        reps = 1 if self.quick else 2
        self.start_server(url=URL_B)
        runs = []
        seed = 1
        for x in levels:
            for _ in range(reps):
                relay = self.start([self.relay, "--a", URL_A, "--b", URL_B, "--a2b-congestion-max-ms", str(x),
                                    "--seed", str(seed), "--duration", "120"])
                seed += 1
                time.sleep(0.3)
                log = self.start([self.raw, "arrivals", "--url", URL_B, "--robot", ROBOT, "--frames", str(frames),
                                  "--timeout", "90"])
                a = self.run([self.client, "playback", "--url", URL_A, "--frames", str(frames),
                              "--period-ms", "100"], timeout=100)
                arr = self.collect(log, 10, "arrivals")
                self.stop(relay)
                runs.append({"congestion_max_ms": x, "robotalk": a, "arrivals": arr})
                # Let the server's playback state and the client's session go before the next run.
                time.sleep(2.5)
        return {"figure": "playback", "frames": frames, "period_ms": 100, "runs": runs}

    def playback_estimators(self):
        """Issue 23 item 3: the paper's estimator, the adaptive start before its start lead and the
        adaptive start now (the default), with its bounded stretch, in one run: for each relay profile
        (the congestion levels U[0, X] ms client -> server, and the WAN profiles) the variants
        interleaved on the same relay seed, each on a fresh server; start latency / the hindsight
        minimum (the arrival log on the server's side), late frames, and the stretch of the timing as
        played (the replies' execution times)."""
        frames = 20 if self.quick else 40
        profiles = [("U[0, 0] ms", ["--a2b-congestion-max-ms", "0"]),
                    ("U[0, 50] ms", ["--a2b-congestion-max-ms", "50"]),
                    ("U[0, 100] ms", ["--a2b-congestion-max-ms", "100"]),
                    ("U[0, 150] ms", ["--a2b-congestion-max-ms", "150"]),
                    ("WAN 100 ms +-50 ms, 1 % loss", ["--profile", "wan"]),
                    ("WAN 300 ms +-50 ms, 1 % loss", ["--profile", "wan-300"])]
        if self.quick:
            profiles = [profiles[0], profiles[2], profiles[4]]
        # ROBOTALK_BENCH_PROFILES="U[0, 100];WAN 100" runs only the profiles whose names start so.
        only_profiles = [p for p in os.environ.get("ROBOTALK_BENCH_PROFILES", "").split(";") if p]
        if only_profiles:
            profiles = [p for p in profiles if any(p[0].startswith(o) for o in only_profiles)]
        # relay seeds per profile: 5 (quick: 3); ROBOTALK_BENCH_RUNS=N another count
        reps = int(os.environ.get("ROBOTALK_BENCH_RUNS", self.runs))
        # (name, server arguments, client arguments, the server's hand-over margin in ms: a frame of
        # the adaptive schedule must have arrived that long before it plays; the fixed schedule of
        # the paper calls a frame late only once it arrives after its time; the profiles it runs on,
        # None: every one).
        adaptive = ["--playback-estimator", "adaptive", "--playback-margin", "2"]
        congested = ("U[0, 100]", "U[0, 150]")
        variants = (("paper", ["--playback-estimator", "paper"], [], 0.0, None),
                    # the default before the start lead (issue 23's first adaptive start)
                    ("adaptive_lead0", adaptive + ["--playback-start-lead", "0"], [], 2.0, None),
                    # the server's default and the client's: redundancy decided from the link
                    ("adaptive", adaptive, [], 2.0, None),
                    # a lost frame's retransmission comes a round trip late: the client's redundancy
                    ("adaptive_copies", adaptive, ["--copies", "2"], 2.0, ("WAN",)),
                    # the client's default before (issue 23, tenth session): each playback package once
                    ("adaptive_one_copy", adaptive, ["--copies", "1"], 2.0, None),
                    # the same two after one unmeasured sequence in the same session (a long-lived client)
                    ("adaptive_warm", adaptive, ["--warmup", "1"], 2.0, ("WAN",)),
                    ("adaptive_one_copy_warm", adaptive, ["--copies", "1", "--warmup", "1"], 2.0, ("WAN",)),
                    ("adaptive_queue", adaptive + ["--playback-queue-start", "on"], [], 2.0, congested),
                    # before the connect burst's own queue was left out of the delay spread
                    ("adaptive_burst_off", adaptive + ["--playback-burst-discount", "off"], [], 2.0, congested + ("WAN",)),
                    # a wider timing tolerance (an option): each gap up to 50 % longer; the gate moves with it
                    ("adaptive_stretch50", adaptive + ["--playback-stretch", "0.5"], ["--stretch-bound", "0.5"], 2.0,
                     None),
                    # the default before a retransmitted package's delay was left out of the history
                    ("adaptive_resent", adaptive + ["--playback-resent-delays", "on"], [], 2.0, ("WAN",)),
                    ("adaptive_stretch50_copies", adaptive + ["--playback-stretch", "0.5"],
                     ["--stretch-bound", "0.5", "--copies", "2"], 2.0, ("WAN",)),
                    # both options: the queue start decides where the 50 % stretch can follow the queue
                    ("adaptive_stretch50_queue", adaptive + ["--playback-stretch", "0.5", "--playback-queue-start", "on"],
                     ["--stretch-bound", "0.5"], 2.0, None))
        # the default before a queue beyond the gate was followed (issue 23, seventh session)
        variants += (("adaptive_follow_off", adaptive + ["--playback-follow-queue", "off"], [], 2.0, None),)
        # the thin buffer (issue 23, tenth session; an option): a gap up to 25 % while the buffer is
        # thin, judged at that bound; "adaptive_thin_off" (the default since, every gap within 10 %)
        # is the name its relay runs in bench/results/session10/ gave the default
        thin = ["--playback-thin-stretch", "0.25"]
        # frames that come twice (issue 23, eleventh session; an option): the server waits for frame 0's
        # second copy and covers the earlier of two delays; the client sends two copies always.
        # In bench/results/session11/ this build was the branch's "adaptive_copies" (then its default).
        variants += (("adaptive_copies_start", adaptive + ["--playback-copies-start", "on"], ["--copies", "2"], 2.0,
                      ("WAN",)),)
        variants += (("adaptive_thin", adaptive + thin, ["--stretch-bound", "0.25"], 2.0, None),
                     ("adaptive_thin_off", adaptive + ["--playback-thin-stretch", "0.1"], [], 2.0, None))
        # ROBOTALK_BENCH_BEFORE_SERVER=PATH adds the default's arguments on another build's
        # robotalk-server ("adaptive_before_build"): a code change's before and after on the same
        # relay seeds and under the same load, interleaved.
        before_server = os.environ.get("ROBOTALK_BENCH_BEFORE_SERVER")
        if before_server:
            variants += (("adaptive_before_build", adaptive, [], 2.0, None),
                         # the same with the client's two copies always (issue 23, eleventh session)
                         ("adaptive_copies_before_build", adaptive, ["--copies", "2"], 2.0, ("WAN",)))
        # ROBOTALK_BENCH_VARIANTS=a,b runs only those variants (a shorter run).
        only_variants = [v for v in os.environ.get("ROBOTALK_BENCH_VARIANTS", "").split(",") if v]
        if only_variants:
            variants = tuple(v for v in variants if v[0] in only_variants)
        runs = []
        # Another first seed (ROBOTALK_BENCH_SEED) gives a second set of relay draws to pool with the first.
        seed = int(os.environ.get("ROBOTALK_BENCH_SEED", "101"))
        for name, impair in profiles:
            for _ in range(reps):
                for est, server_args, client_args, margin_ms, only in variants:  # interleaved on one relay seed
                    if only and not name.startswith(only):
                        continue
                    own_server = self.server_bin
                    if est in ("adaptive_before_build", "adaptive_copies_before_build"):
                        self.server_bin = before_server
                    try:  # --log-playback: the estimator's inputs and decision in the server's log
                        self.start_server(url=URL_B, extra=server_args + ["--log-playback"])
                    finally:
                        self.server_bin = own_server
                    relay = self.start([self.relay, "--a", URL_A, "--b", URL_B, *impair, "--seed", str(seed),
                                        "--duration", "120"])
                    time.sleep(0.3)
                    warmups = int(client_args[client_args.index("--warmup") + 1]) if "--warmup" in client_args else 0
                    log = self.start([self.raw, "arrivals", "--url", URL_B, "--robot", ROBOT, "--frames",
                                      str(frames), "--timeout", "50", "--skip", str(frames * warmups)])
                    time.sleep(0.2)  # the arrival log subscribed before the first frame
                    a = self.run([self.client, "playback", "--url", URL_A, "--frames", str(frames),
                                  "--period-ms", "100", "--stretch-bound", "0.1", *client_args],
                                 timeout=60 * (1 + warmups))
                    arr = self.collect(log, 50 * (1 + warmups), "arrivals")
                    self.stop(relay)
                    self.stop_server()
                    runs.append({"profile": name, "relay_args": impair, "seed": seed, "estimator": est,
                                 "margin_ms": margin_ms, "server_args": server_args,
                                 "client_args": client_args, "robotalk": a, "arrivals": arr,
                                 "decision": self.playback_decision(), "late_starts": self.late_starts()})
                    time.sleep(0.5)
                seed += 1
        return {"figure": "playback_estimators", "frames": frames, "period_ms": 100, "stretch_bound": 0.1,
                "runs": runs}

    @staticmethod
    def key_values(text):
        out = {}
        for line in (text or "").splitlines():
            k, eq, v = line.partition("=")
            if eq and " " not in k:
                try:
                    out[k] = float(v)
                except ValueError:
                    out[k] = v
        return out

    @staticmethod
    def relay_stats(text, direction):
        for line in (text or "").splitlines():
            if line.startswith(direction + ":"):
                return {k: float(v) for k, _, v in (f.partition("=") for f in line.split()[1:])}
        return {}

    def links(self):
        """Issue 23: deadline enforcement (commands through a lossy, jittery relay, about half past the
        robot's 0.1 s deadline when they arrive: none may run later than it) and link-health accuracy
        (the session's reported loss and delay against what the relay injected), per relay profile."""
        n = 20000 if self.quick else 100000
        profiles = [("lan: 2 ms, 1 % loss", ["--latency-ms", "2", "--a2b-loss", "0.01"]),
                    ("20 ms, 5 % loss", ["--latency-ms", "20", "--a2b-loss", "0.05"]),
                    ("wan: 100 ms +-50 ms, 1 % loss", ["--latency-ms", "100", "--jitter-ms", "50", "--loss", "0.01"])]
        runs = []
        for seed, (name, impair) in enumerate(profiles, start=11):
            self.start_server(url=URL_B)
            relay = self.start([self.relay, "--a", URL_A, "--b", URL_B, *impair, "--seed", str(seed),
                                "--duration", "900", "--stats"])
            time.sleep(0.3)
            health = subprocess.run([self.link, URL_A, ROBOT, "health", "2000", "5"], capture_output=True, text=True,
                                    timeout=120)
            dl = subprocess.run([self.link, URL_A, ROBOT, "deadlines", str(n), str(seed)], capture_output=True,
                                text=True, timeout=900)
            relay.send_signal(2)
            rout, _ = relay.communicate(timeout=10)
            self.stop_server()
            runs.append({"profile": name, "relay_args": impair, "health": self.key_values(health.stdout),
                         "deadlines": self.key_values(dl.stdout), "relay_a2b": self.relay_stats(rout, "a2b"),
                         "relay_b2a": self.relay_stats(rout, "b2a"), "rc": [health.returncode, dl.returncode]})
            time.sleep(2.5)
        return {"figure": "links", "commands": n, "runs": runs}

    def micro(self):
        out = {}
        for name in ("robotalk-kinematics-bench", "robotalk-codec-bench"):
            exe = f"{os.path.abspath(self.args.build)}/bench/{name}"
            if not os.path.exists(exe):
                out[name] = {"error": "not built (libbenchmark-dev missing?)"}
                continue
            r = subprocess.run([exe, "--benchmark_format=json", "--benchmark_repetitions=3",
                                "--benchmark_report_aggregates_only=true",
                                f"--benchmark_min_time={0.05 if self.quick else 0.2}"],
                               capture_output=True, text=True, timeout=300)
            out[name] = json.loads(r.stdout)["benchmarks"] if r.returncode == 0 else {"error": r.stderr[-400:]}
        return {"figure": "micro", "benches": out}

    def ode(self):
        exe = f"{os.path.abspath(self.args.build)}/bench/robotalk-ode-bench"
        shared = os.environ.get("ROBOTALK_SHARED_ROBOTS", os.path.join(ROOT, "..", "shared", "robots"))
        if not os.path.exists(exe):
            return {"figure": "ode", "error": "robotalk-ode-bench not built"}
        r = subprocess.run([exe, os.path.join(ROOT, "models"), shared], capture_output=True, text=True, timeout=600)
        return {"figure": "ode", "output": r.stdout, "rc": r.returncode, "shared_robots": os.path.exists(shared)}


    def trajectory(self):
        """Issue 22: tracking of interpolated sines, the receding-horizon client, the
        RobotDaemon's cost per period (bench/trajectory_bench.cpp; in-process, manual clock)."""
        exe = f"{os.path.abspath(self.args.build)}/bench/robotalk-trajectory-bench"
        shared = os.environ.get("ROBOTALK_SHARED_ROBOTS", os.path.join(ROOT, "..", "shared", "robots"))
        if not os.path.exists(exe):
            return {"figure": "trajectory", "error": "robotalk-trajectory-bench not built"}
        csv_path = os.path.join(self.args.out, "trajectory_ode_10hz.csv")
        cmd = [exe, shared, "--csv", csv_path] + (["--quick"] if self.quick else [])
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        plot = {}
        if os.path.exists(csv_path):  # kept in the JSON, so the figure can be redrawn from the results alone
            with open(csv_path) as f:
                rows = [line.strip().split(",") for line in f if line.strip()]
            os.remove(csv_path)
            plot = {name: [float(row[i]) for row in rows[1:]] for i, name in enumerate(rows[0])}
        output = r.stdout
        # (b) through the network: robotalk-lcm-relay adds 5 ms ± 3 ms (uniform) on the client → server leg.
        client = f"{os.path.abspath(self.args.build)}/bench/robotalk-receding-client"
        iiwa = os.path.join(shared, "iiwa14.urdf")
        if os.path.exists(client) and os.path.exists(iiwa):
            self.start_server(url=URL_B, robot=f"iiwa=kinematic:{iiwa}")
            splices = 1000 if self.quick else 10000
            relay = self.start([self.relay, "--a", URL_A, "--b", URL_B, "--a2b-latency-ms", "5", "--a2b-jitter-ms",
                                "3", "--a2b-jitter-dist", "uniform", "--seed", "22",
                                "--duration", str(splices // 100 + 60)])
            time.sleep(0.3)
            c = subprocess.run([client, "--url", URL_A, "--robot", "iiwa", "--joint", "iiwa_joint_6",
                                "--splices", str(splices)], capture_output=True, text=True,
                               timeout=splices // 100 + 60)
            self.stop(relay)
            self.stop_server()
            output += "\n(b, network) " + (c.stdout.strip().splitlines()[0] if c.returncode == 0 else
                                           f"failed ({c.returncode}): {c.stderr.strip()[-300:]}") + "\n"
        return {"figure": "trajectory", "output": output, "stderr": r.stderr[-400:], "rc": r.returncode,
                "shared_robots": os.path.exists(shared), "plot_ode_10hz": plot}


FIGURES = ["query", "timed", "panic", "throughput", "scale", "cli", "memory", "jitter", "playback",
           "playback_estimators", "links", "micro",
           "ode", "trajectory"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--quick", action="store_true", help="a ~2 minute smoke run (fewer, shorter runs)")
    ap.add_argument("--only", default="", help="comma-separated figures: " + ",".join(FIGURES))
    ap.add_argument("--out", default=os.path.join(ROOT, "bench", "results", "latest"))
    ap.add_argument("--traffic", choices=["split", "single"], default=None,
                    help="scale: the traffic layout (default: RoboTalk's, split)")
    ap.add_argument("--scale-seconds", type=float, default=None, help="scale: seconds per level (default 30)")
    ap.add_argument("--scale-clients", type=lambda s: [int(x) for x in s.split(",")], default=[8, 16, 32, 64],
                    help="scale: the numbers of clients, comma-separated (default 8,16,32,64)")
    args = ap.parse_args()
    only = [f for f in args.only.split(",") if f] or [f for f in FIGURES if not (args.quick and f == "ode")]
    os.makedirs(args.out, exist_ok=True)
    b = Bench(args)
    meta = {"date_utc": time.strftime("%Y-%m-%d %H:%M:%S", time.gmtime()), "quick": args.quick,
            "runs": b.runs, "nproc": os.cpu_count(), "loadavg_start": os.getloadavg(),
            "commit": subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"],
                                     capture_output=True, text=True).stdout.strip()
            or os.environ.get("ROBOTALK_COMMIT", "")}
    try:
        for name in only:
            t0 = time.monotonic()
            loadavg_start = os.getloadavg()
            print(f"bench: {name} ...", file=sys.stderr, flush=True)
            try:
                result = getattr(b, name)()
            except Exception as e:  # one broken figure must not lose the others
                result = {"figure": name, "error": repr(e)}
            result["wall_s"] = round(time.monotonic() - t0, 1)
            result["loadavg_start"] = loadavg_start
            result["loadavg"] = os.getloadavg()
            result["meta"] = meta
            with open(os.path.join(args.out, f"{name}.json"), "w") as f:
                json.dump(result, f, indent=1)
            print(f"bench: {name} done in {result['wall_s']} s", file=sys.stderr, flush=True)
    finally:
        b.cleanup()


if __name__ == "__main__":
    main()
