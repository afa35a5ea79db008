#!/usr/bin/env python3
"""Writes the measured tables of docs/performance.md and its figures from bench/results.

    python3 bench/gen_performance.py [--latest DIR] [--before DIR] [--doc FILE] [--figdir DIR]
                                     [--freeze-before]

Reads bench/results/latest/*.json (the last run of bench/run_bench.py) and
bench/results/before/*.json (the frozen BEFORE run, measured on the code before
issue 11's changes); replaces the text between the markers
<!-- bench:begin --> and <!-- bench:end --> of the doc. --freeze-before
first copies latest/ over before/ (done once, for the BEFORE column).
Every figure is a median over the runs of one bench run; ratios are
RoboTalk / floor from the SAME run. Python 3 standard library + matplotlib.
"""
import argparse
import glob
import json
import os
import shutil
import statistics

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BEGIN, END = "<!-- bench:begin -->", "<!-- bench:end -->"
# Figures with a section of their own (between their own markers), not in the main table.
OWN_SECTIONS = {"trajectory": ("<!-- trajectory:begin -->", "<!-- trajectory:end -->"),
                "playback_estimators": ("<!-- playback23:begin -->", "<!-- playback23:end -->")}


def load(d):
    out = {}
    for f in glob.glob(os.path.join(d, "*.json")):
        with open(f) as fh:
            r = json.load(fh)
        out[r.get("figure", os.path.basename(f)[:-5])] = r
    return out


def med(xs):
    xs = [x for x in xs if x is not None]
    return statistics.median(xs) if xs else None


def get(d, *path):
    for p in path:
        if not isinstance(d, dict) or p not in d:
            return None
        d = d[p]
    return d


def fmt(x, unit="", digits=0):
    if x is None:
        return "—"
    if digits == 0 and abs(x) >= 1000 and unit in ("", "cmd/s", "/s"):
        return f"{x / 1000:.1f}k{(' ' + unit) if unit else ''}"
    return f"{x:.{digits}f}{(' ' + unit) if unit else ''}"


def per_s(x):
    return "—" if x is None else f"{x / 1000:.1f}k/s"


def us(x):
    """Microseconds, shown as ms from 10 ms up."""
    if x is None:
        return "—"
    return f"{x:.0f} µs" if abs(x) < 10000 else f"{x / 1000:.1f} ms"


def ratio(a, b, digits=2):
    return f"{a / b:.{digits}f}" if a is not None and b not in (None, 0) else "—"


def pair(r, a, b, key):
    """Median p50 / p99 (µs) of runs[i][a][key] and runs[i][b][key] over r['runs']:
    (RoboTalk text, floor text, ratio text)."""
    runs = r.get("runs", [])
    a50, a99 = med([get(x, a, key, "p50") for x in runs]), med([get(x, a, key, "p99") for x in runs])
    b50, b99 = med([get(x, b, key, "p50") for x in runs]), med([get(x, b, key, "p99") for x in runs])
    return f"{us(a50)} / {us(a99)}", f"{us(b50)} / {us(b99)}", f"{ratio(a50, b50)} / {ratio(a99, b99)}"


def rows_for(res):
    """[(figure, robotalk, floor-with-name, ratio)] for one bench run."""
    rows = []
    q = res.get("query", {})
    a, b, r = pair(q, "robotalk", "raw", "rtt_us")
    rows.append(("direct query round trip p50 / p99 (BASE_POSE)", a, f"raw LCM ping-pong, same bytes: {b}", r))
    t = res.get("timed", {})
    for label, key in (("1 kHz timed commands, lateness p50 / p99", "runs"),
                       ("same, other core loaded (busy loop)", "loaded_runs")):
        sub = {"runs": t.get(key, [])}
        a, b, r = pair(sub, "robotalk", "bare_default", "lateness_us")
        _, c, r2 = pair(sub, "robotalk", "bare_1ns", "lateness_us")
        rows.append((label, a, f"bare `clock_nanosleep` loop: {b}; with 1 ns slack: {c}", f"{r} (vs 1 ns: {r2})"))
    p = res.get("panic", {})
    runs = p.get("runs", [])
    a50, a99 = med([get(x, "robotalk", "ack_us", "p50") for x in runs]), med([get(x, "robotalk", "ack_us", "p99") for x in runs])
    b50, b99 = med([get(x, "raw", "rtt_us", "p50") for x in runs]), med([get(x, "raw", "rtt_us", "p99") for x in runs])
    rows.append((f"PANIC acknowledgement p50 / p99, {p.get('streamers', 8)} clients streaming at 100 Hz",
                 f"{us(a50)} / {us(a99)}", f"raw ping-pong 64 B, same load: {us(b50)} / {us(b99)}",
                 f"{ratio(a50, b50)} / {ratio(a99, b99)}"))
    th = res.get("throughput", {})
    runs = th.get("runs", [])
    a100 = med([get(x, "robotalk", "per_s") for x in runs])
    b100 = med([get(x, "raw", "per_s") for x in runs])
    rows.append(("throughput, 1 client, 100 commands in flight (one package each)", per_s(a100).replace("/s", " cmd/s"),
                 f"raw LCM echo, 100 in flight: {per_s(b100)}", ratio(a100, b100)))
    big = th.get("inflight1000_runs", [])
    if big:
        per = ", ".join(fmt(get(x, "robotalk", "per_s")) + (" (cap hit)" if get(x, "robotalk", "timed_out") else "")
                        for x in big)
        lost = sum(get(x, "robotalk", "gave_up") or 0 for x in big)
        rtx = sum(get(x, "robotalk", "retransmissions") or 0 for x in big)
        a1k = med([get(x, "robotalk", "per_s") for x in big])
        b1k = med([get(x, "raw", "per_s") for x in big])
        rows.append((f"throughput, 1,000 single-command packages in flight ({len(big)} runs, {th.get('count')} "
                     f"commands, cap {th.get('cap_s')} s)",
                     f"{per} cmd/s; {lost} gave up, {rtx} retransmissions",
                     f"raw LCM echo, 1,000 in flight: {per_s(b1k)}",
                     f"{ratio(a1k, b1k, 3)} (vs own 100-in-flight: {ratio(a1k, a100, 3)})"))
    for lvl in res.get("scale", {}).get("levels", []):
        cl = lvl["per_client"]
        ok = [c for c in cl if "sent" in c]
        sent = sum(c["sent"] for c in ok)
        to = sum(c["timeouts"] for c in ok)
        p99s = [get(c, "lateness_us", "p99") for c in ok if get(c, "lateness_us", "n")]
        cpu = med([c.get("cpu_pct") for c in ok])
        fails = len(cl) - len(ok)
        rows.append((f"scale: {lvl['clients']} clients × 100 Hz, delay mode (100 ms), {lvl['seconds']} s",
                     f"{100.0 * to / sent if sent else 0:.1f} % timed out; lateness p99 median {us(med(p99s))},"
                     f" worst {us(max(p99s) if p99s else None)}; client CPU {fmt(cpu, '%', 1)} each,"
                     f" server {fmt(lvl['server_cpu_pct'], '%')}" + machine_text(lvl.get("machine"))
                     + (f"; {fails} clients failed to connect" if fails else ""),
                     "—", "—"))
    c = res.get("cli", {})
    a = med([med(x["robotalk_ms"]) for x in c.get("runs", [])])
    b = med([med(x["raw_ms"]) for x in c.get("runs", [])])
    rows.append(("CLI `robotalk query pioneer base_pose`, wall time", fmt(a, "ms", 1),
                 f"new process + LCM + one raw round trip: {fmt(b, 'ms', 1)}", ratio(a, b)))
    m = res.get("memory", {})
    if m.get("levels"):
        rows.append(("memory per idle session (server RSS)",
                     "; ".join(session_level(l) for l in m["levels"]),
                     f"server RSS with none: {m['levels'][0]['base_rss_kb'] / 1024:.1f} MiB", "—"))
    for load in m.get("loads", []):
        rows.append(memory_load_row(load))
    j = res.get("jitter", {})
    a, b, r = pair(j, "robotalk", "raw", "deviation_us")
    rows.append(("STATE stream at 1 kHz: \\|inter-arrival − 1 ms\\| p50 / p99", a,
                 f"raw LCM 1 kHz publisher (`clock_nanosleep`): {b}", r))
    for lv, (ch, hs, late, n) in playback_levels(res).items():
        rows.append((f"playback start latency, relay congestion U[0, {lv}] ms per message",
                     f"{fmt(ch, 's', 3)} (late frames: {late} of {n})",
                     f"hindsight minimum: {fmt(hs, 's', 3)}", playback_ratio(ch, hs)))
    return rows


def machine_text(m):
    if not m:
        return ""
    return (f"; whole machine (shared): {100 - m['idle_pct']:.0f} % busy, "
            f"{m['sys_pct'] + m['irq_softirq_pct']:.0f} % sys+softirq")


def playback_ratio(chosen, hindsight):
    r = ratio(chosen, hindsight, 1)
    return r + " (floor near 0)" if hindsight is not None and hindsight < 0.005 else r


MEMORY_LOADS = {
    "unknown": "{n} packages of 300 long-named unknown joints",
    "playbacks": "{n} finished 5-frame playbacks",
    "queue": "10,000 queued STOPs",
}


def memory_load_row(load):
    """One exhaustion case of issue 19 item 8: server RSS under the load beside its idle RSS."""
    what = MEMORY_LOADS.get(load["load"], load["load"]).format(n=f"{load['packages']:,}")
    if load.get("rss_kb", -1) in (None, -1) or load.get("per_session_kb") is None:
        return (f"memory: {load['sessions']} sessions × {what}", "not measured: " + str(load.get("error")), "—", "—")
    text = (f"{(load['rss_kb'] - load['idle_rss_kb']) / 1024:.1f} MiB over idle "
            f"({load['per_session_kb']:.0f} KiB a session; peak {load['hwm_kb'] / 1024:.1f} MiB)")
    if load.get("new_client_admitted") is not None and load["new_client_admitted"] >= 0:
        text += "; a new client's command " + ("admitted" if load["new_client_admitted"] else "REFUSED")
    return (f"memory: {load['opened']} sessions × {what} (server RSS)", text,
            f"the same server idle: {load['idle_rss_kb'] / 1024:.1f} MiB", "—")


def session_level(level):
    """'100: 1.68 KiB'; a run before sessions needed a hello has no 'opened'."""
    opened = level.get("opened", level["sessions"])
    if not opened or level.get("per_session_kb") is None:
        return f"{level['sessions']}: none opened"
    text = f"{opened}: {level['per_session_kb']:.2f} KiB"
    return text if opened == level["sessions"] else text + f" ({level['sessions']} asked)"


def playback_levels(res):
    out = {}
    runs = res.get("playback", {}).get("runs", [])
    for lv in sorted({r["congestion_max_ms"] for r in runs}):
        rs = [r for r in runs if r["congestion_max_ms"] == lv]
        ch = med([get(r, "robotalk", "chosen_delay_s") for r in rs])
        hs = med([get(r, "arrivals", "hindsight_min_s") for r in rs])
        late = sum(get(r, "robotalk", "late_frames") or 0 for r in rs)
        n = sum(get(r, "robotalk", "lateness_us", "n") or 0 for r in rs)
        out[lv] = (ch, hs, int(late), int(n))
    return out


def micro_rows(res):
    rows = []
    for bench, items in get(res, "micro", "benches").items() if get(res, "micro", "benches") else []:
        if not isinstance(items, list):
            rows.append((bench, "not run", items.get("error", "")))
            continue
        for b in items:
            if b.get("aggregate_name") != "median":
                continue
            unit = {"ns": 1e-3, "us": 1, "ms": 1e3}[b["time_unit"]]
            name = b["run_name"].replace("BM_", "")
            rows.append((name, f"{b['real_time'] * unit:.3f} µs", b.get("label", "")))
    return rows


def plot(res, figdir):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    runs = res.get("playback", {}).get("runs", [])
    if runs:
        fig, ax = plt.subplots(figsize=(6, 3.8))
        xs = [r["congestion_max_ms"] for r in runs]
        ax.scatter(xs, [get(r, "robotalk", "chosen_delay_s") for r in runs], label="server's chosen delay", marker="o")
        ax.scatter(xs, [get(r, "arrivals", "hindsight_min_s") for r in runs],
                   label="hindsight minimum (from the arrival log)", marker="x")
        lv = playback_levels(res)
        ax.plot(list(lv), [v[0] for v in lv.values()], alpha=0.5)
        ax.plot(list(lv), [v[1] for v in lv.values()], alpha=0.5)
        ax.set_xlabel("relay congestion: service time U[0, X] ms per message (client → server)")
        ax.set_ylabel("start latency after the first frame (s)")
        ax.set_title("Playback start latency, 10 Hz sequence", fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(figdir, "perf_playback.png"), dpi=110)
        plt.close(fig)
    levels = res.get("scale", {}).get("levels", [])
    if levels:
        fig, ax1 = plt.subplots(figsize=(6, 3.8))
        ns = [l["clients"] for l in levels]
        tos, cpus = [], []
        for l in levels:
            ok = [c for c in l["per_client"] if "sent" in c]
            sent = sum(c["sent"] for c in ok)
            tos.append(100.0 * sum(c["timeouts"] for c in ok) / sent if sent else 0)
            cpus.append(med([c.get("cpu_pct") for c in ok]) or 0)
        ax1.plot(ns, tos, "o-", label="commands timed out (%)")
        ax1.plot(ns, cpus, "s--", label="CPU per client process (%)")
        ax1.set_xscale("log", base=2)
        ax1.set_xticks(ns, [str(n) for n in ns])
        ax1.set_xlabel("clients, each 100 Hz in delay mode")
        ax1.set_ylabel("%")
        ax1.set_title("Scale on one LCM bus", fontsize=10)
        ax1.grid(alpha=0.3)
        ax1.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(figdir, "perf_scale.png"), dpi=110)
        plt.close(fig)


def describe(res):
    """The run most figures come from; figures re-run later (--only) are named."""
    metas = [(name, r["meta"]) for name, r in res.items() if "meta" in r and name not in OWN_SECTIONS]
    if not metas:
        return "no run"
    runs = {}
    for name, m in metas:
        runs.setdefault((m.get("date_utc"), m.get("commit")), []).append(name)
    main_key = max(runs, key=lambda k: len(runs[k]))
    meta = next(m for name, m in metas if (m.get("date_utc"), m.get("commit")) == main_key)
    text = (f"{meta.get('date_utc')} UTC, commit {meta.get('commit')}, {'quick' if meta.get('quick') else 'full'} mode, "
            f"{meta.get('runs')} runs, load average at start {meta.get('loadavg_start', [0])[0]:.1f} on "
            f"{meta.get('nproc')} CPUs")
    later = [f"{', '.join(sorted(names))} re-run {date} UTC at {commit}"
             for (date, commit), names in sorted(runs.items()) if (date, commit) != main_key]
    return text + (f" ({'; '.join(later)})" if later else "")


def replace_between(doc, begin, end, text):
    if begin not in doc or end not in doc:
        raise SystemExit(f"markers {begin} / {end} not found")
    head, rest = doc.split(begin, 1)
    _, tail = rest.split(end, 1)
    return head + begin + "\n" + text + "\n" + end + tail


def measured_head(r, tail):
    """"Measured <date> UTC, commit …, mode, load average …" + tail, from a figure's JSON."""
    m = r.get("meta", {})
    return (f"Measured {m.get('date_utc')} UTC, commit {m.get('commit')}, {'quick' if m.get('quick') else 'full'} "
            f"mode, load average at start {r.get('loadavg_start', [0])[0]:.1f} on {m.get('nproc')} CPUs" + tail)


def pool_playback(latest_path, other_path):
    """Appends another playback_estimators run's runs to latest's; each run's date, commit and load
    stay in "parts" (one "Measured" line each)."""
    with open(latest_path) as fh:
        a = json.load(fh)
    with open(other_path) as fh:
        b = json.load(fh)

    def part(r):
        return {"meta": r.get("meta", {}), "loadavg_start": r.get("loadavg_start"), "loadavg": r.get("loadavg"),
                "wall_s": r.get("wall_s"), "frames": r.get("frames"), "runs_n": len(r.get("runs", [])),
                "seeds": sorted({x["seed"] for x in r.get("runs", [])})}

    parts = a.get("parts") or [part(a)]
    parts.append(part(b))
    a["parts"] = parts
    a["runs"] = a.get("runs", []) + b.get("runs", [])
    with open(latest_path, "w") as fh:
        json.dump(a, fh, indent=1)


def playback_estimators_section(res):
    """Issue 23 item 3's table: per relay profile, the paper's estimator, the quick start and the
    adaptive start (same relay seeds, interleaved): start latency / hindsight minimum per run, late
    frames, the timing's stretch."""
    r = res.get("playback_estimators")
    if not r:
        return None
    heads = []
    for p in r.get("parts") or [dict(r, runs_n=len(r.get("runs", [])))]:
        end = (p.get("loadavg") or [None])[0]
        seeds = p.get("seeds") or sorted({x["seed"] for x in r.get("runs", [])})
        heads.append(measured_head(p, (f", at the end {end:.1f}" if end is not None else "") +
                                   f"; {p.get('frames')} frames at 10 Hz per run, {p.get('wall_s')} s for "
                                   f"{p.get('runs_n')} runs, relay seeds {seeds[0]}–{seeds[-1]} "
                                   "(`scripts/bench.sh --only playback_estimators`)."))
    head = "  \n".join(heads)
    if r.get("error"):
        return head + "\n\nNot measured: " + str(r["error"])
    names = {"paper": "paper's estimator",
             "adaptive_lead0": "adaptive, previous default (`--playback-start-lead 0`)",
             "adaptive": "adaptive, start lead 1 (the default now)",
             "adaptive_copies": "adaptive (default) + client sends 2 copies",
             "adaptive_one_copy": "adaptive (default) + client sends 1 copy (the client's default before)",
             "adaptive_warm": "adaptive (default), the client's second sequence in its session",
             "adaptive_one_copy_warm": "adaptive (default) + 1 copy, the client's second sequence in its session",
             "adaptive_queue": "adaptive (default) + queue start (option)",
             "adaptive_burst_off": "adaptive (default), burst discount off (`--playback-burst-discount off`)",
             "adaptive_stretch50": "adaptive, stretch 50 % (`--playback-stretch 0.5`, option)",
             "adaptive_stretch50_queue": "adaptive, stretch 50 % and queue start (both options)",
             "adaptive_stretch50_copies": "adaptive, stretch 50 % (option) + client sends 2 copies",
             "adaptive_resent": "adaptive, previous default (`--playback-resent-delays on`)",
             "adaptive_before_build": "adaptive (default) on the build before (`ROBOTALK_BENCH_BEFORE_SERVER`)"}
    lines = [head, "", "| relay profile (client → server) | estimator | start latency (per run) | hindsight minimum "
             "| ratio (per run) | hindsight + hand-over | ratio to it | late frames | pauses past the bound "
             "| largest gap stretch | whole-sequence stretch |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    verdicts = []
    for prof in dict.fromkeys(x["profile"] for x in r.get("runs", [])):
        for est in names:
            rs = [x for x in r["runs"] if x["profile"] == prof and x["estimator"] == est]
            if not rs:
                continue
            margin = [(x.get("margin_ms") or 0.0) / 1e3 for x in rs]
            ch = [get(x, "robotalk", "chosen_delay_s") for x in rs]
            hs = [get(x, "arrivals", "hindsight_min_s") for x in rs]
            ratios = [c / h if c is not None and h else None for c, h in zip(ch, hs)]
            ratios_own = [c / (h + m) if c is not None and h is not None and h + m > 0 else None
                          for c, h, m in zip(ch, hs, margin)]
            # A frame past the stretch bound plays at its arrival (a pause): late for the verdict too.
            late_each = [int(get(x, "robotalk", "late_frames") or 0) + int(get(x, "robotalk", "not_run") or 0)
                         for x in rs]
            paused_each = [int(get(x, "robotalk", "gaps_over_bound") or 0) for x in rs]
            late = sum(late_each)
            n = sum(int(get(x, "robotalk", "lateness_us", "n") or 0) for x in rs)
            over = sum(int(get(x, "robotalk", "gaps_over_bound") or 0) for x in rs)
            gs = max((get(x, "robotalk", "max_gap_stretch") or 0) for x in rs)
            ts = max((get(x, "robotalk", "total_stretch_s") or 0) for x in rs)
            err = [x["robotalk"].get("error") for x in rs if isinstance(x.get("robotalk"), dict)
                   and x["robotalk"].get("error")]
            fmt_s = ", ".join(f"{c * 1e3:.1f} ms" if c is not None else "—" for c in ch)
            fmt_h = ", ".join(f"{h * 1e3:.1f} ms" if h is not None else "—" for h in hs)
            fmt_ho = ", ".join(f"{(h + m) * 1e3:.1f} ms" if h is not None else "—" for h, m in zip(hs, margin))
            fr = ", ".join(f"{x:.2f}" if x is not None else "—" for x in ratios)
            fro = ", ".join(f"{x:.2f}" if x is not None else "—" for x in ratios_own)
            lines.append(f"| {prof} | {names[est]} | {fmt_s} | {fmt_h} | {fr} | {fmt_ho} | {fro} | {late} of {n} | "
                         f"{over} | {gs * 100:.1f} % | {ts * 1e3:.1f} ms |" + (f" (error: {err[0][:80]})" if err else ""))
            met = [x is not None and x <= 1.25 and lt == 0 and pz == 0
                   for x, lt, pz in zip(ratios, late_each, paused_each)]
            met_own = [x is not None and x <= 1.25 and lt == 0 and pz == 0
                       for x, lt, pz in zip(ratios_own, late_each, paused_each)]
            verdicts.append((prof, names[est], sum(met), sum(met_own), len(rs)))
    lines += ["", "Runs with ratio ≤ 1.25, no late frame and no pause past the bound (to the hindsight minimum; to "
              "it + the server's hand-over margin):", "", "| relay profile | estimator | runs met (hindsight) | runs met (+ hand-over) |",
              "|---|---|---|---|"]
    lines += [f"| {p} | {e} | {a} of {k} | {b} of {k} |" for p, e, a, b, k in verdicts]
    return "\n".join(lines)


def trajectory_section(res, figdir):
    """Issue 22's section: robotalk-trajectory-bench's output as it printed it, and the
    ODE iiwa14 10 Hz plot (step vs quintic vs the continuous sine)."""
    r = res.get("trajectory")
    if not r:
        return None
    head = measured_head(r, " (`robotalk-trajectory-bench`, bench/trajectory_bench.cpp).")
    if r.get("error") or r.get("rc"):
        return head + "\n\nNot measured: " + str(r.get("error") or r.get("stderr"))
    plot = r.get("plot_ode_10hz") or {}
    if plot.get("time_s"):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, (ax, ax2) = plt.subplots(2, 1, figsize=(7, 5.2), sharex=True, gridspec_kw={"height_ratios": [2, 1]})
        t = plot["time_s"]
        ax.plot(t, plot["sine"], "k-", lw=1, label="continuous sine")
        ax.plot(t, plot["step"], "-", lw=1, label="step (today's default)")
        ax.plot(t, plot["quintic"], "--", lw=1, label="quintic")
        ax.set_ylabel("iiwa_joint_6 (rad)")
        ax.set_title("ODE iiwa14, 0.5 Hz sine streamed at 10 Hz frames (delay mode, 300 ms)", fontsize=10)
        ax.legend(fontsize=8, loc="lower left")
        ax.grid(alpha=0.3)
        ax2.plot(t, [a - b for a, b in zip(plot["step"], plot["sine"])], "-", lw=1, label="step − sine")
        ax2.plot(t, [a - b for a, b in zip(plot["quintic"], plot["sine"])], "--", lw=1, label="quintic − sine")
        ax2.set_xlabel("time from the first frame (s), every 10 ms control period")
        ax2.set_ylabel("error (rad)")
        ax2.legend(fontsize=8, loc="lower left")
        ax2.grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(os.path.join(figdir, "trajectory_ode_10hz.png"), dpi=110)
        plt.close(fig)
    return head + "\n\n" + r.get("output", "").strip() + "\n\n![ODE iiwa14 10 Hz: step vs quintic](figures/trajectory_ode_10hz.png)"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--latest", default=os.path.join(ROOT, "bench", "results", "latest"))
    ap.add_argument("--before", default=os.path.join(ROOT, "bench", "results", "before"))
    ap.add_argument("--doc", default=os.path.join(ROOT, "docs", "performance.md"))
    ap.add_argument("--figdir", default=os.path.join(ROOT, "docs", "figures"))
    ap.add_argument("--freeze-before", action="store_true")
    ap.add_argument("--pool-playback", metavar="JSON",
                    help="pool a second playback_estimators run (other relay seeds: ROBOTALK_BENCH_SEED) "
                         "into latest's playback_estimators.json before writing the tables")
    args = ap.parse_args()
    if args.pool_playback:
        pool_playback(os.path.join(args.latest, "playback_estimators.json"), args.pool_playback)
    if args.freeze_before:
        shutil.rmtree(args.before, ignore_errors=True)
        shutil.copytree(args.latest, args.before)
    before, latest = load(args.before), load(args.latest)
    same = describe(before) == describe(latest)
    lines = [f"BEFORE: {describe(before)}.  ", f"Latest: {describe(latest)}" + (" (the BEFORE run)." if same else "."), ""]
    lines += ["| figure | BEFORE: RoboTalk | BEFORE: floor, same run | BEFORE: ratio | latest: RoboTalk | latest: ratio |",
              "|---|---|---|---|---|---|"]
    rb, rl = rows_for(before), rows_for(latest)
    latest_by = {r[0]: r for r in rl}
    for row in rb:
        l = latest_by.get(row[0])
        lr, lratio = ("same run", "") if same else ((l[1], l[3]) if l else ("—", "—"))
        lines.append(f"| {row[0]} | {row[1]} | {row[2]} | {row[3]} | {lr} | {lratio} |")
    for row in rl:  # figures the BEFORE run did not have
        if not any(r[0] == row[0] for r in rb):
            lines.append(f"| {row[0]} | — | {row[2]} | — | {row[1]} | {row[3]} |")
    lines += ["", "In-process (Google Benchmark, median of 3 repetitions, latest run):", "",
              "| benchmark | time per call | what |", "|---|---|---|"]
    lines += [f"| {n} | {t} | {w} |" for n, t, w in micro_rows(latest)]
    ode = get(latest, "ode", "output")
    if ode:
        lines += ["", "The ode driver (`robotalk-ode-bench`, latest run; method in docs/ode_sim.md; the bare world is",
                  "now built exactly as the driver builds it, see bench/ode_bench.cpp):", "", ode.strip()]
    with open(args.doc) as f:
        doc = f.read()
    if BEGIN not in doc or END not in doc:
        raise SystemExit(f"{args.doc}: markers {BEGIN} / {END} not found")
    head, rest = doc.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    doc = head + BEGIN + "\n" + "\n".join(lines) + "\n" + END + tail
    os.makedirs(args.figdir, exist_ok=True)
    section = trajectory_section(latest, args.figdir)
    if section is not None:
        doc = replace_between(doc, *OWN_SECTIONS["trajectory"], section)
    section = playback_estimators_section(latest)
    if section is not None and OWN_SECTIONS["playback_estimators"][0] in doc:
        doc = replace_between(doc, *OWN_SECTIONS["playback_estimators"], section)
    with open(args.doc, "w") as f:
        f.write(doc)
    plot(latest if latest else before, args.figdir)
    print(f"gen_performance: wrote {args.doc} and {args.figdir}/perf_*.png")


if __name__ == "__main__":
    main()
