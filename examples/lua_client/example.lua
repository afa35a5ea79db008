--[[ The Lua client example: connects to a robot, loads its configuration,
sends a GOTO, then a short timed sequence of pan/tilt set-points in direct
mode (each frame sent at its time by the client's clock, start time "now",
and its reply awaited before the next), then one interpolated (cubic)
sequence of pan waypoints in playback mode, and prints every reply. Same
output as the C and Java examples; tests/examples/client_example_test.sh runs it.
  LUA_PATH="<lua modules dir>/?.lua;<lua modules dir>/?/init.lua;examples/lua_client/?.lua;;" \
  lua5.2 examples/lua_client/example.lua [--url URL] [--robot NAME] [--pause S]
--pause S: wait S seconds after the GOTO (keeping the session); the test
restarts the server meanwhile, and the client must say hello again.
Exit status 0 when every step succeeded. ]]
local rt = require('robotalk_client')
local msgs = require('robotalk_msgs')

local url = os.getenv('LCM_DEFAULT_URL') or 'udpm://239.255.76.67:7667?ttl=0'
local robot = 'pioneer'
local pause_s = 0
local i = 1
while i <= #arg do
  if arg[i] == '--url' and arg[i + 1] then url, i = arg[i + 1], i + 2
  elseif arg[i] == '--robot' and arg[i + 1] then robot, i = arg[i + 1], i + 2
  elseif arg[i] == '--pause' and arg[i + 1] then pause_s, i = tonumber(arg[i + 1]), i + 2
  else
    io.stderr:write('usage: lua5.2 example.lua [--url URL] [--robot NAME] [--pause S]\n')
    os.exit(2)
  end
end

local function fail(err)
  io.stderr:write('error: ' .. tostring(err) .. '\n')
  print('failed')
  os.exit(1)
end

local function print_reply(what, r)
  print(string.format('reply %d %s: %s%s exec_us=%.0f late_ms=%.1f', r.id, what, rt.signal_name(r.signal),
    r.message ~= '' and ' ' .. r.message or '', r.exec_time_us, r.lateness_us / 1000))
end

local client, err = rt.connect(url, robot, 5.0)
if not client then fail(err) end
print(string.format('connected: robot=%s server=%s layout=%s session=%s client=%016x', robot, client:server_hex(),
  client.split and 'split' or 'single', client:session_hex(), client.client_id))
print('clock: ' .. rt.clock_source)

local config, hash = client:load_config(5.0)
if not config then fail(hash) end
local dofs = 0
for _, j in ipairs(config.joints) do dofs = dofs + j.num_dofs end
print(string.format('config: robot=%s links=%d joints=%d frames=%d dofs=%d hash=%s (reply and message agree)',
  config.robot_name, config.num_links, config.num_joints, config.num_frames, dofs, hash))

-- A GOTO is answered when the base has reached its goal.
local ok = true
local r, e = client:command(msgs.command_t.GOTO, '', { 0.5, 0.0, 0.0 }, 30)
if not r then fail(e) end
print_reply('GOTO 0.5 0 0', r)
ok = ok and r.signal == msgs.reply_t.SUCCESS
if pause_s > 0 then
  print(string.format('pausing %.1f s', pause_s))
  io.stdout:flush()
  local server_before = client:server_hex()
  local paused, perr = client:pause(pause_s)
  if not paused then fail(perr) end
  if client:server_hex() ~= server_before then
    print(string.format('new server instance %s, session %s', client:server_hex(), client:session_hex()))
  end
end

-- Direct mode: the client keeps the timing, sending each frame at t0 + offset.
local spacing = 0.25
local frames = { { 'pan', 0.1 }, { 'pan', 0.2 }, { 'pan', 0.3 }, { 'tilt', -0.2 } }
local t0 = rt.now()
local exec = {}
for k, f in ipairs(frames) do
  local paused, perr = client:pause(math.max(0, t0 + (k - 1) * spacing - rt.now()))
  if not paused then fail(perr) end
  r, e = client:command(msgs.command_t.JOINT_SETPOINT, f[1], { f[2] }, 5)
  if not r then fail(e) end
  print_reply(string.format('sequence +%.2f s %s %.2f', (k - 1) * spacing, f[1], f[2]), r)
  ok = ok and r.signal == msgs.reply_t.SUCCESS
  exec[k] = r.exec_time_us
end
local s = 'spacing_s:'
for k = 2, #exec do s = s .. string.format(' %.3f', (exec[k] - exec[k - 1]) / 1e6) end
print(s)

-- An interpolated sequence: pan's waypoints in one cubic playback package
-- (offsets; the server picks the start), the middle one with its velocity;
-- each is answered when the trajectory passes it. It ends at 0.3, where the
-- sequence above left pan. Sent only when everything so far succeeded: a
-- client whose sequence failed moves nothing more.
if ok then
  local point_spacing, way = 0.2, { 0.33, 0.36, 0.3 }
  local points = {}
  for k, q in ipairs(way) do
    points[k] = rt.new_command(msgs.command_t.JOINT_SETPOINT, 'pan', math.floor(k * point_spacing * 1e6 + 0.5), { q },
      k == 2 and { 0.1 } or nil)
  end
  local point_replies
  point_replies, e = client:playback(msgs.package_header_t.INTERPOLATION_CUBIC, points, 10)
  if not point_replies then fail(e) end
  for k, q in ipairs(way) do
    print_reply(string.format('trajectory cubic +%.2f s pan %.2f', k * point_spacing, q), point_replies[k])
    ok = ok and (point_replies[k].signal == msgs.reply_t.SUCCESS or point_replies[k].signal == msgs.reply_t.MODIFIED)
  end
end

local paused, perr = client:pause(0.5)  -- let the last set-point get there
if not paused then fail(perr) end
local pose, pan, tilt
pose, e = client:query(msgs.query_t.BASE_POSE, '')
if not pose then fail(e) end
print(string.format('pose: x=%.3f y=%.3f theta=%.3f', pose.values[1], pose.values[2], pose.values[3]))
pan, e = client:query(msgs.query_t.JOINT_STATE, 'pan')
if not pan then fail(e) end
tilt, e = client:query(msgs.query_t.JOINT_STATE, 'tilt')
if not tilt then fail(e) end
print(string.format('joints: pan=%.3f tilt=%.3f', pan.values[1], tilt.values[1]))
if not ok then fail('a command did not succeed') end
print('done')
