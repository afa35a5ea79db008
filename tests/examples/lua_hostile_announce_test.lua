-- The Lua client example against hostile datagrams (review9): an error raised
-- by a decoder inside an LCM handler escaped lcm:handle_timeout() (and left
-- LCM's C module marked "in handle": the next handle() aborted the process on
-- an assertion). One ANNOUNCE that did not decode (a declared count past its
-- bytes, a torn or foreign datagram) ended the client's connect with
-- "buffer ran out of bytes": anyone on the network could keep it from its robot.
--   lua5.2 lua_hostile_announce_test.lua URL LCMTYPES_LUA_DIR LCM_LUA_CPATH_DIR EXAMPLE_DIR
-- (under scripts/netns_run.sh)
-- Starts a sender of hostile ANNOUNCEs (this file with `send`), then looks for
-- a robot nobody serves: it must end as without them ("no robot 'nobody'
-- announced"). Exit 0 pass, 1 fail.
local url, types, cpath, example, role = arg[1], arg[2], arg[3], arg[4], arg[5]
package.path = types .. '/?.lua;' .. types .. '/?/init.lua;' .. example .. '/?.lua;' .. package.path
package.cpath = cpath .. '/?.so;' .. package.cpath
local lcm = require 'lcm'
local msgs = require 'robotalk_msgs'

if role == 'send' then
  local a = msgs.announce_t:new()
  a.url_hint = ''
  a.robots = {}
  local b = a:encode()
  local hostile = {
    b:sub(1, #b - 4) .. string.char(0x7f, 0xff, 0xff, 0xff),  -- 2^31 - 1 robots, none carried
    b:sub(1, #b - 4) .. string.char(0, 0, 0, 3),
    b:sub(1, 20),
    'not an announce_t at all',
  }
  local out = lcm.lcm.new(url)
  for i = 1, 40 do
    os.execute('sleep 0.025')
    out:publish('ROBOTALK/ANNOUNCE', hostile[(i - 1) % #hostile + 1])
  end
  os.exit(0)
end

local rc = require 'robotalk_client'
local self_path = debug.getinfo(1, 'S').source:sub(2)
os.execute(string.format("'%s' '%s' '%s' '%s' '%s' '%s' send &", arg[-1], self_path, url, types, cpath, example))
local ok, client, err = pcall(rc.connect, url, 'nobody', 1.5)
local outcome = not ok and ('raised ' .. tostring(client)) or client and 'connected to a robot nobody serves' or err
print('40 hostile ANNOUNCEs while connecting: ' .. outcome)
if not outcome:find("^no robot 'nobody' announced") then
  print("FAIL: a hostile datagram ended the connect (expected: no robot 'nobody' announced)")
  os.exit(1)
end
print('PASS')
os.exit(0)
