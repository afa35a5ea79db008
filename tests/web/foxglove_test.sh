#!/usr/bin/env bash
# Foxglove live and from MCAP, as a user would see them (docs/interop.md),
# checked with the npm clients Foxglove itself is built on
# (foxglove_test.mjs): robotalk-web's Foxglove endpoint, with and without a
# key, and `robotalk-logplay export --mcap` of the session recorded meanwhile,
# compared with the same log's CSV export.
# Two servers on two LCM URLs: an open one (recorded, watched by a bridge
# without a key, given the robot's URDF: its scene is the URDF's geometry)
# and a keyed one (its bridge holds a key with query and panic rights, and
# no URDF: its scene is the equivalent inertia boxes). Runs inside a private network namespace (netns_run.sh):
#   foxglove_test.sh SERVER CLI WEB LOGPLAY KEYGEN MODELS_DIR
set -u
server_bin=$1 cli=$2 web=$3 logplay=$4 keygen=$5 models=$6
url="udpm://239.255.76.67:7857?ttl=0"
keyed_url="udpm://239.255.76.67:7858?ttl=0"
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../lib.sh"
command -v node >/dev/null || { echo "FAIL: node not found (scripts/setup.sh installs it)"; exit 1; }
[ -d "$here/../../tools/web/node_modules/@foxglove/ws-protocol" ] ||
  { echo "FAIL: tools/web/node_modules has no @foxglove/ws-protocol (scripts/setup.sh runs npm ci)"; exit 1; }
robot=pioneer

for k in server web alice; do "$keygen" --out "$tmp/$k" >/dev/null || exit 1; done
{ echo "$(cut -d' ' -f1 "$tmp/alice.pub") alice *=all"
  echo "$(cut -d' ' -f1 "$tmp/web.pub") web *=query,panic"; } >"$tmp/clients"
chmod 600 "$tmp/clients"
"$server_bin" --robot "$robot=kinematic:$models/pioneer2dx_pantilt.urdf" --url "$url" --duration 60 2>"$tmp/server.log" &
pids+=($!)
"$server_bin" --robot "$robot=kinematic:$models/pioneer2dx_pantilt.urdf" --url "$keyed_url" --duration 60 \
  --key "$tmp/server" --clients "$tmp/clients" 2>"$tmp/keyed.log" &
pids+=($!)
for _ in $(seq 50); do grep -q "serving robot" "$tmp/server.log" && grep -q "serving robot" "$tmp/keyed.log" && break; sleep 0.1; done

# Record before the bridge connects, so its CONFIG query's answer is logged.
"$logplay" record -o "$tmp/session.lcmlog" --lcm-url "$url" -c 'ROBOTALK/.*' 2>"$tmp/record.log" &
logger=$!
wait_for "$tmp/record.log" "recording"

# The robot's URDF as the bridge and the export get it: the shipped pioneer
# with a material on base_link's visual and the caster's collision sphere
# replaced by a mesh of the web tests' package (tests/web/data/mesh_bot).
mesh="$here/data/mesh_bot/meshes/arm.stl"
urdf="$tmp/pioneer_geometry.urdf"
python3 - "$models/pioneer2dx_pantilt.urdf" "$urdf" <<'PY' || { echo "FAIL: cannot write $urdf"; exit 1; }
import sys, xml.etree.ElementTree as ET
tree = ET.parse(sys.argv[1]); robot = tree.getroot()
red = ET.Element("material", name="signal_red"); ET.SubElement(red, "color", rgba="0.8 0.1 0.1 1")
robot.insert(0, red)
link = {l.get("name"): l for l in robot.findall("link")}
ET.SubElement(link["base_link"].find("visual"), "material", name="signal_red")
geometry = link["caster"].find("collision/geometry")
geometry.remove(geometry.find("sphere"))
ET.SubElement(geometry, "mesh", filename="package://mesh_bot/meshes/arm.stl", scale="0.5 0.5 0.5")
tree.write(sys.argv[2])
PY
geometry_opts=(--urdf "$robot=$urdf" --package-path "$here/data")

start_web() {  # start_web OUT URL [env...] -- [web options...]: sets $web_port (not in a subshell: lib.sh stops $pids)
  local out=$1 u=$2 envs=(); shift 2
  while [ $# -gt 0 ] && [ "$1" != "--" ]; do envs+=("$1"); shift; done
  shift
  env "${envs[@]}" "$web" --port 0 --lcm-url "$u" "$@" >"$out" 2>&1 &
  pids+=($!)
  web_port=""
  for _ in $(seq 50); do web_port=$(grep -o '127.0.0.1:[0-9]*' "$out" | cut -d: -f2); [ -n "$web_port" ] && break; sleep 0.1; done
}
start_web "$tmp/web.out" "$url" -- "${geometry_opts[@]}"
port=$web_port
start_web "$tmp/keyed_web.out" "$keyed_url" ROBOTALK_KEY="$tmp/web" --
keyed_port=$web_port
check "both bridges listen" test -n "$port" -a -n "$keyed_port"

# Some traffic to record: a short sequence while Foxglove watches.
cat >"$tmp/seq.txt" <<'SEQ'
0.0 setspeed 0.3 0.2
0.0 joint_setpoint pan 0.4
0.8 joint_setpoint tilt -0.2
1.2 stop
SEQ
"$cli" --url "$url" send "$robot" --file "$tmp/seq.txt" >"$tmp/send.out" 2>&1 &
sender=$!
node "$here/foxglove_test.mjs" live "$port" "$robot" "$keyed_port" "$mesh"
check "Foxglove live (foxglove_test.mjs live)" test $? -eq 0
wait "$sender"
check "the recorded sequence succeeds: $(cat "$tmp/send.out")" test "$(grep -c SUCCESS "$tmp/send.out")" -eq 4
sleep 0.3
kill -INT "$logger"; wait "$logger"
check "record stops with status 0: $(cat "$tmp/record.log")" test $? -eq 0

"$logplay" export "$tmp/session.lcmlog" --mcap "$tmp/session.mcap" >"$tmp/export.out" 2>"$tmp/export.err"
check "export --mcap exits 0: $(cat "$tmp/export.err")" test $? -eq 0
check "export --mcap says what it wrote" grep -q "wrote [0-9]* messages" "$tmp/export.err"
"$logplay" export "$tmp/session.lcmlog" -o "$tmp/csv" --no-plot >/dev/null 2>&1
check "the CSV export of the same log" test -s "$tmp/csv/state.csv"
node "$here/foxglove_test.mjs" mcap "$tmp/session.mcap" "$tmp/csv/state.csv" "$tmp/csv/commands.csv" "$robot"
check "Foxglove from MCAP (foxglove_test.mjs mcap)" test $? -eq 0

"$logplay" export "$tmp/session.lcmlog" --mcap "$tmp/geometry.mcap" "${geometry_opts[@]}" >/dev/null 2>"$tmp/geometry.err"
check "export --mcap --urdf exits 0: $(cat "$tmp/geometry.err")" test $? -eq 0
node "$here/foxglove_test.mjs" mcap-scene "$tmp/geometry.mcap" "$robot" "$mesh"
check "Foxglove from MCAP, given the URDF (foxglove_test.mjs mcap-scene)" test $? -eq 0
"$logplay" export "$tmp/session.lcmlog" --mcap "$tmp/x.mcap" --urdf "$robot=$tmp/none.urdf" >/dev/null 2>"$tmp/nourdf.err"
check "export --mcap with a missing --urdf file fails with status 2" test $? -eq 2
check "and names the file: $(cat "$tmp/nourdf.err")" grep -q "none.urdf" "$tmp/nourdf.err"

"$logplay" export "$tmp/session.lcmlog" --mcap "$tmp/no/such/dir/x.mcap" >/dev/null 2>"$tmp/bad.err"
check "an unwritable --mcap path fails with status 1" test $? -eq 1
check "and names the file: $(cat "$tmp/bad.err")" grep -q "no/such/dir/x.mcap" "$tmp/bad.err"

echo "foxglove: $pass passed, $failures failed"
[ "$failures" -eq 0 ]
