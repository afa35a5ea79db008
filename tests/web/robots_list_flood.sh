#!/bin/bash
# review15 reproducer, run by hand (about 45 s; not a ctest entry: the suite is
# at its time budget): made-up robots announced on the bus change robotalk-web's
# robots list many times a second, and each change was queued for every page
# as a message it must receive: a page that reads slowly (here: not at all;
# an operator's page on a slow link) was closed once 64 MiB of lists were
# queued for it (its PANIC button dead until it reconnects), and the bridge's
# memory grew meanwhile. Passes when the page is still open after SECONDS.
#   scripts/netns_run.sh tests/web/robots_list_flood.sh BUILD_DIR [SECONDS]
# BUILD_DIR: a build with robotalk-web and the Lua lcmtypes; needs lua5.2 with
# the LCM module (liblcm-lua) and tools/web/node_modules (npm ci).
set -u
build=$1 seconds=${2:-40}
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
url="udpm://239.255.76.67:7993?ttl=0"
tmp=$(mktemp -d)
trap 'kill $web 2>/dev/null; rm -rf "$tmp"' EXIT
cat > "$tmp/forge.lua" <<'LUA'
-- An ANNOUNCE naming a fresh made-up robot every 2 ms for SECONDS.
local url, types, cpath, seconds = arg[1], arg[2], arg[3], tonumber(arg[4])
package.path = types .. '/?.lua;' .. types .. '/?/init.lua;' .. package.path
package.cpath = cpath .. '/?.so;' .. package.cpath
local lcm = require 'lcm'
local msgs = require 'robotalk_msgs'
local out, n, t0 = lcm.lcm.new(url), 0, os.time()
while os.time() - t0 < seconds do
  local an = msgs.announce_t:new()
  an.protocol_version, an.server_id = 4, 1000 + n
  local r = msgs.robot_info_t:new()
  r.name, r.driver = string.format('made_up_%06d', n), 'none'
  an.robots, an.num_robots = { r }, 1
  out:publish('ROBOTALK/ANNOUNCE', an:encode())
  n = n + 1
  out:handle_timeout(2)
end
print('forged ANNOUNCEs: ' .. n)
LUA
cat > "$tmp/page.py" <<'PY'
import socket, sys, time
sys.path.insert(0, sys.argv[2])
from ws_upgrade import upgrade
s, head, _ = upgrade(int(sys.argv[1]))
s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
time.sleep(float(sys.argv[3]))  # reads nothing meanwhile
s.settimeout(1)
total = 0
try:
    while True:
        c = s.recv(1 << 20)
        if not c:
            print("page: closed by robotalk-web"); sys.exit(1)
        total += len(c)
except socket.timeout:
    print("page: still open")
PY
"$build/tools/web/robotalk-web" --port 8093 --rate 240 --lcm-url "$url" --www "$root/tools/web/www" \
  --node-modules "$root/tools/web/node_modules" 2> "$tmp/web.err" > /dev/null &
web=$!
sleep 1
python3 "$tmp/page.py" 8093 "$here" "$seconds" &
page=$!
sleep 0.5
lua5.2 "$tmp/forge.lua" "$url" "$build/lcmtypes/lua" /usr/lib/lua/5.2 "$seconds" &
wait $page
rc=$?
echo "robotalk-web $(grep VmRSS /proc/$web/status)"
cat "$tmp/web.err"
# The close is said on stderr (the page may still read what was sent before it).
grep -q "closing the WebSocket" "$tmp/web.err" && rc=1
[ $rc = 0 ] && echo PASS || echo "FAIL: a page that reads slowly was closed by a flood of made-up robots"
exit $rc
