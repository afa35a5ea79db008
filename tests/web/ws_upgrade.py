"""A WebSocket upgrade of robotalk-web with the standard library only, for
the web tests that hold many (web_ws_cap_test.sh, web_http_cap_test.sh):
  upgrade(port, path="/ws", protocol=None, source=None) -> (socket, status line, answer)
source: the local address to connect from (another 127.0.0.0/8 address: another client).
The answer is the whole head (and, for a refusal, its body to the end)."""
import base64
import os
import socket
import time


def upgrade(port, path="/ws", protocol=None, source=None):
    s = socket.create_connection(("127.0.0.1", port), timeout=3, source_address=(source, 0) if source else None)
    key = base64.b64encode(os.urandom(16)).decode()
    extra = "Sec-WebSocket-Protocol: %s\r\n" % protocol if protocol else ""
    s.sendall(("GET %s HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
               "Sec-WebSocket-Key: %s\r\nSec-WebSocket-Version: 13\r\n%s\r\n" % (path, port, key, extra)).encode())
    data = b""
    while b"\r\n\r\n" not in data:
        chunk = s.recv(4096)
        if not chunk:
            break
        data += chunk
    head = data.split(b"\r\n", 1)[0].decode(errors="replace")
    if " 101 " not in head:  # a refusal: read its body to the end
        s.settimeout(2)
        try:
            while True:
                chunk = s.recv(4096)
                if not chunk:
                    break
                data += chunk
        except OSError:
            pass
    return s, head, data.decode(errors="replace")


def get(s):
    """One GET / on socket s: its status line, or what went wrong."""
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


def load_page(port, within=3.0):
    """A new client's GET /, tried again until it is answered 200 or `within`
    seconds pass: (its status line or what went wrong, seconds taken)."""
    t0 = time.monotonic()
    page = "no answer"
    while time.monotonic() - t0 < within:
        try:
            s = socket.create_connection(("127.0.0.1", port), timeout=within - (time.monotonic() - t0))
            page = get(s)
            s.close()
            if page.startswith("HTTP/1.1 200"):
                break
        except OSError as e:
            page = "%s: %s" % (type(e).__name__, e)
    return page, time.monotonic() - t0


def page_websocket(port, source=None):
    """A new page's /ws WebSocket and its first message (the PANIC button's
    connection): (the socket, or None when it went wrong; its status line,
    with " + hello" once the hello came)."""
    try:
        s, head, data = upgrade(port, source=source)
        while "hello" not in data and " 101 " in head:
            chunk = s.recv(4096)
            if not chunk:
                break
            data += chunk.decode(errors="replace")
        return s, head + (" + hello" if "hello" in data else "")
    except OSError as e:
        return None, "%s: %s" % (type(e).__name__, e)
