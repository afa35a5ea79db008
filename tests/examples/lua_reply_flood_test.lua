-- The Lua client example under a flood of well-formed replies in its own
-- session (review15): it filed every reply it read by its id, whatever the
-- id, in a table it never emptied, so a sender on the LAN (open mode: the
-- session and server ids travel in every package) naming fresh ids grew its
-- memory without bound while the program waited in a call.
--   lua5.2 lua_reply_flood_test.lua URL LCMTYPES_LUA_DIR LCM_LUA_CPATH_DIR EXAMPLE_DIR
-- (under scripts/netns_run.sh)
-- Starts a fake server for robot 'fake' (this file with `serve`: it announces
-- it, answers the hello, then sends 20,000 reply packages of the client's
-- session, each with one reply of 2 KiB under an id the client never used),
-- connects, and waits in pause(); Lua's memory may grow by at most 8 MiB.
-- Exit 0 pass, 1 fail.
local url, types, cpath, example, role = arg[1], arg[2], arg[3], arg[4], arg[5]
package.path = types .. '/?.lua;' .. types .. '/?/init.lua;' .. example .. '/?.lua;' .. package.path
package.cpath = cpath .. '/?.so;' .. package.cpath
local lcm = require 'lcm'
local msgs = require 'robotalk_msgs'
local rc = require 'robotalk_client'
local SENT = 20000

if role == 'serve' then
  local out = lcm.lcm.new(url)
  local client_id = nil
  out:subscribe('ROBOTALK/fake/HELLO', function(_, data)
    local h = msgs.hello_t.decode(data)
    local a = msgs.hello_answer_t:new()
    a.protocol_version, a.client_id, a.client_nonce = rc.PROTOCOL_VERSION, h.client_id, h.client_nonce
    a.server_id, a.session_id = 7, 99
    out:publish(string.format('ROBOTALK/fake/HELLO/%016x', h.client_id), a:encode())
    client_id = h.client_id
  end)
  local an = msgs.announce_t:new()
  an.protocol_version, an.server_id = rc.PROTOCOL_VERSION, 7
  local robot = msgs.robot_info_t:new()
  robot.name, robot.driver = 'fake', 'none'
  an.robots, an.num_robots = { robot }, 1
  local announce = an:encode()
  for _ = 1, 60 do
    if client_id then break end
    out:publish('ROBOTALK/ANNOUNCE', announce)
    out:handle_timeout(50)
  end
  if not client_id then os.exit(1) end
  os.execute('sleep 0.3')  -- the client is in its pause()
  local p = msgs.reply_package_t:new()
  p.protocol_version, p.client_id, p.server_id, p.session_id = rc.PROTOCOL_VERSION, client_id, 7, 99
  local r = msgs.reply_t:new()
  r.message = string.rep('x', 2000)
  p.replies, p.num_replies = { r }, 1
  local channel = string.format('ROBOTALK/fake/REPLY/%016x', client_id)
  for i = 1, SENT do
    r.id = 1000000 + i  -- never one of the client's
    out:publish(channel, p:encode())
    if i % 50 == 0 then out:handle_timeout(2) end  -- within what the client drains
  end
  os.exit(0)
end

local self_path = debug.getinfo(1, 'S').source:sub(2)
os.execute(string.format("'%s' '%s' '%s' '%s' '%s' '%s' serve &", arg[-1], self_path, url, types, cpath, example))
local client, err = rc.connect(url, 'fake', 3.0)
if not client then
  print('FAIL: could not connect to the fake server: ' .. tostring(err))
  os.exit(1)
end
collectgarbage('collect')
local before = collectgarbage('count')
local ok, perr = client:pause(4.0)  -- waits in a call: it reads and files what comes
if not ok then
  print('FAIL: pause: ' .. tostring(perr))
  os.exit(1)
end
collectgarbage('collect')
local grown = (collectgarbage('count') - before) / 1024
print(string.format('%d reply packages of one 2 KiB reply each under fresh ids: Lua memory grew %.1f MiB', SENT,
  grown))
if grown > 8 then
  print('FAIL: the client kept every reply it was sent, under any id')
  os.exit(1)
end
print('PASS')
os.exit(0)
