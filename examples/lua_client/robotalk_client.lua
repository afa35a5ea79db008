--[[ A small RoboTalk client in Lua 5.2 (protocol 3, open mode, direct mode),
written from docs/protocol.md and docs/writing_a_client.md with LCM's Lua
module (Debian's liblcm-lua: /usr/lib/lua/5.2/lcm.so) and the Lua modules
lcm-gen makes of lcmtypes/robotalk_msgs.

Needs on LUA_PATH the generated modules (<dir>/?.lua;<dir>/?/init.lua, CMake:
ROBOTALK_LCMTYPES_LUA_DIR) and this folder; on LUA_CPATH LCM's lcm.so; and a
sub-second clock: Lua 5.2 has none (os.time counts whole seconds, os.clock is
CPU time), so this uses lua-posix (posix.time.clock_gettime, CLOCK_MONOTONIC)
and, without it, LuaSocket's socket.gettime.

What it does: finds the robot on ROBOTALK/ANNOUNCE (and from it the traffic
layout, single or split), opens a session with a hello, numbers packages 1, 2,
3 ..., sends one package at a time and waits for its replies (direct mode),
retransmitting it with the same sequence until it is acknowledged (fixed
300 ms, 10 tries) and, once acknowledged, every second until each item has
its final reply; ignores a second copy of a reply; sends a heartbeat every
250 ms so the server's watchdog keeps the session; says hello again after
SESSION_UNKNOWN (nothing in that package ran) and sends it again.

int64 in Lua 5.2: numbers are doubles, exact only below 2^53. The client id is
chosen below 2^53; ids and sequences count from 1; server clock times
(microseconds of a monotonic clock) stay far below. The server's session_id
and server_id are random 63/64-bit numbers: this client never uses them as
numbers but as their 8 raw bytes, cut from the received encoding and spliced
into each encoded package; the same for the config hash. LCM's Lua module
prints "WARNING! Unpacking really large integers may result in loss of
precision!" (on stderr) whenever it decodes one: this client zeroes those
fields before decoding, so only ANNOUNCE's robots[].config_hash (inside a
variable-length array) still prints it, once per ANNOUNCE heard while connecting. Not done: keyed mode
(a keyed server is refused with an error). Errors: functions return nil and a
message. ]]
local lcm = require('lcm')
local msgs = require('robotalk_msgs')

local M = {}
M.PROTOCOL_VERSION = 4
local RETRANSMIT_S, RECHECK_S, HEARTBEAT_S, HELLO_REPEAT_S, MAX_TRIES = 0.3, 1.0, 0.25, 0.2, 10
local SIGNALS = { [-1] = 'UNKNOWN_OUTCOME', [0] = 'SUCCESS', 'MODIFIED', 'NA', 'BUSY', 'INTERRUPTED', 'ERROR', 'PANIC' }
function M.signal_name(s) return SIGNALS[s] or '?' end

-- The client's clock, seconds (sub-second: see above).
do
  local ok, ptime = pcall(require, 'posix.time')
  if ok and ptime.clock_gettime then
    M.clock_source = 'posix.time.clock_gettime(CLOCK_MONOTONIC)'
    M.now = function()
      local ts = ptime.clock_gettime(ptime.CLOCK_MONOTONIC)
      return ts.tv_sec + ts.tv_nsec * 1e-9
    end
  else
    local ok2, socket = pcall(require, 'socket')
    if ok2 and socket.gettime then
      M.clock_source = 'socket.gettime'
      M.now = socket.gettime
    else
      error('robotalk_client: no sub-second clock: install lua-posix (Debian) or LuaSocket')
    end
  end
end

local function random_bytes(n)
  local f = assert(io.open('/dev/urandom', 'rb'))
  local s = f:read(n)
  f:close()
  return s
end

-- Where an int64 field lies in an encoding: encode `msg` with field = 0 and
-- = 1 (set by `set`) and find the byte that differs; returns the 1-based
-- start of the field's 8 bytes. The layouts are fixed before these fields.
local function int64_offset(new_msg, set)
  local a, b = new_msg(), new_msg()
  set(a, 0)
  set(b, 1)
  local ea, eb = a:encode(), b:encode()
  for i = 1, #ea do
    if ea:byte(i) ~= eb:byte(i) then return i - 7 end
  end
  error('int64_offset: field not found')
end

local function new_package()
  local p = msgs.package_t:new()
  p.header = msgs.package_header_t:new()
  return p
end
local function new_reply_package()
  local r = msgs.reply_package_t:new()
  return r
end
local OFF = {
  answer_session = int64_offset(function() return msgs.hello_answer_t:new() end,
    function(m, v) m.session_id = v end),
  answer_server = int64_offset(function() return msgs.hello_answer_t:new() end,
    function(m, v) m.server_id = v end),
  reply_session = int64_offset(new_reply_package, function(m, v) m.session_id = v end),
  reply_server = int64_offset(new_reply_package, function(m, v) m.server_id = v end),
  package_session = int64_offset(new_package, function(m, v) m.header.session_id = v end),
}
OFF.announce_server = int64_offset(function() return msgs.announce_t:new() end, function(m, v) m.server_id = v end)
local function raw8(bytes, at) return bytes:sub(at, at + 7) end
-- `bytes` with the 8-byte fields at the given offsets set to zero: LCM's Lua
-- decoder then has no large integer to lose precision on (or warn about).
local function zeroed(bytes, ...)
  for _, at in ipairs({ ... }) do bytes = bytes:sub(1, at - 1) .. string.rep('\0', 8) .. bytes:sub(at + 8) end
  return bytes
end
-- A text from the wire (anyone's in open mode) as an error names it: each
-- control character (C0, DEL, C1 in UTF-8) as \xNN, so it never reaches a
-- terminal as an escape nor forges a line (review14).
function M.printable(text)
  local function esc(c) return string.format('\\x%02x', c:byte()) end
  text = text:gsub('\194[\128-\159]', function(c1) return esc(c1:sub(1, 1)) .. esc(c1:sub(2, 2)) end)
  return (text:gsub('[\0-\31\127]', esc))
end

local function hex(raw) return (raw:gsub('.', function(c) return string.format('%02x', c:byte()) end)) end
M.hex_of_raw = hex

local Client = {}
Client.__index = Client

-- An LCM handler for what anyone on the network can send: `handle(data)` runs
-- under pcall, so a message that does not decode (a declared count or length
-- past its bytes, a torn datagram, another type's bytes) is dropped, counted in
-- self.refused and said once on stderr. Raised out of the handler it would end
-- whatever call was waiting, and leave LCM's C module "in handle": its next
-- handle() aborts the process on an assertion.
function Client:guarded(channel, handle)
  return function(_, data)
    local ok, err = pcall(handle, data)
    if ok then return end
    self.refused = (self.refused or 0) + 1
    if self.refused == 1 then
      io.stderr:write(string.format('robotalk-lua: dropped a message on %s: %s (hostile or corrupt; counted, said once)\n',
        channel, tostring(err)))
    end
  end
end

-- url without RoboTalk's own option traffic=single|split (LCM does not know
-- it; the layout is taken from ANNOUNCE).
local function lcm_url_of(url)
  local base, query = url:match('^([^?]*)%?(.*)$')
  if not base then return url end
  local kept = {}
  for opt in query:gmatch('[^&]+') do
    if not opt:match('^traffic=') then kept[#kept + 1] = opt end
  end
  return base .. (#kept > 0 and '?' .. table.concat(kept, '&') or '')
end
M.lcm_url_of = lcm_url_of

-- "udpm://G:P?opts" -> "udpm://G:(P+delta)?opts" (the split layout's ports; no port: LCM's 7667).
local function shifted_url(url, delta)
  local head, port, tail = url:match('^(udpm://[^:/?]+):(%d+)(.*)$')
  if not head then
    head, tail = url:match('^(udpm://[^:/?]+)(.*)$')
    port = 7667
  end
  if not head or (tail ~= '' and tail:sub(1, 1) ~= '?') then return nil end
  return head .. ':' .. (tonumber(port) + delta) .. tail
end
M.shifted_url = shifted_url

-- Handles what arrives on the client's LCM instances for about `wait_s`.
function Client:handle_for(wait_s)
  if not self.split then
    self.main:handle_timeout(math.max(0, math.floor(wait_s * 1000)))
    return
  end
  -- No select over two LCM instances in the Lua API: poll both in 5 ms slices.
  local deadline = M.now() + wait_s
  repeat
    while self.main:handle_timeout(0) do end
    self.reply:handle_timeout(math.max(0, math.min(5, math.floor((deadline - M.now()) * 1000))))
  until M.now() >= deadline
end

function Client:on_hello_answer(data)
  local m = msgs.hello_answer_t.decode(zeroed(data, OFF.answer_session, OFF.answer_server))
  if m.client_id ~= self.client_id then return end
  for i = 1, 16 do if m.client_nonce[i] ~= self.nonce[i] then return end end  -- not our hello
  self.hello_answered = true
  self.session_raw = raw8(data, OFF.answer_session)
  self.server_raw = raw8(data, OFF.answer_server)
  if m.keyed then
    self.refusal = 'the server answered in keyed mode'
  elseif self.session_raw == string.rep('\0', 8) then
    self.refusal = m.refusal
  else
    self.refusal = nil
  end
end

-- The items of an acknowledged package whose session is gone: they may or may
-- not have run; never re-sent (signal -1, UNKNOWN_OUTCOME).
function Client:unknown_outcome(p, why)
  for _, id in ipairs(p.ids) do
    self.replies[id] = self.replies[id] or { id = id, signal = -1, values = {}, lateness_us = 0, exec_time_us = 0,
      message = 'may or may not have run (' .. why .. '); query or re-plan' }
  end
end

function Client:on_reply(data)
  local m = msgs.reply_package_t.decode(zeroed(data, OFF.reply_session, OFF.reply_server))
  if m.protocol_version ~= M.PROTOCOL_VERSION or m.client_id ~= self.client_id then return end
  local session, server = raw8(data, OFF.reply_session), raw8(data, OFF.reply_server)
  if server ~= self.server_raw then
    -- A new server instance: what the old one acknowledged may or may not have run.
    if self.pending and self.pending.acked then
      self:unknown_outcome(self.pending, 'server instance ' .. hex(self.server_raw) .. ' is gone')
    end
    self.server_raw = server
  end
  local p = self.pending
  if p and p.sequence ~= m.ack_sequence then p = nil end
  if m.session_status == msgs.reply_package_t.SESSION_UNKNOWN then
    if p and p.session_raw == session then
      if p.acked then  -- its first copy was accepted in the session that has expired since
        self:unknown_outcome(p, 'its session expired')
      else
        p.session_unknown = true  -- nothing in it ran: send it again in a new session
      end
    end
    if session == self.session_raw then self.hello_answered = false end  -- say hello again
    return
  end
  if session ~= self.session_raw then return end  -- an older session's late answer
  if p then p.acked = true end
  -- Filed only under an id of the package being waited for: a reply under any
  -- other id (a forger's, naming ids this client never used) is dropped, and
  -- exchange() takes its replies out, so the table holds one package's at most.
  local waited = {}
  for _, id in ipairs(self.pending and self.pending.ids or {}) do waited[id] = true end
  for _, r in ipairs(m.replies) do
    if waited[r.id] and not self.replies[r.id] then self.replies[r.id] = r end  -- a second copy: ignored
  end
end

function Client:say_hello(timeout_s)
  local hello = msgs.hello_t:new()  -- keyed = false, key fields zero: open mode
  hello.protocol_version = M.PROTOCOL_VERSION
  hello.client_id = self.client_id
  local nonce = random_bytes(16)
  self.nonce = {}
  for i = 1, 16 do self.nonce[i] = nonce:byte(i) end
  hello.client_nonce = self.nonce
  self.hello_answered = false
  local deadline, next_hello = M.now() + timeout_s, 0
  while not self.hello_answered do
    local now = M.now()
    if now >= deadline then
      return nil, string.format("no answer to hello from '%s' within %.1f s", self.robot, timeout_s)
    end
    if now >= next_hello then
      self.request:publish(self.hello_channel, hello:encode())
      next_hello = now + HELLO_REPEAT_S
    end
    self:handle_for(math.min(next_hello, deadline) - now)
  end
  if self.refusal then return nil, "hello refused by '" .. self.robot .. "': " .. M.printable(self.refusal) end
  self.last_new_package = M.now()
  return true
end

-- Encodes `pkg` with a new sequence and this session's raw session id, and publishes it.
function Client:publish_new(pkg)
  pkg.header.protocol_version = M.PROTOCOL_VERSION
  pkg.header.client_id = self.client_id
  pkg.header.sequence = self.next_sequence
  pkg.header.session_id = 0  -- replaced by the raw bytes below
  pkg.header.send_time_us = math.floor(M.now() * 1e6)
  self.next_sequence = self.next_sequence + 1
  local e = pkg:encode()
  local at = OFF.package_session
  e = e:sub(1, at - 1) .. self.session_raw .. e:sub(at + 8)
  self.request:publish(self.request_channel, e)
  self.last_new_package = M.now()
  return e, pkg.header.sequence
end

function Client:heartbeat()
  local pkg = new_package()
  pkg.header.payload_type = msgs.package_header_t.PAYLOAD_QUERIES  -- size 0: no payload
  self:publish_new(pkg)
end

-- Timers: a new hello when the session is gone, resends, retransmissions, heartbeats.
function Client:run_timers()
  if not self.hello_answered then
    io.stderr:write('robotalk-lua: session unknown to the server; saying hello again\n')
    local ok, err = self:say_hello(3.0)
    if not ok then return nil, err end
  end
  local p, now = self.pending, M.now()
  if p and p.session_unknown then  -- nothing in it ran: send it again, new sequence, new session
    p.bytes, p.sequence = self:publish_new(p.pkg)
    p.session_raw, p.session_unknown, p.acked, p.tries, p.last_send = self.session_raw, false, false, 1, M.now()
  elseif p and now - p.last_send >= (p.acked and RECHECK_S or RETRANSMIT_S) then
    if not p.acked and p.tries >= MAX_TRIES then
      return nil, string.format('package %d not acknowledged after %d tries', p.sequence, p.tries)
    end
    self.request:publish(self.request_channel, p.bytes)  -- the same sequence
    p.last_send = now
    if not p.acked then p.tries = p.tries + 1 end
  end
  if now - self.last_new_package >= HEARTBEAT_S then self:heartbeat() end
  return true
end

-- Direct mode: sends one package and blocks until every item in it has its
-- final reply (at most timeout_s). Returns the replies in item order.
function Client:exchange(pkg, timeout_s)
  local items = pkg.header.payload_type == msgs.package_header_t.PAYLOAD_COMMANDS and pkg.commands or pkg.queries
  local p = { pkg = pkg, ids = {}, tries = 1, acked = false, session_raw = self.session_raw }
  for i, item in ipairs(items) do
    item.id = self.next_id
    self.next_id = self.next_id + 1
    p.ids[i] = item.id
  end
  pkg.header.payload_size = #items
  p.bytes, p.sequence = self:publish_new(pkg)
  p.last_send = M.now()
  self.pending = p
  local deadline = M.now() + timeout_s
  while true do
    local missing = 0
    for _, id in ipairs(p.ids) do if not self.replies[id] then missing = missing + 1 end end
    if missing == 0 then break end
    if M.now() >= deadline then
      self.pending = nil
      for _, id in ipairs(p.ids) do self.replies[id] = nil end
      return nil, string.format('%d of %d replies missing after %.1f s', missing, #p.ids, timeout_s)
    end
    local ok, err = self:run_timers()
    if not ok then self.pending = nil return nil, err end
    self:handle_for(0.02)
  end
  self.pending = nil
  local out = {}
  for i, id in ipairs(p.ids) do out[i], self.replies[id] = self.replies[id], nil end
  return out
end

-- One query, blocking.
function Client:query(qtype, target, timeout_s)
  local q = msgs.query_t:new()
  q.type, q.target = qtype, target or ''
  local pkg = new_package()
  pkg.header.payload_type = msgs.package_header_t.PAYLOAD_QUERIES
  pkg.header.mode = msgs.package_header_t.MODE_DIRECT
  pkg.num_queries, pkg.queries = 1, { q }
  local r, err = self:exchange(pkg, timeout_s or 5)
  return r and r[1], err
end

-- A command_t: its type, target, start time (us), values and (a waypoint's,
-- optional) velocities.
function M.new_command(ctype, target, start_time_us, values, velocities)
  local c = msgs.command_t:new()
  c.type, c.target, c.start_time_us = ctype, target or '', start_time_us or 0
  c.values, c.velocities = values or {}, velocities or {}
  c.num_values, c.num_velocities = #c.values, #c.velocities
  return c
end

-- A playback sequence in one package (docs/protocol.md, Modes): each
-- command's start_time_us is its offset from the sequence start, and the
-- server chooses when that is (no clock sync needed). `interpolation`
-- (package_header_t.INTERPOLATION_*) joins its set-points into a trajectory
-- (docs/protocol.md, Trajectories). Blocks until every command has its final
-- reply (at most timeout_s); returns the replies in order.
function Client:playback(interpolation, commands, timeout_s)
  local pkg = new_package()
  pkg.header.payload_type = msgs.package_header_t.PAYLOAD_COMMANDS
  pkg.header.mode = msgs.package_header_t.MODE_PLAYBACK
  pkg.header.interpolation = interpolation
  pkg.header.playback_id = self.next_id  -- an id of this client's, as its commands' are
  self.next_id = self.next_id + 1
  pkg.header.playback_frames = #commands
  for _, c in ipairs(commands) do
    pkg.header.playback_duration_us = math.max(pkg.header.playback_duration_us, c.start_time_us)
  end
  pkg.num_commands, pkg.commands = #commands, commands
  return self:exchange(pkg, timeout_s or 5)
end

-- One command in direct mode (start time 0 = now), blocking until its final reply.
function Client:command(ctype, target, values, timeout_s)
  local c = M.new_command(ctype, target, 0, values)
  local pkg = new_package()
  pkg.header.payload_type = msgs.package_header_t.PAYLOAD_COMMANDS
  pkg.header.mode = msgs.package_header_t.MODE_DIRECT
  pkg.num_commands, pkg.commands = 1, { c }
  local r, err = self:exchange(pkg, timeout_s or 5)
  return r and r[1], err
end

-- Lets seconds pass while keeping the session (heartbeats, replies filed).
function Client:pause(seconds)
  local deadline = M.now() + seconds
  while M.now() < deadline do
    local ok, err = self:run_timers()
    if not ok then return nil, err end
    self:handle_for(math.min(0.02, deadline - M.now()))
  end
  return true
end

-- Loads the configuration: subscribes to ROBOTALK/<robot>/CONFIG, sends a
-- CONFIG query and waits for both its reply and the robot_config_t whose hash
-- the reply names (either order). Returns the config and the hash (16 hex
-- digits, read from the raw bytes: a double cannot hold it).
function Client:load_config(timeout_s)
  local channel = 'ROBOTALK/' .. self.robot .. '/CONFIG'
  local heard = {}
  local sub = self.main:subscribe(channel, self:guarded(channel, function(data)  -- before asking
    local config = msgs.robot_config_t.decode(zeroed(data, 13))  -- header.hash: returned as hex
    -- config_header_t.hash: bytes 13..20 (fingerprint 8, format_version 4).
    heard.hash, heard.config = hex(raw8(data, 13)), config
  end))
  local r, err = self:query(msgs.query_t.CONFIG, '', timeout_s)
  local result
  if r and r.signal ~= msgs.reply_t.SUCCESS then
    err = 'CONFIG answered ' .. M.signal_name(r.signal) .. ': ' .. M.printable(r.message)
  elseif r then
    local deadline = M.now() + timeout_s
    while heard.hash ~= r.message and M.now() < deadline do
      local ok, terr = self:run_timers()
      if not ok then err = terr break end
      self:handle_for(0.02)
    end
    if heard.hash == r.message then
      result = heard.config
    else
      err = err or ('no robot_config_t with hash ' .. M.printable(r.message) .. ' on ' .. channel)
    end
  end
  self.main:unsubscribe(sub)
  if result then return result, r.message end
  return nil, err
end

-- Listens to ROBOTALK/ANNOUNCE on url until `robot` is announced (at most
-- timeout_s), opens the LCM instances its traffic layout asks for, says hello.
function M.connect(url, robot, timeout_s)
  local self = setmetatable({ robot = robot, replies = {}, next_sequence = 1, next_id = 1 }, Client)
  -- A random client id below 2^53 (exact in a double): 52 random bits, not 0.
  repeat
    local b = random_bytes(7)
    local id = 0
    for i = 1, 7 do id = id * 256 + b:byte(i) end
    self.client_id = id % 2 ^ 52
  until self.client_id ~= 0
  url = lcm_url_of(url)
  self.main = lcm.lcm.new(url)
  -- The other robots heard, for the error: at most 32 of them (a flood of
  -- ANNOUNCEs naming made-up robots costs no memory).
  local found, problem, heard, heard_count = nil, nil, {}, 0
  local sub = self.main:subscribe('ROBOTALK/ANNOUNCE', self:guarded('ROBOTALK/ANNOUNCE', function(data)
    local a = msgs.announce_t.decode(zeroed(data, OFF.announce_server))  -- robots[].config_hash still warns
    for _, r in ipairs(a.robots) do
      if r.name ~= robot then
        local name = M.printable(r.name)
        if not heard[name] and heard_count < 32 then heard[name], heard_count = true, heard_count + 1 end
      elseif a.protocol_version ~= M.PROTOCOL_VERSION then
        problem = string.format("'%s' speaks protocol %d; this client speaks %d", robot, a.protocol_version,
          M.PROTOCOL_VERSION)
      elseif a.keyed then
        problem = "the server of '" .. robot .. "' requires keys (keyed mode, docs/security.md); " ..
          'this example client supports open mode only'
      else
        found = a
      end
    end
  end))
  local deadline = M.now() + timeout_s
  while not found and not problem and M.now() < deadline do
    self.main:handle_timeout(math.max(1, math.floor((deadline - M.now()) * 1000)))
  end
  self.main:unsubscribe(sub)
  if not found and not problem then
    local names = {}
    for name in pairs(heard) do names[#names + 1] = name end
    table.sort(names)
    problem = string.format("no robot '%s' announced within %.1f s (heard: %s)", robot, timeout_s,
      #names > 0 and table.concat(names, ', ') or 'nothing')
  end
  if problem then return nil, problem end

  self.split = found.traffic_layout == msgs.announce_t.TRAFFIC_SPLIT
  if not self.split and found.traffic_layout ~= msgs.announce_t.TRAFFIC_SINGLE then
    return nil, 'unknown traffic layout ' .. found.traffic_layout .. ' in ANNOUNCE'
  end
  self.request, self.reply = self.main, self.main
  if self.split then
    local request_url, reply_url = shifted_url(url, 1), shifted_url(url, 2 + self.client_id % 64)
    if not request_url then return nil, "the split layout needs a udpm://GROUP:PORT URL, not '" .. url .. "'" end
    self.request, self.reply = lcm.lcm.new(request_url), lcm.lcm.new(reply_url)
  end
  local hexid = string.format('%016x', self.client_id)
  self.hello_channel = 'ROBOTALK/' .. robot .. '/HELLO'
  self.request_channel = 'ROBOTALK/' .. robot .. '/REQUEST'
  local answers, replies = self.hello_channel .. '/' .. hexid, 'ROBOTALK/' .. robot .. '/REPLY/' .. hexid
  self.reply:subscribe(answers, self:guarded(answers, function(data) self:on_hello_answer(data) end))
  self.reply:subscribe(replies, self:guarded(replies, function(data) self:on_reply(data) end))
  local ok, err = self:say_hello(timeout_s)
  if not ok then return nil, err end
  return self
end

function Client:session_hex() return hex(self.session_raw) end
function Client:server_hex() return hex(self.server_raw) end

return M
