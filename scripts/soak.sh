#!/usr/bin/env bash
# The soak (issue 9, item 9; docs/soak.md). Its 60 s form runs in ctest (soak_60s, label soak).
#
#   scripts/soak.sh [--seconds N] [--seed S] [--per-mode K] [--kills K] [--build DIR] [--keep] [--keyed]
#                   [--playback-copies 0|1|2] (ClientOptions::playback_copies of every client; 0, the default: decided from the link)
#   scripts/soak.sh --check-only DIR     the checks again on a kept run's files
#
# One robotalk-server (kinematic driver, models/pioneer2dx_pantilt.urdf,
# --log-executions, --panic-latch) behind robotalk-lcm-relay (10 % loss, 5 %
# duplication, 10 % of copies held back 20 ms: reordering), K clients per mode
# (direct, delay, playback, watch; default 4 each = 16) plus one chaos client
# (seeded panics and resets), for N seconds (default 60). On a seeded schedule
# it kill -9s --kills command clients (default 3; each is replaced by a new
# client with a new seed) and kill -9s the server once, just after a panic,
# starting it again at once with the same --panic-latch file (it must start in
# panic when the file says so). Then it checks the clients' reports
# (robotalk-soak-client, one JSON line per command outcome) against the
# servers' audit logs ("executed" / "refused" lines) and prints sent / executed / refused by reason /
# unknown-outcome / lost; exits 1 if anything ran twice, out of start-time
# order, was lost, or ran without having been sent.
#
# --keyed: the server runs in keyed mode (robotalk-keygen: one key per client
# process, all with every right), every package sealed (docs/security.md).
#
# Everything runs in one private network namespace (scripts/netns_run.sh; exits
# 77 where none can be made). Clients talk on udpm://239.255.76.67:7100 (ports
# 7100..7165, the split layout), the server on 7200 (7200..7265).
# Bounded: clients stop sending after N s and have 45 s to collect their last
# answers before they are killed; the relay stops by itself after N + 120 s.
set -u
root=$(cd "$(dirname "$0")/.." && pwd)
seconds=60 seed=1 per_mode=4 kills=3 build="$root/build" keep=0 check_only="" keyed=0 copies=0
while [ $# -gt 0 ]; do
  case $1 in
    --seconds) seconds=$2; shift 2 ;;
    --seed) seed=$2; shift 2 ;;
    --per-mode) per_mode=$2; shift 2 ;;
    --kills) kills=$2; shift 2 ;;
    --build) build=$2; shift 2 ;;
    --keep) keep=1; shift ;;
    --keyed) keyed=1; shift ;;
    --playback-copies) copies=$2; shift 2 ;;
    --check-only) check_only=$2; shift 2 ;;
    -h|--help) sed -n '2,25p' "$0"; exit 0 ;;
    *) echo "soak.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done
case $seconds in ''|*[!0-9]*) echo "soak.sh: --seconds wants whole seconds, got '$seconds'" >&2; exit 2 ;; esac
[ "$seconds" -ge 10 ] || { echo "soak.sh: --seconds must be at least 10" >&2; exit 2; }

check() {  # check DIR: the report (python below), exit status 1 on a violation
/usr/bin/python3 - "$1" <<'EOF'
import glob, json, os, re, sys
tmp = sys.argv[1]
# The server's audit (--log-executions): "executed" = the driver accepted
# the command (SUCCESS, MODIFIED, in progress): it ran; "refused" = the
# driver refused it (BUSY, NA, ERROR, INTERRUPTED): it reached the driver
# and moved nothing.
audit_re = re.compile(r"(executed|refused) client ([0-9a-f]{16}) command (-?\d+) (\S+) -> (in progress|[A-Z_]+)")
executed = {}   # (client, id) -> [(instance, signal)]: the commands that ran
driver_refused = {}  # (client, id) -> [(instance, signal)]: refused by the driver
order = {}      # client -> ids that ran, in execution order (instances in order)
audited = {}    # client -> every audited id (ran or refused), in order
logs = sorted(glob.glob(os.path.join(tmp, "server*.log")), key=lambda p: int(re.findall(r"\d+", os.path.basename(p))[0]))
per_instance = []
for n, path in enumerate(logs, 1):
    count = 0
    for line in open(path, errors="replace"):
        m = audit_re.search(line)
        if not m:
            continue
        key = (m.group(2), int(m.group(3)))
        audited.setdefault(key[0], []).append(key[1])
        if m.group(1) == "refused":
            driver_refused.setdefault(key, []).append((n, m.group(5)))
            continue
        executed.setdefault(key, []).append((n, m.group(5)))
        order.setdefault(key[0], []).append(key[1])
        count += 1
    per_instance.append(count)
killed = set(os.path.basename(l.strip()) for l in open(os.path.join(tmp, "killed")) if l.strip())

clients = {}    # hex -> dict
panics = resets = 0
notsent = 0
samples = 0
for path in sorted(glob.glob(os.path.join(tmp, "client*.jsonl"))):
    c, mode = None, "?"
    sent, final, seqs_failed, ids_seen, status = {}, {}, [], set(), {}
    for line in open(path, errors="replace"):
        try:
            e = json.loads(line)
        except ValueError:
            continue   # a line cut by kill -9
        ev = e["ev"]
        if ev == "hello":
            c, mode = e["client"], e["mode"]
        elif ev == "sent":
            sent[e["id"]] = e; ids_seen.add(e["id"])
        elif ev == "final":
            final[e["id"]] = e
        elif ev == "status":
            status[e["id"]] = e
        elif ev == "marker":
            ids_seen.add(e["id"])
        elif ev == "seq_failed":
            seqs_failed.append(e)
        elif ev == "notsent":
            notsent += 1
        elif ev == "panic":
            panics += 1
        elif ev == "reset":
            resets += 1
        elif ev == "samples":
            samples += e["n"]
    if c is not None:
        clients[c] = dict(sent=sent, final=final, seqs_failed=seqs_failed, status=status, ids=sorted(ids_seen),
                          killed=os.path.basename(path) in killed, path=path, mode=mode)

violations = []
for key, runs in executed.items():
    for n, sig in runs:
        if sig not in ("SUCCESS", "MODIFIED", "in progress"):
            violations.append("AUDIT: client %s command %d is logged as executed with %s (a refusal)" % (key[0], key[1], sig))
count = dict(sent=0, executed=sum(per_instance), twice=0, lost=0, out_of_order=0, phantom=0, playback_unanswered=0)
refused, answered_ran, unknown = {}, {}, {}
def bump(d, k, n=1): d[k] = d.get(k, 0) + n

for key in set(executed) | set(driver_refused):
    runs = executed.get(key, []) + driver_refused.get(key, [])
    if len(runs) > 1:
        count["twice"] += 1
        violations.append("EXECUTED TWICE: client %s command %d reached the driver %d times (%s)" %
                          (key[0], key[1], len(runs), ", ".join("instance %d: %s" % r for r in runs)))

for c, info in clients.items():
    for cid, s in info["sent"].items():
        count["sent"] += 1
        runs = executed.get((c, cid), [])
        no = driver_refused.get((c, cid), [])
        f = info["final"].get(cid)
        if f is None:
            if info["killed"]:
                bump(unknown, "client killed before its answer (ran %d)" % min(len(runs), 1))
            elif no and not runs:
                bump(unknown, "no answer recorded, refused by the driver (not run)")
            elif not runs:
                count["lost"] += 1
                violations.append("LOST: client %s command %d (%s) got no answer and never ran" % (c, cid, s["type"]))
            else:
                bump(unknown, "no answer recorded, ran")
            continue
        out = f["outcome"]
        if out in ("UNKNOWN_OUTCOME", "TIMEOUT", "CLIENT_ERROR"):
            label = {"UNKNOWN_OUTCOME": "UnknownOutcomeError", "TIMEOUT": "client wait timed out", "CLIENT_ERROR": "ClientError"}[out]
            bump(unknown, "%s (ran %d)" % (label, min(len(runs), 1)))
            continue
        if runs:
            sig = runs[0][1]
            if out == "PANIC" or (sig != "in progress" and sig != out):
                violations.append("ANSWER MISMATCH: client %s command %d ran (%s) but was answered %s: %s" % (c, cid, sig, out, f["msg"]))
            bump(answered_ran, out)
            continue
        if no:
            # Refused by the driver: moved nothing, and its answer must say so.
            if out != no[0][1]:
                violations.append("ANSWER MISMATCH: client %s command %d was refused by the driver (%s) but was answered %s: %s" % (c, cid, no[0][1], out, f["msg"]))
            bump(refused, "%s (refused by the driver)" % no[0][1])
            continue
        if out in ("SUCCESS", "MODIFIED"):
            count["lost"] += 1
            violations.append("LOST: client %s command %d (%s) answered %s but never ran" % (c, cid, s["type"], out))
            continue
        reason = out
        if out == "INTERRUPTED":
            reason += " (flushed by panic)" if "flushed by panic" in f["msg"] else \
                      " (panic before it ran)" if "entered panic" in f["msg"] else " (" + re.sub(r"\d+", "#", f["msg"])[:40] + ")"
        elif out == "ERROR":
            reason += " (" + re.sub(r"[0-9.e+-]+", "#", f["msg"])[:60] + ")"
        bump(refused, reason)

    # Executions nobody reported sending: frames of a failed playback
    # sequence (ids between its marker and the next reported id), or a killed
    # client's last commands (above every id it reported).
    ids = info["ids"]
    gaps = []
    for sf in info["seqs_failed"]:
        nxt = min([i for i in ids if i > sf["after"]], default=float("inf"))
        gaps.append([sf["after"], nxt, sf["frames"], 0, sf["outcome"]])
    top = max(ids, default=0)
    for cid in audited.get(c, []):
        if cid in info["sent"]:
            continue
        ran = (c, cid) in executed
        g = next((g for g in gaps if g[0] < cid < g[1]), None)
        if g is not None:
            g[3] += ran
        elif info["killed"] and cid > top:
            bump(unknown, "client killed before its report (ran 1)" if ran else
                 "client killed before its report (refused by the driver; outside the balance)")
        else:
            count["phantom"] += 1
            violations.append("RAN UNSENT: client %s command %d ran but no report sent it" % (c, cid))
    for g in gaps:
        count["sent"] += g[2]
        if g[3] > g[2]:
            violations.append("EXECUTED TWICE?: a failed playback sequence of %d frames ran %d commands" % (g[2], g[3]))
        label = "playback frame, sequence " + ("UnknownOutcomeError" if g[4] == "UNKNOWN_OUTCOME" else "TimeoutError")
        bump(unknown, label + " (ran)", g[3])
        # COMMAND_STATUS of the frames that did not run (asked after a plain
        # timeout; the first id after the marker is the PLAYBACK id itself).
        known = 0
        for cid, st in sorted(info["status"].items()):
            # Frames are the ids after the marker and the PLAYBACK id (the
            # ids above them are the client's own queries, e.g. a re-sync).
            if not (g[0] + 1 < cid <= g[0] + 1 + g[2]) or cid >= g[1] or (c, cid) in executed:
                continue
            known += 1
            out = st["outcome"]
            if st["kind"] == "not_received":
                bump(unknown, label + ", status: not in this session (not run)")
            elif st["kind"] == "not_ended":
                # Still waiting or running. A frame that ended BUSY (refused,
                # e.g. "GOTO in progress") is "ended": refused, below.
                count["lost"] += 1
                violations.append("LOST: client %s playback frame %d was accepted, never ran and was never answered "
                                  "(COMMAND_STATUS: %s)" % (c, cid, st["msg"]))
            elif out in ("PANIC", "INTERRUPTED", "ERROR", "NA", "BUSY"):
                bump(refused, "%s (playback frame, learnt by COMMAND_STATUS)" % out)
            else:
                bump(unknown, label + ", status %s (not run)" % out)
        bump(unknown, label + " (not run)", g[2] - g[3] - known)
        pst = info["status"].get(g[0] + 1)
        if pst is not None and pst["kind"] == "not_ended":
            count["playback_unanswered"] += 1

    # Start-time order per client and actuator, over the servo commands whose
    # start is known (docs/protocol.md: a servo command that arrives after a
    # later one of the same client on the same actuator ran is superseded;
    # commands on other actuators, and tasks such as GOTO, may run late).
    last_by = {}
    for cid in order.get(c, []):
        s = info["sent"].get(cid)
        if s is None or s["start_us"] < 0:
            continue
        if s["type"] in ("JOINT_SETPOINT", "JOINT_SPEED", "JOINT_FORCE", "FRAME_SETPOINT"):
            actuator = s["type"][:5] + ":" + s.get("target", "")
        elif s["type"] == "SETSPEED":
            actuator = "base"
        else:
            continue
        last = last_by.get(actuator)
        if last is not None and s["start_us"] < last[1]:
            count["out_of_order"] += 1
            f = info["final"].get(cid, {})
            late = f.get("late_us", -1)
            why = "no reply" if late is None or late < 0 else \
                  "it ran %.0f ms late: it reached the server after the newer one's start" % (late / 1e3) \
                  if late > last[1] - s["start_us"] else "it ran %.0f ms late: the server had both" % (late / 1e3)
            violations.append("OUT OF ORDER: client %s (%s) command %d (start %d us) ran after command %d (start %.0f ms later); %s" %
                              (c, info["mode"], cid, s["start_us"], last[0], (last[1] - s["start_us"]) / 1e3, why))
        if last is None or s["start_us"] >= last[1]:
            last_by[actuator] = (cid, s["start_us"])

for c in set(audited) - set(clients):
    n = len(audited[c])
    count["phantom"] += n
    violations.append("RAN UNSENT: %d commands of client %s, which no report names" % (n, c))

relay = [l.strip() for l in open(os.path.join(tmp, "relay.out")) if l.startswith(("a2b", "b2a"))]
kills = len(killed)
print("soak: %d client reports (%d killed), %d server instances, %d panics (%d resets answered), %d watch samples" %
      (len(clients), kills, len(logs), panics, resets, samples))
for l in relay:
    m = dict(kv.split("=") for kv in l.split()[1:])
    print("  relay %s received %s lost %s duplicated %s reordered %s" % (l[:3], m.get("received"), m.get("lost"), m.get("duplicated"), m.get("reordered")))
print("sent            %6d  (commands with an id; %d calls threw before sending: no session)" % (count["sent"], notsent))
print("executed        %6d  (audit 'executed' lines: %s per server instance)" % (count["executed"], " + ".join(map(str, per_instance))))
print("  answered after running: " + ", ".join("%s %d" % kv for kv in sorted(answered_ran.items())))
by_signal = {}
for runs in driver_refused.values():
    bump(by_signal, runs[0][1])
print("refused by the driver %d  (audit 'refused' lines: %s; none counts as run)" %
      (len(driver_refused), ", ".join("%s %d" % kv for kv in sorted(by_signal.items())) or "none"))
print("refused         %6d" % sum(refused.values()))
for k, v in sorted(refused.items(), key=lambda kv: -kv[1]):
    if v:
        print("  %-66s %6d" % (k, v))
print("unknown-outcome %6d" % sum(unknown.values()))
for k, v in sorted(unknown.items(), key=lambda kv: -kv[1]):
    if v:
        print("  %-66s %6d" % (k, v))
print("  (PLAYBACK requests the server never answered, COMMAND_STATUS BUSY: %d)" % count["playback_unanswered"])
not_run = sum(v for k, v in unknown.items() if "not run" in k or "ran 0" in k)
unreported = unknown.get("client killed before its report (ran 1)", 0)
print("  (balance: sent %d + unreported %d = executed %d + refused %d + unknown not run %d + lost %d%s)" %
      (count["sent"], unreported, count["executed"], sum(refused.values()), not_run, count["lost"],
       "" if count["sent"] + unreported == count["executed"] + sum(refused.values()) + not_run + count["lost"] else ": DOES NOT ADD UP"))
print("lost            %6d" % count["lost"])
print("executed twice  %6d" % count["twice"])
print("out of order    %6d" % count["out_of_order"])
print("ran unsent      %6d" % count["phantom"])
for v in violations[:40]:
    print("  " + v)
bad = count["lost"] or count["twice"] or count["out_of_order"] or count["phantom"] or violations
if os.path.exists(os.path.join(tmp, "latch_lost")):
    bad = True
    print("  LATCH LOST: a panic latched at the kill was gone after the restart")
print("soak: " + ("FAIL" if bad else "PASS"))
sys.exit(1 if bad else 0)
EOF
}
if [ -n "$check_only" ]; then check "$check_only"; exit; fi

if [ -z "${ROBOTALK_SOAK_IN_NETNS:-}" ]; then
  export ROBOTALK_SOAK_IN_NETNS=1
  exec "$root/scripts/netns_run.sh" "$0" --seconds "$seconds" --seed "$seed" --per-mode "$per_mode" \
    --kills "$kills" --build "$build" --playback-copies "$copies" $([ "$keep" = 1 ] && echo --keep) \
    $([ "$keyed" = 1 ] && echo --keyed)
fi

server_bin=$build/robotalk-server/robotalk-server
relay_bin=$build/tools/lcm_relay/robotalk-lcm-relay
client_bin=$build/bench/robotalk-soak-client
cli_bin=$build/robotalk-client/robotalk
for b in "$server_bin" "$relay_bin" "$client_bin" "$cli_bin"; do
  [ -x "$b" ] || { echo "soak.sh: $b not built (cmake --build $build --target robotalk-server robotalk-lcm-relay robotalk-soak-client robotalk robotalk-keygen)" >&2; exit 2; }
done
url_a="udpm://239.255.76.67:7100?ttl=0"   # clients
url_b="udpm://239.255.76.67:7200?ttl=0"   # server
tmp=$(mktemp -d /tmp/robotalk-soak.XXXXXX)
export ROBOTALK_KNOWN_SERVERS="$tmp/known_servers"  # keyed: a fresh server key per run, pinned here
server_pid="" relay_pid=""
declare -A client_pids=()   # pid -> report file
cleanup() {
  for p in "${!client_pids[@]}"; do kill -9 "$p" 2>/dev/null; done
  [ -n "$server_pid" ] && kill "$server_pid" 2>/dev/null
  [ -n "$relay_pid" ] && kill "$relay_pid" 2>/dev/null
  wait 2>/dev/null
  if [ "$keep" = 1 ]; then echo "soak: files kept in $tmp"; else rm -rf "$tmp"; fi
}
trap cleanup EXIT
RANDOM=$seed
t0=$(date +%s.%N)
elapsed() { awk -v t0="$t0" -v t="$(date +%s.%N)" 'BEGIN { printf "%.1f", t - t0 }'; }
sleep_until() { local d; d=$(awk -v t0="$t0" -v at="$1" -v t="$(date +%s.%N)" 'BEGIN { d = t0 + at - t; print (d > 0 ? d : 0) }'); sleep "$d"; }

# Keyed mode: a key pair for the server and one per client process (the
# first clients, the replacements of killed ones, the CLI), all listed with
# every right. Open mode: no keys (ROBOTALK_KEY empty = open).
server_keys=()
key_of() { [ "$keyed" = 1 ] && echo "$tmp/keys/client$1"; }
if [ "$keyed" = 1 ]; then
  keygen=$build/tools/keygen/robotalk-keygen
  [ -x "$keygen" ] || { echo "soak.sh: $keygen not built" >&2; exit 2; }
  mkdir -p "$tmp/keys"
  "$keygen" --out "$tmp/keys/server" --name soak-server >/dev/null || exit 2
  for k in cli $(seq $((per_mode * 4 + 1 + kills))); do
    "$keygen" --out "$tmp/keys/client$k" --name "soak-$k" >/dev/null || exit 2
    echo "$(cat "$tmp/keys/client$k.pub") *=all" >>"$tmp/keys/clients"
  done
  chmod 644 "$tmp/keys/clients"
  server_keys=(--key "$tmp/keys/server" --clients "$tmp/keys/clients")
fi

instance=0
start_server() {
  instance=$((instance + 1))
  local log=$tmp/server$instance.log
  "$server_bin" --robot "pioneer=kinematic:$root/models/pioneer2dx_pantilt.urdf" --url "$url_b" \
    --log-executions --panic-latch "$tmp/panic.latch" "${server_keys[@]}" 2>"$log" &
  server_pid=$!
  for _ in $(seq 100); do grep -q "serving robot" "$log" 2>/dev/null && return 0; sleep 0.05; done
  echo "soak.sh: the server did not start:" >&2; cat "$log" >&2; exit 2
}

n_clients=0
start_client() {  # start_client MODE SECONDS
  n_clients=$((n_clients + 1))
  local out=$tmp/client$n_clients.jsonl
  ROBOTALK_KEY=$(key_of "$n_clients") "$client_bin" --mode "$1" --url "$url_a" --robot pioneer --seconds "$2" \
    --seed $((seed * 1000 + n_clients)) --playback-copies "$copies" --out "$out" 2>"$tmp/client$n_clients.err" &
  client_pids[$!]=$out
  echo "$!" "$1" "$out" >>"$tmp/clients"
}

start_server
"$relay_bin" --a "$url_a" --b "$url_b" --loss 0.1 --dup 0.05 --reorder 0.1 --reorder-delay-ms 20 \
  --seed "$seed" --duration $((seconds + 120)) --stats >"$tmp/relay.out" 2>&1 &
relay_pid=$!
modes=(direct delay playback watch)
for m in "${modes[@]}"; do
  for _ in $(seq "$per_mode"); do start_client "$m" "$seconds"; done
done
start_client chaos "$seconds"

# The seeded schedule: one server restart in the middle third, kills spread
# over the run (whole seconds from the start).
restart_at=$((seconds / 3 + RANDOM % (seconds / 3)))
events=("$restart_at restart")
for _ in $(seq "$kills"); do events+=("$((1 + RANDOM % (seconds - 2))) kill"); done
mapfile -t events < <(printf '%s\n' "${events[@]}" | sort -n)
echo "soak: $seconds s, seed $seed, $([ "$keyed" = 1 ] && echo "keyed, ")$((per_mode * 4 + 1)) clients ($per_mode per mode + chaos), files in $tmp"
for ev in "${events[@]}"; do
  at=${ev%% *} what=${ev#* }
  sleep_until "$at"
  if [ "$what" = restart ]; then
    # Kill it in panic (if the chaos client's reset does not come first): a
    # server killed with the robot latched must start again in panic.
    ROBOTALK_KEY=$(key_of cli) "$cli_bin" --url "$url_a" --timeout 5 panic pioneer >/dev/null 2>&1
    kill -9 "$server_pid"; wait "$server_pid" 2>/dev/null
    latched=no  # what the dead server left on disk
    grep -q "^pioneer" "$tmp/panic.latch" 2>/dev/null && latched=yes
    echo "soak: t=$(elapsed) s: server killed (-9) (panic latched: $latched) and started again"
    start_server
    if [ "$latched" = yes ]; then
      if grep -q "starts in PANIC" "$tmp/server$instance.log"; then
        echo "soak: the new instance started in panic, as latched"
      else
        echo "LATCH LOST: the robot was latched in panic at the kill; the new instance did not start in panic" | tee "$tmp/latch_lost"
      fi
      ROBOTALK_KEY=$(key_of cli) "$cli_bin" --url "$url_a" --timeout 5 reset pioneer >/dev/null 2>&1 || echo "soak: the reset after the restart failed" >&2
    fi
  else
    victims=()
    while read -r pid mode out; do
      [ "$mode" = watch ] || [ "$mode" = chaos ] && continue
      [ -n "${client_pids[$pid]:-}" ] && victims+=("$pid:$mode")
    done <"$tmp/clients"
    [ ${#victims[@]} -eq 0 ] && continue
    v=${victims[$((RANDOM % ${#victims[@]}))]}
    pid=${v%%:*} mode=${v#*:}
    kill -9 "$pid"; wait "$pid" 2>/dev/null
    echo "${client_pids[$pid]}" >>"$tmp/killed"
    unset "client_pids[$pid]"
    echo "soak: t=$(elapsed) s: client $pid ($mode) killed (-9); a new $mode client takes its place"
    start_client "$mode" $((seconds - at > 1 ? seconds - at : 1))
  fi
done
sleep_until "$seconds"
# Clients collect their last answers (each wait is bounded by the client's
# give-up); stragglers are killed and counted as killed.
deadline=$((seconds + 45))
for pid in "${!client_pids[@]}"; do
  while kill -0 "$pid" 2>/dev/null; do
    if [ "$(awk -v t0="$t0" -v t="$(date +%s.%N)" -v d="$deadline" 'BEGIN { print (t - t0 > d) }')" = 1 ]; then
      echo "soak: client $pid still running after $deadline s: killed" >&2
      kill -9 "$pid"; echo "${client_pids[$pid]}" >>"$tmp/killed"
      break
    fi
    sleep 0.2
  done
  wait "$pid" 2>/dev/null
done
client_pids=()
kill "$server_pid" 2>/dev/null; wait "$server_pid" 2>/dev/null; server_pid=""
kill "$relay_pid" 2>/dev/null; wait "$relay_pid" 2>/dev/null; relay_pid=""
touch "$tmp/killed"

check "$tmp"
rc=$?
[ $rc -ne 0 ] && keep=1
exit $rc
