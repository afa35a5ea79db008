#!/usr/bin/env bash
# web13: robotalk-web's plain HTTP connections were not bounded. Each one that
# sends a partial request and nothing more (slowloris) held a descriptor for
# its 30 s read timeout, so a client that opens many used up the bridge's
# descriptors (the EMFILE pause of web_fd_limit then kept everyone out) and
# the operator's page, whose PANIC button stops the robot, could not load.
# Checks, with 120 such connections from 127.0.0.1 held open:
#  1. out of descriptors (`ulimit -n 64`): a new client still gets the page
#     and a /ws WebSocket (its hello) within 3 s;
#  2. with descriptors to spare: at most --max-http-waiting (64) of them stay
#     open, the oldest closed first; an operator's keep-alive connection from
#     another address (127.0.0.2), opened before the flood, is never the one
#     closed and takes its next request; the page and /ws work.
# review14 (KIND slow, ctest web_slow_reader): the same with 120 slow readers,
# each asking for a 16 MB file under /modules/three/ with a 4 KB receive
# buffer and reading nothing: a connection whose answer is being written
# held its descriptor up to the 30 s timeout outside --max-http-waiting's
# count (before: with `ulimit -n 64` the page and /ws timed out after 3 s;
# with descriptors to spare more than 64 stayed open). With them, check 2
# counts the connections still established on the bridge's side.
# Usage: web_http_cap_test.sh ROBOTALK_WEB WWW_DIR [KIND] (inside a private
# network namespace); KIND: unfinished (the default) or slow.
set -u
web=$1
www=$2
kind=${3:-unfinished}
. "$(dirname "$0")/bare_web.sh"
check() {  # check PORT PHASE
  python3 - "$1" "$2" "$(dirname "$0")" "$kind" <<'PY'
import select, socket, subprocess, sys, time
port, phase, kind = int(sys.argv[1]), sys.argv[2], sys.argv[4]
sys.path.insert(0, sys.argv[3])
import ws_upgrade
LIMIT, FLOOD = 64, 120  # robotalk-web's default --max-http-waiting; connections opened
flooding = "unfinished requests" if kind == "unfinished" else "slow readers"
ok = True

def fail(text):
    global ok
    print("FAIL (%s): %s" % (phase, text))
    ok = False

operator = None
if phase == "spare":  # the operator's page, loaded before the flood, its connection kept alive
    operator = socket.socket()
    operator.bind(("127.0.0.2", 0))
    operator.settimeout(3)
    operator.connect(("127.0.0.1", port))
    first = ws_upgrade.get(operator)
    if not first.startswith("HTTP/1.1 200"):
        fail("the operator's first request: %s" % first)
flood = []
for _ in range(FLOOD):
    s = socket.socket()
    s.settimeout(2)
    if kind == "unfinished":
        s.connect(("127.0.0.1", port))
        s.sendall(b"GET / HTTP/1.1\r\nHost: x\r\n")  # a request never finished
    else:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        try:
            s.connect(("127.0.0.1", port))
            s.sendall(b"GET /modules/three/big.js HTTP/1.1\r\nHost: x\r\n\r\n")  # its answer never read
        except OSError:
            pass
    flood.append(s)
time.sleep(1)
page, took = ws_upgrade.load_page(port)
print("%s: a new client's GET / with %d %s open: %s after %.2f s" % (phase, FLOOD, flooding, page, took))
if not page.startswith("HTTP/1.1 200"):
    fail("the page does not load within 3 s")
s, hello = ws_upgrade.page_websocket(port)
if s:
    s.close()
print("%s: a new /ws WebSocket: %s" % (phase, hello))
if " 101 " not in hello or "hello" not in hello:
    fail("no WebSocket (the page's PANIC button) within 3 s")
if phase == "spare" and kind == "unfinished":
    readable, _, _ = select.select(flood, [], [], 0.5)
    closed = [s for s in readable if s.recv(1, socket.MSG_PEEK) == b""]
    open_ = len(flood) - len(closed)
    oldest_closed = all(flood.index(s) < FLOOD - open_ for s in closed)
    print("spare: of %d unfinished requests, %d still open (oldest closed first: %s)" % (FLOOD, open_, oldest_closed))
    if open_ > LIMIT:
        fail("%d connections waiting for a request are open, more than %d" % (open_, LIMIT))
    if not oldest_closed:
        fail("a newer connection was closed before an older one")
if phase == "spare" and kind == "slow":
    # The bridge's side of each connection still established (one it closed
    # is not, whatever of its answer is still unread); the operator's too.
    ss = subprocess.run(["ss", "-Htn", "state", "established", "( sport = :%d )" % port],
                        capture_output=True, text=True).stdout
    open_ = len([l for l in ss.splitlines() if l.strip()])
    print("spare: of %d slow readers and the operator's connection, %d still open" % (FLOOD, open_))
    if open_ > LIMIT:
        fail("%d HTTP connections are open (answers not read), more than %d" % (open_, LIMIT))
if phase == "spare":
    again = ws_upgrade.get(operator)
    print("spare: the operator's keep-alive connection, next request: %s" % again)
    if not again.startswith("HTTP/1.1 200"):
        fail("the operator's connection (another address) was closed for the flood")
sys.exit(0 if ok else 1)
PY
}
said() {  # a line on stderr says connections were closed, naming the option
  grep -m1 -- "--max-http-waiting" "$tmp/web.log" ||
    { echo "FAIL ($1): no line on stderr names --max-http-waiting:"; cat "$tmp/web.log"; return 1; }
}
big() {  # the large file the slow readers ask for (sparse)
  [ "$kind" = unfinished ] || truncate -s 16M "$tmp/node_modules/three/big.js"
}
case $kind in
  unfinished) ports=(18435 7725 18437 7727) ;;
  slow) ports=(18441 7731 18443 7733) ;;
  *) echo "unknown KIND '$kind'"; exit 2 ;;
esac
rc=0
tmp=$(mktemp -d)
(start_bare_web "$web" "$www" "${ports[0]}" "${ports[1]}" 64 && big && check "${ports[0]}" out-of-descriptors &&
  said out-of-descriptors) || rc=1
tmp=$(mktemp -d)
(start_bare_web "$web" "$www" "${ports[2]}" "${ports[3]}" && big && check "${ports[2]}" spare && said spare) || rc=1
exit $rc
