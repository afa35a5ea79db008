#!/usr/bin/env python3
"""Opens a port of the demo's private network namespace to this machine's browser.

usage: demo_forward.py HOST_NETNS_FD LISTEN_PORT TARGET_PORT

The demo (scripts/demo.sh) runs its session in a private network namespace,
so robotalk-web's port there is out of the reach of a browser on the machine.
This runs inside that namespace, given an open file descriptor of the
machine's own network namespace (demo.sh opens /proc/self/ns/net before it
enters the private one). It enters the machine's namespace just long enough
to listen on its loopback, 127.0.0.1:LISTEN_PORT (the next free port, up to
20 further, when that one is taken), returns to the private namespace,
prints the port it listens on, and relays every connection to
127.0.0.1:TARGET_PORT there (plain TCP both ways: HTTP and the page's
WebSocket alike). Only loopback: nothing is offered to the network. It runs
until it is killed.
"""

import ctypes
import ctypes.util
import os
import socket
import sys
import threading

CLONE_NEWNET = 0x40000000


def setns(fd):
    if hasattr(os, "setns"):  # Python 3.12
        os.setns(fd, CLONE_NEWNET)
        return
    libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
    if libc.setns(fd, CLONE_NEWNET) != 0:
        err = ctypes.get_errno()
        raise OSError(err, "setns: " + os.strerror(err))


def listen_in(netns_fd, first_port):
    """A listening socket on 127.0.0.1 of the namespace netns_fd names."""
    own = os.open("/proc/self/ns/net", os.O_RDONLY)
    setns(netns_fd)
    try:
        for port in range(first_port, first_port + 21):
            s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
            try:
                s.bind(("127.0.0.1", port))
            except OSError:
                s.close()
                continue
            s.listen(16)
            return s
        raise OSError("ports %d-%d of 127.0.0.1 are all taken" % (first_port, first_port + 20))
    finally:
        setns(own)  # the sockets made from here on are the private namespace's
        os.close(own)


def pump(src, dst):
    try:
        while True:
            data = src.recv(65536)
            if not data:
                break
            dst.sendall(data)
    except OSError:
        pass
    for s, how in ((dst, socket.SHUT_WR), (src, socket.SHUT_RD)):
        try:
            s.shutdown(how)
        except OSError:
            pass


def relay(client, target_port):
    try:
        upstream = socket.create_connection(("127.0.0.1", target_port), timeout=5)
        upstream.settimeout(None)
    except OSError:
        client.close()
        return
    back = threading.Thread(target=pump, args=(upstream, client), daemon=True)
    back.start()
    pump(client, upstream)
    back.join()
    client.close()
    upstream.close()


def main(argv):
    if len(argv) != 4 or not all(a.isdigit() for a in argv[1:]):
        sys.stderr.write("usage: demo_forward.py HOST_NETNS_FD LISTEN_PORT TARGET_PORT\n")
        return 2
    netns_fd, listen_port, target_port = (int(a) for a in argv[1:])
    try:
        listener = listen_in(netns_fd, listen_port)
    except OSError as e:
        sys.stderr.write("demo_forward.py: %s\n" % e)
        return 1
    print(listener.getsockname()[1], flush=True)
    while True:
        client, _ = listener.accept()
        threading.Thread(target=relay, args=(client, target_port), daemon=True).start()


if __name__ == "__main__":
    sys.exit(main(sys.argv))
