#!/usr/bin/env python3
"""The Python client beside the C++ client, in the same run (docs/performance.md,
"The Python client"). Run it through scripts/python_bench.sh (a private network
namespace); it starts robotalk-server (kinematic Pioneer) and LCM's raw echo,
then per run, alternating C++ and Python on the same server:

  query        BASE_POSE round trip: robotalk-bench-client query (C++),
               RobotClient.query("BASE_POSE") and .base_pose() (Python), and
               robotalk-bench-raw ping (a bare LCM round trip, the floor)
  timed 1 kHz  2000 JOINT_SETPOINTs on a server-clock grid 1 ms apart, sent
  timed 100 Hz  500 of them 10 ms apart, in packages of 10, 100 ms ahead:
               the server's reported lateness (its timer, not the network)
  stream       a delay-mode stream at 100 Hz for --stream-seconds (one
               set-point sent every 10 ms, 100 ms ahead): the client's own CPU
               and the lateness

The Python side runs the same loops as bench/client_bench.cpp (role
processes of this script). Prints a markdown table; writes JSON to
bench/results/python/latest.json.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any, Dict, List

URL = "udpm://239.255.76.67:7985?ttl=0"
ROOT = Path(__file__).resolve().parents[1]


def summary(v: List[float]) -> Dict[str, float]:
    v = sorted(v)
    if not v:
        return {"n": 0, "p50": 0.0, "p99": 0.0, "mean": 0.0, "max": 0.0}
    def pct(p: float) -> float:
        return v[min(len(v) - 1, int(p * (len(v) - 1) + 0.5))]
    return {"n": len(v), "p50": pct(0.5), "p99": pct(0.99), "mean": sum(v) / len(v), "max": v[-1]}


def cpu_s() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


# --- the Python roles (one process each, as the C++ client's) -----------------

def role_query(count: int, warmup: int = 50) -> Dict[str, Any]:
    import robotalk
    with robotalk.connect("pioneer", URL) as c:
        out: Dict[str, Any] = {}
        for name, call in (("rtt_us", lambda: c.query("BASE_POSE")), ("base_pose_us", c.base_pose)):
            rtt = []
            for i in range(count + warmup):
                t0 = time.monotonic_ns()
                call()
                if i >= warmup:
                    rtt.append((time.monotonic_ns() - t0) / 1e3)
            out[name] = summary(rtt)
        out["retransmissions"] = c.stats()["retransmissions"]
        return out


def role_timed(count: int, period_us: int, lead_ms: int = 100) -> Dict[str, Any]:
    import robotalk
    with robotalk.connect("pioneer", URL) as c:
        period, lead = period_us * 1e-6, lead_ms * 1e-3
        base = c.server_now() + lead + 0.05
        pending = []
        for k in range(0, count, 10):
            first = base + k * period
            # client time (CLOCK_MONOTONIC, as the C++ client's steady clock) of first - lead
            wake = first - lead - c.clock_offset
            time.sleep(max(0.0, wake - time.monotonic()))
            batch = [robotalk.Command("JOINT_SETPOINT", "pan", [0.05 * (j % 4)], start=base + j * period)
                     for j in range(k, min(count, k + 10))]
            pending += c.send_batch(batch)
        late, failed, timeouts = [], 0, 0
        for p in pending:
            try:
                r = p.wait(6)
                failed += not r.succeeded
                late.append(r.lateness * 1e6)
            except robotalk.TimeoutError:
                timeouts += 1
        return {"lateness_us": summary(late), "not_success": failed, "timeouts": timeouts}


def role_stream(seconds: float, rate: float = 100, delay_ms: int = 100) -> Dict[str, Any]:
    import robotalk
    with robotalk.connect("pioneer", URL) as c:
        cpu1, t0 = cpu_s(), time.monotonic()
        period, n, delay = 1 / rate, int(seconds * rate), delay_ms * 1e-3
        pending: List[robotalk.PendingReply] = []
        late: List[float] = []
        failed = lost = 0

        def collect() -> None:
            nonlocal failed, lost
            while pending:
                try:
                    r = pending[0].poll()
                except robotalk.RobotalkError:
                    lost += 1
                    pending.pop(0)
                    continue
                if r is None:
                    return
                failed += not r.succeeded
                late.append(r.lateness * 1e6)
                pending.pop(0)

        for k in range(n):
            time.sleep(max(0.0, t0 + k * period - time.monotonic()))
            pending.append(c.set_joint("pan", [0.05 * (k % 4)], start=c.server_now() + delay, wait=False))
            collect()
        wall = time.monotonic() - t0
        cpu2 = cpu_s()
        for p in pending:
            try:
                r = p.wait(7)
                failed += not r.succeeded
                late.append(r.lateness * 1e6)
            except robotalk.RobotalkError:
                lost += 1
        return {"lateness_us": summary(late), "sent": n, "timeouts": lost, "not_success": failed,
                "cpu_pct": 100 * (cpu2 - cpu1) / wall}


# --- the driver ----------------------------------------------------------------

def run(cmd: List[str], timeout: float = 180) -> Dict[str, Any]:
    out = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    if out.returncode != 0:
        raise RuntimeError(f"{cmd[0]} failed: {out.stderr[-500:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default=str(ROOT / "build"))
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--query-count", type=int, default=2000)
    ap.add_argument("--stream-seconds", type=float, default=10)
    ap.add_argument("--role", choices=["query", "timed", "stream"])
    ap.add_argument("--count", type=int, default=0)
    ap.add_argument("--period-us", type=int, default=1000)
    args = ap.parse_args()
    if args.role == "query":
        print(json.dumps(role_query(args.count)))
        return 0
    if args.role == "timed":
        print(json.dumps(role_timed(args.count, args.period_us)))
        return 0
    if args.role == "stream":
        print(json.dumps(role_stream(args.stream_seconds)))
        return 0

    b = Path(args.build)
    client, raw = str(b / "bench/robotalk-bench-client"), str(b / "bench/robotalk-bench-raw")
    py = [sys.executable, __file__, "--build", str(b)]
    env_path = str(b / "python")
    os.environ["PYTHONPATH"] = env_path + os.pathsep + os.environ.get("PYTHONPATH", "")
    server = subprocess.Popen([str(b / "robotalk-server/robotalk-server"), "--robot",
                               f"pioneer=kinematic:{ROOT / 'models/pioneer2dx_pantilt.urdf'}", "--url", URL,
                               "--duration", "3600", "--no-panic-latch"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    echo = subprocess.Popen([raw, "echo", "--url", URL, "--duration", "3600"], stdout=subprocess.DEVNULL)
    time.sleep(1.0)
    runs = []
    try:
        n = str(args.query_count)
        for _ in range(args.runs):
            r: Dict[str, Any] = {}
            r["query_cpp"] = run([client, "query", "--url", URL, "--count", n])
            r["query_py"] = run(py + ["--role", "query", "--count", n])
            r["query_raw"] = run([raw, "ping", "--url", URL, "--count", n])
            for tag, count, period in (("1k", 2000, 1000), ("100", 500, 10000)):
                r[f"timed{tag}_cpp"] = run([client, "timed", "--url", URL, "--count", str(count),
                                            "--period-us", str(period)])
                r[f"timed{tag}_py"] = run(py + ["--role", "timed", "--count", str(count),
                                                "--period-us", str(period)])
            s = str(args.stream_seconds)
            r["stream_cpp"] = run([client, "stream", "--url", URL, "--seconds", s, "--rate", "100",
                                   "--delay-ms", "100"])
            r["stream_py"] = run(py + ["--role", "stream", "--stream-seconds", s])
            runs.append(r)
    finally:
        for p in (echo, server):
            p.terminate()
            p.wait(10)

    def med(key: str, *path: str) -> float:
        vals = []
        for r in runs:
            v: Any = r[key]
            for k in path:
                v = v[k]
            vals.append(float(v))
        return statistics.median(vals)

    rows = [
        ("query round trip p50 (us)", med("query_cpp", "rtt_us", "p50"), med("query_py", "rtt_us", "p50"),
         med("query_raw", "rtt_us", "p50") if "rtt_us" in runs[0]["query_raw"] else float("nan")),
        ("query round trip p99 (us)", med("query_cpp", "rtt_us", "p99"), med("query_py", "rtt_us", "p99"),
         med("query_raw", "rtt_us", "p99") if "rtt_us" in runs[0]["query_raw"] else float("nan")),
        ("base_pose() (numpy) p50 (us)", med("query_cpp", "rtt_us", "p50"), med("query_py", "base_pose_us", "p50"),
         float("nan")),
        ("1 kHz lateness p50 (us)", med("timed1k_cpp", "lateness_us", "p50"), med("timed1k_py", "lateness_us", "p50"),
         float("nan")),
        ("1 kHz lateness p99 (us)", med("timed1k_cpp", "lateness_us", "p99"), med("timed1k_py", "lateness_us", "p99"),
         float("nan")),
        ("100 Hz lateness p50 (us)", med("timed100_cpp", "lateness_us", "p50"),
         med("timed100_py", "lateness_us", "p50"), float("nan")),
        ("100 Hz lateness p99 (us)", med("timed100_cpp", "lateness_us", "p99"),
         med("timed100_py", "lateness_us", "p99"), float("nan")),
        ("100 Hz stream: client CPU (%)", med("stream_cpp", "cpu_pct"), med("stream_py", "cpu_pct"), float("nan")),
        ("100 Hz stream: lateness p99 (us)", med("stream_cpp", "lateness_us", "p99"),
         med("stream_py", "lateness_us", "p99"), float("nan")),
    ]
    print(f"median of {len(runs)} runs; C++ and Python alternate on one server\n")
    print("| figure | C++ client | Python | Python / C++ | raw LCM floor |")
    print("|---|---|---|---|---|")
    for name, cpp, pyv, floor in rows:
        ratio = f"{pyv / cpp:.2f}×" if cpp > 0 else "—"
        fl = "" if floor != floor else f"{floor:.1f}"
        print(f"| {name} | {cpp:.1f} | {pyv:.1f} | {ratio} | {fl} |")
    bad = {k: v for r in runs for k, v in r.items() if isinstance(v, dict) and v.get("timeouts", 0)}
    print(f"\ntimeouts: {bad or 'none'}")
    out = ROOT / "bench/results/python"
    out.mkdir(parents=True, exist_ok=True)
    (out / "latest.json").write_text(json.dumps({"runs": runs, "rows": rows}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
