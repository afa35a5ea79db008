"""A WebSocket upgrade of robotalk-web with the standard library only, for
the web tests that hold many (web_ws_cap_test.sh, web_http_cap_test.sh):
  upgrade(port, path="/ws", protocol=None, source=None) -> (socket, status line, answer)
source: the local address to connect from (another 127.0.0.0/8 address: another client).
The answer is the whole head (and, for a refusal, its body to the end)."""
import base64
import os
import socket


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
