#!/usr/bin/env python3
"""Presses a robot's PANIC button as robotalk-web's page does, with no
browser: a WebSocket client of /ws (RFC 6455, standard library only) that
sends {"type":"panic","robot":NAME} until a panic_result says it was taken,
retrying every 0.5 s while the bridge has not connected the robot yet.
  ws_panic.py PORT ROBOT TIMEOUT_S
Prints the panic_result; exits 0 when one says ok, 1 otherwise."""
import base64
import json
import os
import socket
import struct
import sys
import time

port, robot, timeout = int(sys.argv[1]), sys.argv[2], float(sys.argv[3])
deadline = time.monotonic() + timeout


class Ws:
    def __init__(self):
        self.s = socket.create_connection(("127.0.0.1", port), timeout=1)
        key = base64.b64encode(os.urandom(16)).decode()
        self.s.sendall(("GET /ws HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nUpgrade: websocket\r\n"
                        "Connection: Upgrade\r\nSec-WebSocket-Key: %s\r\nSec-WebSocket-Version: 13\r\n\r\n"
                        % (port, key)).encode())
        self.buf = b""
        while b"\r\n\r\n" not in self.buf:
            self.buf += self.recv()
        head, self.buf = self.buf.split(b"\r\n\r\n", 1)
        if b" 101 " not in head.split(b"\r\n")[0]:
            raise RuntimeError(head.decode(errors="replace"))

    def recv(self):
        data = self.s.recv(65536)
        if not data:
            raise EOFError("the bridge closed the connection")
        return data

    def need(self, n):
        while len(self.buf) < n:
            self.buf += self.recv()
        out, self.buf = self.buf[:n], self.buf[n:]
        return out

    def send_text(self, text):
        payload, mask = text.encode(), os.urandom(4)
        n = len(payload)
        head = bytes([0x81]) + (bytes([0x80 | n]) if n < 126 else bytes([0x80 | 126]) + struct.pack(">H", n))
        self.s.sendall(head + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(payload)))

    def read(self):  # (opcode, payload) of the next frame
        b0, b1 = self.need(2)
        n = b1 & 0x7F
        if n == 126:
            n = struct.unpack(">H", self.need(2))[0]
        elif n == 127:
            n = struct.unpack(">Q", self.need(8))[0]
        if b1 & 0x80:
            self.need(4)
        return b0 & 0x0F, self.need(n)


last = "no answer"
while time.monotonic() < deadline:
    try:
        ws = Ws()
        while time.monotonic() < deadline:
            ws.send_text(json.dumps({"type": "panic", "robot": robot}))
            answer_by = time.monotonic() + 0.5
            result = None
            while result is None and time.monotonic() < answer_by:
                opcode, payload = ws.read()
                if opcode == 1:
                    msg = json.loads(payload)
                    if msg.get("type") == "panic_result" and msg.get("robot") == robot:
                        result = msg
            if result is not None:
                last = json.dumps(result)
                if result.get("ok"):
                    print(last)
                    sys.exit(0)
            time.sleep(0.5)
    except (OSError, EOFError, RuntimeError) as e:
        last = "%s: %s" % (type(e).__name__, e)
        time.sleep(0.2)
print(last)
sys.exit(1)
