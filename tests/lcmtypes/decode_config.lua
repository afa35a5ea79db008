-- Decodes an encoded robotalk_msgs.robot_config_t from a file with the
-- generated Lua 5.2 bindings, verifies its hash as docs/configuration_message.md
-- describes, and prints one summary line (the format of write_config.cpp).
-- Usage: lua5.2 decode_config.lua GENERATED_LUA_DIR LCM_LUA_MODULE_DIR FILE
local lua_dir, lcm_dir, file = arg[1], arg[2], arg[3]
package.path = lua_dir .. '/?.lua;' .. lua_dir .. '/?/init.lua;' .. package.path
package.cpath = lcm_dir .. '/?.so;' .. package.cpath
local robotalk_msgs = require('robotalk_msgs')

local f = assert(io.open(file, 'rb'))
local data = f:read('*a')
f:close()
local msg = robotalk_msgs.robot_config_t.decode(data)

-- Lua 5.2 numbers are doubles: an int64 (header.hash) loses bits, so the hash
-- is read from its 8 raw bytes (12..19, 0-based) and FNV-1a 64 is computed in
-- four 16-bit limbs, least significant first.
local function hex64(limbs)
  return string.format('%04x%04x%04x%04x', limbs[4], limbs[3], limbs[2], limbs[1])
end
local function fnv1a64(bytes)
  local h = {0x2325, 0x8422, 0x9ce4, 0xcbf2}  -- 0xcbf29ce484222325
  local p = {0x01b3, 0x0000, 0x0100, 0x0000}  -- 0x100000001b3
  for i = 1, #bytes do
    h[1] = bit32.bxor(h[1], bytes:byte(i))
    local r = {0, 0, 0, 0}
    for a = 1, 4 do
      for b = 1, 5 - a do r[a + b - 1] = r[a + b - 1] + h[a] * p[b] end
    end
    local carry = 0
    for k = 1, 4 do
      local v = r[k] + carry
      h[k] = v % 65536
      carry = math.floor(v / 65536)
    end
  end
  return hex64(h)
end

local stored = ''
for i = 13, 20 do stored = stored .. string.format('%02x', data:byte(i)) end
local zeroed = data:sub(1, 12) .. string.rep('\0', 8) .. data:sub(21)
local dofs = 0
for j = 1, msg.num_joints do dofs = dofs + msg.joints[j].num_dofs end
print(string.format('robot=%s links=%d joints=%d frames=%d roots=%d dofs=%d hash=0x%s verified=%s',
  msg.robot_name, msg.num_links, msg.num_joints, msg.num_frames, msg.num_roots, dofs, stored,
  fnv1a64(zeroed) == stored and 'yes' or 'no'))
