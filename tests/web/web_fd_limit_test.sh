#!/usr/bin/env bash
# Review 12: robotalk-web out of file descriptors (connections held open by
# someone, up to its limit) must not spin. Its accept loop re-armed at once on
# EMFILE, which the kernel answers at once again: the io_context thread burnt
# a core (measured on the base: 0.42 CPU s per s on a loaded 2-core VM, with
# 80 idle connections against `ulimit -n 48`). Now it waits 100 ms between
# failed accepts; the page loads again once connections close.
# Usage: web_fd_limit_test.sh ROBOTALK_WEB WWW_DIR (inside a private network namespace).
set -u
web=$1
www=$2
port=18431
tmp=$(mktemp -d)
. "$(dirname "$0")/bare_web.sh"
start_bare_web "$web" "$www" "$port" 7721 48
python3 - "$pid" "$port" <<'PY'
import socket, sys, time
pid, port = int(sys.argv[1]), int(sys.argv[2])
def cpu():
    f = open('/proc/%d/stat' % pid).read().rsplit(')', 1)[1].split()
    return (int(f[11]) + int(f[12])) / float(__import__('os').sysconf('SC_CLK_TCK'))
held = []
for _ in range(80):  # more than its descriptors
    s = socket.socket()
    s.settimeout(1)
    try:
        s.connect(('127.0.0.1', port))
        held.append(s)
    except OSError:
        break
time.sleep(0.5)
c0, t0 = cpu(), time.time()
time.sleep(2)
used = (cpu() - c0) / (time.time() - t0)
print("held %d connections; robotalk-web used %.2f CPU s per s meanwhile" % (len(held), used))
for s in held:
    s.close()
time.sleep(0.5)
page = b''
for _ in range(20):  # the next accept comes within its pause
    try:
        s = socket.create_connection(('127.0.0.1', port), timeout=2)
        s.sendall(b'GET / HTTP/1.1\r\nHost: x\r\n\r\n')
        page = s.recv(20)
        break
    except OSError:
        time.sleep(0.2)
ok = True
if used > 0.15:
    print("FAIL: robotalk-web spins while out of descriptors (%.2f CPU s per s)" % used)
    ok = False
if not page.startswith(b'HTTP/1.1 200'):
    print("FAIL: the page does not load once the connections closed: %r" % page)
    ok = False
sys.exit(0 if ok else 1)
PY
