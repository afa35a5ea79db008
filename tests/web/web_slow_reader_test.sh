#!/usr/bin/env bash
# review14: robotalk-web's --max-http-waiting bounded only the HTTP
# connections waiting for a request. One that asked for a large file (three.js
# is 1.2 MB) and never read its answer was out of that count while its answer
# was written, and held its descriptor up to the 30 s timeout: a client that
# opens many used up the bridge's descriptors (nothing waiting to close, the
# EMFILE pause of web_fd_limit kept everyone out) and the operator's page,
# whose PANIC button stops the robot, could not load.
# Checks, with 120 such slow readers from 127.0.0.1 (each asks for a 16 MB
# file under /modules/three/ with a small receive buffer and reads nothing):
#  1. out of descriptors (`ulimit -n 64`): a new client still gets the page
#     and a /ws WebSocket (its hello) within 3 s;
#  2. with descriptors to spare: at most --max-http-waiting (64) of them stay
#     open; the page and /ws work.
# Usage: web_slow_reader_test.sh ROBOTALK_WEB WWW_DIR (inside a private network namespace).
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
LIMIT, FLOOD = 64, 120  # robotalk-web's default --max-http-waiting; slow readers opened
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

flood = []
for _ in range(FLOOD):
    s = socket.socket()
    s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    s.settimeout(2)
    try:
        s.connect(("127.0.0.1", port))
        s.sendall(b"GET /modules/three/big.js HTTP/1.1\r\nHost: x\r\n\r\n")  # its answer never read
    except OSError:
        pass
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
print("%s: a new client's GET / with %d slow readers open: %s after %.2f s"
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
    # The server's side of each connection still established (one closed by
    # the server is not, whatever of its answer is still unread).
    import subprocess
    ss = subprocess.run(["ss", "-Htn", "state", "established", "( sport = :%d )" % port],
                        capture_output=True, text=True).stdout
    open_ = len([l for l in ss.splitlines() if l.strip()])
    print("spare: of %d slow readers, %d still open" % (FLOOD, open_))
    if open_ > LIMIT:
        fail("%d HTTP connections are open (answers not read), more than %d" % (open_, LIMIT))
sys.exit(0 if ok else 1)
PY
}
rc=0
tmp=$(mktemp -d)
(start_bare_web "$web" "$www" 18441 7731 64 && truncate -s 16M "$tmp/node_modules/three/big.js" &&
  check 18441 out-of-descriptors) || rc=1
tmp=$(mktemp -d)
(start_bare_web "$web" "$www" 18443 7733 && truncate -s 16M "$tmp/node_modules/three/big.js" && check 18443 spare) ||
  rc=1
exit $rc
