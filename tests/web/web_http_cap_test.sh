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
# Usage: web_http_cap_test.sh ROBOTALK_WEB WWW_DIR (inside a private network namespace).
set -u
web=$1
www=$2
. "$(dirname "$0")/bare_web.sh"
check() {  # check PORT PHASE
  python3 - "$1" "$2" "$(dirname "$0")" <<'PY'
import select, socket, sys, time
port, phase = int(sys.argv[1]), sys.argv[2]
sys.path.insert(0, sys.argv[3])
import ws_upgrade
LIMIT, FLOOD = 64, 120  # robotalk-web's default --max-http-waiting; idle connections opened
ok = True

def fail(text):
    global ok
    print("FAIL (%s): %s" % (phase, text))
    ok = False

def get(s):  # one GET / on s; the status line, or what went wrong
    try:
        s.sendall(b"GET / HTTP/1.1\r\nHost: x\r\n\r\n")
        data = b""
        while b"\r\n\r\n" not in data:
            chunk = s.recv(65536)
            if not chunk:
                return "closed: %r" % data
            data += chunk
        head, body = data.split(b"\r\n\r\n", 1)
        length = int([l.split(b":")[1] for l in head.split(b"\r\n") if l.lower().startswith(b"content-length")][0])
        while len(body) < length:
            body += s.recv(65536)
        return head.split(b"\r\n")[0].decode()
    except OSError as e:
        return "%s: %s" % (type(e).__name__, e)

operator = None
if phase == "spare":  # the operator's page, loaded before the flood, its connection kept alive
    operator = socket.socket()
    operator.bind(("127.0.0.2", 0))
    operator.settimeout(3)
    operator.connect(("127.0.0.1", port))
    first = get(operator)
    if not first.startswith("HTTP/1.1 200"):
        fail("the operator's first request: %s" % first)
flood = []
for _ in range(FLOOD):
    s = socket.socket()
    s.settimeout(2)
    s.connect(("127.0.0.1", port))
    s.sendall(b"GET / HTTP/1.1\r\nHost: x\r\n")  # a request never finished
    flood.append(s)
time.sleep(1)
t0 = time.monotonic()
page = "no answer"
while time.monotonic() - t0 < 3:
    try:
        s = socket.create_connection(("127.0.0.1", port), timeout=3 - (time.monotonic() - t0))
        page = get(s)
        s.close()
        if page.startswith("HTTP/1.1 200"):
            break
    except OSError as e:
        page = "%s: %s" % (type(e).__name__, e)
print("%s: a new client's GET / with %d unfinished requests open: %s after %.2f s"
      % (phase, FLOOD, page, time.monotonic() - t0))
if not page.startswith("HTTP/1.1 200"):
    fail("the page does not load within 3 s")
hello = "no answer"
try:
    s, hello, data = ws_upgrade.upgrade(port)
    while "hello" not in data and " 101 " in hello:  # the page's first message
        chunk = s.recv(4096)
        if not chunk:
            break
        data += chunk.decode(errors="replace")
    hello += " + hello" if "hello" in data else ""
    s.close()
except OSError as e:
    hello = "%s: %s" % (type(e).__name__, e)
print("%s: a new /ws WebSocket: %s" % (phase, hello))
if " 101 " not in hello or "hello" not in hello:
    fail("no WebSocket (the page's PANIC button) within 3 s")
if phase == "spare":
    readable, _, _ = select.select(flood, [], [], 0.5)
    closed = [s for s in readable if s.recv(1, socket.MSG_PEEK) == b""]
    open_ = len(flood) - len(closed)
    oldest_closed = all(flood.index(s) < FLOOD - open_ for s in closed)
    print("spare: of %d unfinished requests, %d still open (oldest closed first: %s)" % (FLOOD, open_, oldest_closed))
    if open_ > LIMIT:
        fail("%d connections waiting for a request are open, more than %d" % (open_, LIMIT))
    if not oldest_closed:
        fail("a newer connection was closed before an older one")
    again = get(operator)
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
rc=0
tmp=$(mktemp -d)
(start_bare_web "$web" "$www" 18435 7725 64 && check 18435 out-of-descriptors && said out-of-descriptors) || rc=1
tmp=$(mktemp -d)
(start_bare_web "$web" "$www" 18437 7727 && check 18437 spare && said spare) || rc=1
exit $rc
