#!/usr/bin/env bash
# gaps13 (safety.md's Known gap): robotalk-web's WebSocket clients were not
# bounded: each open /ws or Foxglove connection holds a descriptor and its
# queues, so a client that opens many grew the bridge without limit. Now at
# most --max-websockets (64 by default) are open at once, page and Foxglove
# together; one more is refused with HTTP 503 naming the limit, and once one
# closes a new one is accepted.
# Usage: web_ws_cap_test.sh ROBOTALK_WEB WWW_DIR (inside a private network namespace).
set -u
port=18433
tmp=$(mktemp -d)
. "$(dirname "$0")/bare_web.sh"
start_bare_web "$1" "$2" "$port" 7723  # ROBOTALK_WEB, WWW_DIR
python3 - "$port" "$(dirname "$0")" <<'PY'
import socket, sys
port = int(sys.argv[1])
sys.path.insert(0, sys.argv[2])
import ws_upgrade
LIMIT = 64  # robotalk-web's default --max-websockets

def upgrade(path="/ws", protocol=None):
    return ws_upgrade.upgrade(port, path, protocol)

def refused_from_the_busiest(failure):
    """One more WebSocket from 127.0.0.1 (holding the most) is refused 503;
    else says FAIL: `failure`."""
    s, head, _ = upgrade()
    s.close()
    print("then one more from 127.0.0.1 (holding the most): %s" % head)
    if " 503 " not in head:
        print("FAIL: " + failure)
        return False
    return True


ok = True
held = []
for i in range(LIMIT):
    # Every fourth a Foxglove client: the limit counts both kinds.
    s, head, _ = upgrade("/", "foxglove.websocket.v1") if i % 4 == 3 else upgrade()
    if " 101 " not in head:
        print("FAIL: WebSocket %d of %d refused: %s" % (i + 1, LIMIT, head))
        ok = False
        break
    held.append(s)
print("%d WebSockets open" % len(held))
for path, protocol in (("/ws", None), ("/", "foxglove.websocket.v1")):
    s, head, answer = upgrade(path, protocol)
    print("one more (%s): %s" % (protocol or "page", head))
    if " 503 " not in head or "--max-websockets" not in answer or str(LIMIT) not in answer:
        print("FAIL: one more than %d WebSockets is not refused 503 naming the limit:\n%s" % (LIMIT, answer))
        ok = False
    s.close()
held.pop().close()
import time
accepted = False
for _ in range(30):  # the bridge notices the close on its next read
    time.sleep(0.1)
    s, head, _ = upgrade()
    if " 101 " in head:
        accepted = True
        held.append(s)
        break
    s.close()
if not accepted:
    print("FAIL: after one closed, a new WebSocket is still refused")
    ok = False
# review14: at the limit, the operator's page from another address (its PANIC
# button) still gets its WebSocket: the oldest of the address holding the
# most is closed for it; that address itself is still refused.
s, head = ws_upgrade.page_websocket(port, source="127.0.0.2")
print("at the limit, a page from 127.0.0.2: %s" % head)
if " 101 " not in head or "hello" not in head:
    print("FAIL: at the limit a page from another address gets no WebSocket (the PANIC button)")
    ok = False
else:
    held.append(s)
    time.sleep(0.3)
    oldest = held[0]
    oldest.settimeout(1)
    closed = False
    try:
        while not closed:  # its frames first, then the end (or a reset); a timeout: still open
            closed = oldest.recv(65536) == b""
    except socket.timeout:
        pass
    except OSError:
        closed = True
    print("the oldest WebSocket of 127.0.0.1 closed for it: %s" % closed)
    if not closed:
        print("FAIL: the oldest WebSocket of the address holding the most was not closed")
        ok = False
    ok = refused_from_the_busiest("the address holding the most is not refused at the limit") and ok
# final14: an upgrade to a path that is no WebSocket of the bridge closes
# nobody's (it used to close the oldest of the busiest address, then got 404).
s, head, _ = ws_upgrade.upgrade(port, "/nope", None, source="127.0.0.3")
print("at the limit, an upgrade to /nope from 127.0.0.3: %s" % head)
s.close()
time.sleep(0.3)
ok = refused_from_the_busiest("an upgrade to /nope closed a WebSocket at the limit") and ok


def still_open(sock):
    sock.settimeout(0.5)
    try:
        while True:  # frames first; the end (b"") or a reset: closed; a timeout: open
            if sock.recv(65536) == b"":
                return False
    except socket.timeout:
        return True
    except OSError:
        return False


# final14: every address holding one WebSocket (the operator's page first, the
# oldest), one more address is refused; the operator's is never closed for it.
for h in held:
    h.close()
held = []
time.sleep(0.5)
operator, head = ws_upgrade.page_websocket(port, source="127.0.0.2")
if operator is None or " 101 " not in head:
    print("FAIL: the operator's page got no WebSocket once the others closed: %s" % head)
    ok = False
else:
    for i in range(LIMIT - 1):
        h, head, _ = ws_upgrade.upgrade(port, "/ws", None, source="127.0.1.%d" % (i + 1))
        if " 101 " not in head:
            print("FAIL: WebSocket %d , one an address, refused: %s" % (i + 2, head))
            ok = False
            break
        held.append(h)
    h, head, _ = ws_upgrade.upgrade(port, "/ws", None, source="127.0.2.1")
    print("one WebSocket per address, %d addresses; one from another: %s" % (LIMIT, head))
    if " 503 " not in head:
        print("FAIL: with every address holding one, one more address was not refused 503")
        ok = False
    h.close()
    alive = still_open(operator)
    print("the operator's page still open: %s" % alive)
    if not alive:
        print("FAIL: the operator's page (its PANIC button) was closed for another address's WebSocket")
        ok = False
    operator.close()
# The page itself (plain HTTP) still loads at the limit.
s = socket.create_connection(("127.0.0.1", port), timeout=3)
s.sendall(b"GET / HTTP/1.1\r\nHost: x\r\n\r\n")
if not s.recv(20).startswith(b"HTTP/1.1 200"):
    print("FAIL: the page does not load at the limit")
    ok = False
for s in held:
    s.close()
sys.exit(0 if ok else 1)
PY
rc=$?
if [ $rc -eq 0 ] && ! grep -q "max-websockets" "$tmp/web.log"; then
  echo "FAIL: no line on stderr says a WebSocket was refused:"; cat "$tmp/web.log"; rc=1
fi
if [ $rc -eq 0 ] && ! grep -q "closed the oldest WebSocket of 127.0.0.1, which held the most (64), for one from 127.0.0.2" "$tmp/web.log"; then
  echo "FAIL: no line on stderr says which WebSocket was closed for the page from 127.0.0.2:"; cat "$tmp/web.log"; rc=1
fi
exit $rc
