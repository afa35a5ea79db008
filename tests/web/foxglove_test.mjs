// robotalk-web's Foxglove endpoint as Foxglove sees it (docs/interop.md),
// through the npm @foxglove/ws-protocol client (what Foxglove's own
// connection speaks) over the npm ws WebSocket:
//   node foxglove_test.mjs live PORT ROBOT KEYED_PORT|- MESH
//     PORT: a bridge WITHOUT a key: serverInfo offers no services; the
//     robot's five channels are advertised with their JSON Schemas; scene,
//     transforms, joint states, base pose and status arrive and agree with
//     each other; a service call is refused.
//     The bridge at PORT was given the robot's URDF (--urdf, foxglove_test.sh
//     writes it from models/pioneer2dx_pantilt.urdf with a material and a
//     collision mesh): its scene is the URDF's geometry (checkUrdfScene), sent
//     once per subscription, and the mesh's URL serves the mesh's bytes.
//     KEYED_PORT: a bridge holding a key: /robotalk/panic is offered, a call
//     puts ROBOT in panic, and its status channel then says so; it has no
//     URDF, so its scene is the equivalent inertia boxes, and says so.
//   node foxglove_test.mjs mcap FILE.mcap STATE.csv COMMANDS.csv ROBOT
//     the MCAP export of a recorded session read back with @mcap/core (both
//     the indexed reader, as Foxglove opens a file, and the linear stream
//     reader): the same channels and schemas as live, one joint state per
//     logged STATE sample with its log time and positions, every logged
//     command among the requests; no --urdf: the scene is inertia boxes.
//   node foxglove_test.mjs mcap-scene FILE.mcap ROBOT MESH
//     an export given the URDF (--urdf): the scene is the URDF's geometry,
//     the mesh embedded (its bytes are MESH's).
// Prints "ok - ..." / "not ok - ..." lines; exits 1 on any failure.
import { createRequire } from "node:module";
import { readFileSync, openSync, readSync, fstatSync } from "node:fs";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";

const here = dirname(fileURLToPath(import.meta.url));
const require = createRequire(join(here, "../../tools/web/package.json"));
let failures = 0;
function check(what, ok, detail = "") {
  console.log(`${ok ? "ok" : "not ok"} - ${what}${ok || !detail ? "" : `: ${detail}`}`);
  if (!ok) failures++;
}
const TOPICS = {
  tf: "foxglove.FrameTransforms",
  scene: "foxglove.SceneUpdate",
  joint_states: "robotalk.JointState",
  base_pose: "foxglove.PoseInFrame",
  status: "robotalk.RobotStatus",
};
const decoder = new TextDecoder();

function connect(port) {
  const { FoxgloveClient } = require("@foxglove/ws-protocol");
  const WebSocket = require("ws");
  const ws = new WebSocket(`ws://127.0.0.1:${port}/`, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
  const client = new FoxgloveClient({ ws });
  const seen = { info: null, channels: [], services: [], messages: new Map(), statuses: [], responses: [], failures: [] };
  client.on("serverInfo", (i) => (seen.info = i));
  client.on("advertise", (cs) => seen.channels.push(...cs));
  client.on("advertiseServices", (s) => seen.services.push(...s));
  client.on("status", (s) => seen.statuses.push(s));
  client.on("serviceCallResponse", (r) => seen.responses.push(r));
  client.on("serviceCallFailure", (f) => seen.failures.push(f));
  client.on("error", (e) => console.log(`# client error: ${e.message ?? e}`));
  const topicOf = new Map();
  client.on("message", ({ subscriptionId, timestamp, data }) => {
    const topic = topicOf.get(subscriptionId);
    const list = seen.messages.get(topic) ?? [];
    list.push({ timestamp, json: JSON.parse(decoder.decode(data)) });
    seen.messages.set(topic, list);
  });
  return { client, seen, subscribe: (c) => topicOf.set(client.subscribe(c.id), c.topic), ws };
}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
async function until(what, cond, ms = 8000) {
  const end = Date.now() + ms;
  while (Date.now() < end) {
    if (cond()) return true;
    await sleep(50);
  }
  return false;
}

const near = (a, b, tol = 1e-5) => Math.abs(a - b) <= tol;
const nearVec = (v, [x, y, z]) => v && near(v.x, x) && near(v.y, y) && near(v.z, z);
const meta = (e, key) => e?.metadata?.find((m) => m.key === key)?.value;

// The scene of the robot foxglove_test.sh serves with its URDF: collision
// shapes as primitives posed in the link frame, a link without <collision>
// drawn from its <visual>, the material's colour, the caster's collision mesh
// as a model whose bytes `meshBytes(model)` returns.
async function checkUrdfScene(scene, robot, meshFile, meshBytes) {
  const entity = (link) => scene?.entities.find((e) => e.id === `${robot}/${link}`);
  const base = entity("base_link"), wheel = entity("left_wheel"), caster = entity("caster"), ptu = entity("ptu_base");
  const cube = base?.cubes?.[0];
  check("URDF scene: base_link is its collision box (0.44 x 0.38 x 0.22 at -0.1 0 0.17), in the material's colour",
        base && base.frame_id === `${robot}/base_link` && base.frame_locked && base.cubes.length === 1 &&
        nearVec(cube.size, [0.44, 0.38, 0.22]) && nearVec(cube.pose.position, [-0.1, 0, 0.17]) &&
        near(cube.color.r, 0.8) && near(cube.color.g, 0.1) && near(cube.color.b, 0.1) && near(cube.color.a, 1) &&
        meta(base, "geometry") === "urdf collision" && base.spheres.length === 0, JSON.stringify(base));
  const cyl = wheel?.cylinders?.[0];
  const s = Math.SQRT1_2;
  check("URDF scene: left_wheel is its collision cylinder (r 0.0975, length 0.05, axis turned onto y)",
        wheel && wheel.cylinders.length === 1 && wheel.cubes.length === 0 && nearVec(cyl.size, [0.195, 0.195, 0.05]) &&
        near(Math.abs(cyl.pose.orientation.x), s) && near(Math.abs(cyl.pose.orientation.w), s) &&
        near(cyl.bottom_scale, 1) && near(cyl.top_scale, 1), JSON.stringify(wheel));
  const model = caster?.models?.[0];
  check("URDF scene: caster's collision mesh is a model (scale 0.5, STL)",
        caster && caster.models.length === 1 && caster.spheres.length === 0 && nearVec(model.scale, [0.5, 0.5, 0.5]) &&
        model.media_type === "model/stl", JSON.stringify(caster));
  const bytes = model ? await meshBytes(model) : null;
  const want = readFileSync(meshFile);
  check("URDF scene: the model's mesh is the URDF's file, byte for byte",
        bytes && Buffer.compare(Buffer.from(bytes), want) === 0, `${bytes?.length} vs ${want.length} bytes`);
  const ptuCube = ptu?.cubes?.[0];
  check("URDF scene: ptu_base, which has no <collision>, is its visual box (0.08 x 0.07 x 0.06)",
        ptu && ptu.cubes.length === 1 && nearVec(ptuCube.size, [0.08, 0.07, 0.06]) && nearVec(ptuCube.pose.position, [0, 0, 0.03]) &&
        meta(ptu, "geometry") === "urdf visual", JSON.stringify(ptu));
  check("URDF scene: no entity is an inertia box",
        scene && scene.entities.length > 0 && scene.entities.every((e) => meta(e, "geometry") !== "inertia box"),
        JSON.stringify(scene?.entities.map((e) => [e.id, meta(e, "geometry")])));
}

function checkInertiaScene(scene, robot) {
  check("without a URDF the scene is one equivalent inertia box per link, and says so",
        scene && scene.entities.length > 0 && scene.entities.every((e) => e.frame_locked && e.frame_id.startsWith(`${robot}/`) &&
          e.cubes.length === 1 && meta(e, "geometry") === "inertia box" && /--urdf/.test(meta(e, "note") ?? "")),
        JSON.stringify(scene)?.slice(0, 400));
}

async function live(port, robot, keyedPort, meshFile) {
  const c = connect(port);
  check("serverInfo arrives", await until("serverInfo", () => c.seen.info));
  check("a bridge without a key offers no services", !(c.seen.info?.capabilities ?? []).includes("services"),
        JSON.stringify(c.seen.info));
  check(`the ${robot} channels are advertised`,
        await until("channels", () => c.seen.channels.filter((ch) => ch.topic.startsWith(`/${robot}/`)).length === 5),
        JSON.stringify(c.seen.channels.map((ch) => ch.topic)));
  for (const [name, schemaName] of Object.entries(TOPICS)) {
    const ch = c.seen.channels.find((x) => x.topic === `/${robot}/${name}`);
    check(`/${robot}/${name} is ${schemaName}, JSON with a JSON Schema`,
          ch && ch.schemaName === schemaName && ch.encoding === "json" && ch.schemaEncoding === "jsonschema" &&
          JSON.parse(ch.schema).type === "object", JSON.stringify(ch));
    if (ch) c.subscribe(ch);
  }
  const got = (t) => c.seen.messages.get(`/${robot}/${t}`) ?? [];
  check("every channel delivers", await until("messages", () => Object.keys(TOPICS).every((t) => got(t).length >= 3 || (t === "scene" && got(t).length >= 1))),
        Object.keys(TOPICS).map((t) => `${t}=${got(t).length}`).join(" "));
  const scene = got("scene")[0]?.json;
  const js = got("joint_states").at(-1)?.json;
  const tf = got("tf").at(-1)?.json;
  const status = got("status").at(-1)?.json;
  check("the scene has one entity per link, each locked to its link's frame",
        scene && scene.entities.length > 0 && scene.entities.every((e) => e.frame_locked && e.frame_id.startsWith(`${robot}/`)),
        JSON.stringify(scene)?.slice(0, 300));
  await checkUrdfScene(scene, robot, meshFile, async (m) => {
    const r = await fetch(m.url);
    return r.ok ? new Uint8Array(await r.arrayBuffer()) : null;
  });
  const linkFrames = new Set(scene?.entities.map((e) => e.frame_id));
  const children = new Set(tf?.transforms.map((t) => t.child_frame_id));
  check("the transforms reach every link of the scene from 'world'",
        tf && [...linkFrames].every((f) => children.has(f)) && tf.transforms.some((t) => t.parent_frame_id === "world"),
        JSON.stringify(tf)?.slice(0, 300));
  check("joint states name every position", js && js.name.length === js.position.length && js.name.length > 0 && js.robot === robot,
        JSON.stringify(js));
  const t = got("joint_states").at(-1);
  check("a message's timestamp is its sample's server time",
        t && BigInt(t.json.timestamp.sec) * 1000000000n + BigInt(t.json.timestamp.nsec) === t.timestamp,
        t && `${JSON.stringify(t.json.timestamp)} vs ${t.timestamp}`);
  check("status carries panic, moving and the base", status && status.panic === false && status.base.length === 5, JSON.stringify(status));
  // The robot moves (foxglove_test.sh sends pan 0.4): the joint states follow.
  const pan = () => {
    const last = got("joint_states").at(-1)?.json;
    return last ? last.position[last.name.indexOf("pan")] : NaN;
  };
  check("joint states follow the robot (pan reaches its set-point 0.4)",
        await until("pan", () => Math.abs(pan() - 0.4) < 0.01), `pan=${pan()}`);
  const lastOf = (topic) => got(topic).at(-1);
  await until("same sample", () => lastOf("base_pose")?.timestamp === lastOf("status")?.timestamp);
  const bp = lastOf("base_pose"), st = lastOf("status");
  check("base pose and status of one sample agree on x and y",
        bp && st && bp.timestamp === st.timestamp && Math.abs(bp.json.pose.position.x - st.json.base[0]) < 1e-5 &&
        Math.abs(bp.json.pose.position.y - st.json.base[1]) < 1e-5, `${JSON.stringify(bp?.json.pose)} vs ${JSON.stringify(st?.json.base)}`);
  check("the scene was sent once (on subscribing), not with each state",
        got("scene").length === 1 && got("joint_states").length >= 3, `${got("scene").length} scenes, ${got("joint_states").length} joint states`);
  // No key: a call is refused with a reason (the protocol's serviceCallFailure).
  c.client.sendServiceCallRequest({ serviceId: 1, callId: 7, encoding: "json", data: new TextEncoder().encode(`{"robot":"${robot}"}`) });
  check("a service call to a bridge without a key is refused, naming the key",
        await until("failure", () => c.seen.failures.length > 0) && /ROBOTALK_KEY/.test(c.seen.failures[0].message),
        JSON.stringify(c.seen.failures));
  c.client.close();
  if (keyedPort === "-") return;

  const k = connect(keyedPort);
  check("a bridge holding a key offers /robotalk/panic",
        await until("services", () => k.seen.services.some((s) => s.name === "/robotalk/panic")) &&
        k.seen.info.capabilities.includes("services"), JSON.stringify(k.seen.info));
  await until("channels", () => k.seen.channels.some((ch) => ch.topic === `/${robot}/status`));
  k.subscribe(k.seen.channels.find((ch) => ch.topic === `/${robot}/status`));
  k.subscribe(k.seen.channels.find((ch) => ch.topic === `/${robot}/scene`));
  await until("status", () => (k.seen.messages.get(`/${robot}/status`) ?? []).length > 0);
  await until("scene", () => (k.seen.messages.get(`/${robot}/scene`) ?? []).length > 0);
  checkInertiaScene(k.seen.messages.get(`/${robot}/scene`)?.[0]?.json, robot);
  const service = k.seen.services.find((s) => s.name === "/robotalk/panic");
  k.client.sendServiceCallRequest({ serviceId: service.id, callId: 1, encoding: "json", data: new TextEncoder().encode(`{"robot":"nosuchrobot"}`) });
  check("PANIC of an unknown robot fails, naming it",
        await until("failure", () => k.seen.failures.length > 0) && /nosuchrobot/.test(k.seen.failures[0].message), JSON.stringify(k.seen.failures));
  k.client.sendServiceCallRequest({ serviceId: service.id, callId: 2, encoding: "json", data: new TextEncoder().encode(`{"robot":"${robot}"}`) });
  check("PANIC through the service is acknowledged",
        await until("response", () => k.seen.responses.length > 0) && JSON.parse(decoder.decode(k.seen.responses[0].data)).ok === true,
        JSON.stringify(k.seen.failures));
  check("the status channel then shows the robot in panic",
        await until("panic", () => (k.seen.messages.get(`/${robot}/status`) ?? []).at(-1)?.json.panic === true));
  k.client.close();
}

function parseCsv(path) {
  const [head, ...rows] = readFileSync(path, "utf8").trim().split("\n");
  const cols = head.split(",");
  return rows.map((r) => Object.fromEntries(r.split(",").map((v, i) => [cols[i], v])));
}

async function mcap(file, stateCsv, commandsCsv, robot) {
  const { McapIndexedReader, McapStreamReader } = require("@mcap/core");
  const fd = openSync(file, "r");
  const readable = {
    size: async () => BigInt(fstatSync(fd).size),
    read: async (offset, size) => {
      const b = Buffer.alloc(Number(size));
      readSync(fd, b, 0, Number(size), Number(offset));
      return new Uint8Array(b.buffer, b.byteOffset, b.length);
    },
  };
  const reader = await McapIndexedReader.Initialize({ readable });
  check("the file is indexed (chunk indexes, statistics)", reader.chunkIndexes.length > 0 && reader.statistics !== undefined);
  const channels = [...reader.channelsById.values()];
  for (const [name, schemaName] of Object.entries({ ...TOPICS, requests: "robotalk.Request", replies: "robotalk.ReplyBatch" })) {
    const ch = channels.find((c) => c.topic === `/${robot}/${name}`);
    const schema = ch && reader.schemasById.get(ch.schemaId);
    check(`/${robot}/${name} is ${schemaName} (json, jsonschema)`,
          ch && ch.messageEncoding === "json" && schema.name === schemaName && schema.encoding === "jsonschema", JSON.stringify(ch));
  }
  const byTopic = new Map();
  for await (const m of reader.readMessages()) {
    const topic = reader.channelsById.get(m.channelId).topic;
    const list = byTopic.get(topic) ?? [];
    list.push({ logTime: m.logTime, publishTime: m.publishTime, json: JSON.parse(decoder.decode(m.data)) });
    byTopic.set(topic, list);
  }
  const total = [...byTopic.values()].reduce((n, l) => n + l.length, 0);
  check("the statistics count every message", BigInt(total) === reader.statistics.messageCount, `${total} vs ${reader.statistics.messageCount}`);
  // The linear reader (no index) sees the same messages.
  const stream = new McapStreamReader();
  stream.append(readFileSync(file));
  let linear = 0;
  for (let r; (r = stream.nextRecord()); ) if (r.type === "Message") linear++;
  check("a linear read finds the same messages", linear === total && stream.done(), `${linear} vs ${total}`);

  const states = parseCsv(stateCsv).filter((s) => s.robot === robot);
  const js = byTopic.get(`/${robot}/joint_states`) ?? [];
  check("one joint state per logged STATE sample", js.length === states.length && js.length > 0, `${js.length} vs ${states.length}`);
  const dofCols = Object.keys(states[0] ?? {}).slice(10);
  let mismatch = "";
  js.forEach((m, i) => {
    const s = states[i];
    if (!s || mismatch) return;
    if (m.logTime !== BigInt(s.log_time_us) * 1000n) mismatch = `#${i} log time ${m.logTime} vs ${s.log_time_us} us`;
    else if (m.publishTime !== BigInt(s.server_time_us) * 1000n) mismatch = `#${i} publish time ${m.publishTime} vs ${s.server_time_us} us`;
    else if (dofCols.some((c, d) => Math.abs(Number(s[c]) - m.json.position[d]) > 2e-6)) mismatch = `#${i} positions ${m.json.position} vs ${dofCols.map((c) => s[c])}`;
    else if (m.json.name.join() !== dofCols.join()) mismatch = `#${i} names ${m.json.name} vs ${dofCols}`;
  });
  check("each joint state has its sample's log time, server time, names and positions", !mismatch, mismatch);
  const status = byTopic.get(`/${robot}/status`) ?? [];
  check("status follows the logged panic flag", status.length === states.length &&
        status.every((m, i) => String(m.json.panic ? 1 : 0) === states[i].panic || String(m.json.panic) === states[i].panic),
        `${status.length} vs ${states.length}`);
  check("scene and transforms are there", (byTopic.get(`/${robot}/scene`) ?? []).length >= 1 && (byTopic.get(`/${robot}/tf`) ?? []).length === states.length);
  checkInertiaScene(byTopic.get(`/${robot}/scene`)?.[0]?.json, robot);
  const requests = byTopic.get(`/${robot}/requests`) ?? [];
  const sent = new Set(requests.flatMap((r) => r.json.commands.map((c) => `${r.json.client}/${r.json.sequence}/${c.id}`)));
  const logged = parseCsv(commandsCsv).filter((c) => c.robot === robot && c.mode !== "panic");
  check("every logged command is among the requests", logged.length > 0 && logged.every((c) => sent.has(`${c.client}/${c.sequence}/${c.id}`)),
        `${logged.length} logged, ${sent.size} in requests`);
  const replies = (byTopic.get(`/${robot}/replies`) ?? []).flatMap((b) => b.json.replies);
  check("the replies include the commands' SUCCESS", replies.filter((r) => r.signal === "SUCCESS").length >= logged.length,
        `${replies.length} replies`);
  const times = [...byTopic.values()].flat().map((m) => m.logTime);
  check("log times lie within the recording", times.every((t) => t > 1600000000000000000n));
}

async function mcapScene(file, robot, meshFile) {
  const { McapStreamReader } = require("@mcap/core");
  const stream = new McapStreamReader();
  stream.append(readFileSync(file));
  const channels = new Map();
  const scenes = [];
  let states = 0;
  for (let r; (r = stream.nextRecord()); ) {
    if (r.type === "Channel") channels.set(r.id, r.topic);
    if (r.type !== "Message") continue;
    const topic = channels.get(r.channelId);
    if (topic === `/${robot}/scene`) scenes.push(JSON.parse(decoder.decode(r.data)));
    if (topic === `/${robot}/joint_states`) states++;
  }
  check("the export holds one scene per logged configuration, not one per state",
        scenes.length >= 1 && scenes.length < states, `${scenes.length} scenes, ${states} states`);
  await checkUrdfScene(scenes[0], robot, meshFile, async (m) => (m.data ? Buffer.from(m.data, "base64") : null));
}

const [mode, ...args] = process.argv.slice(2);
if (mode === "live") await live(args[0], args[1], args[2] ?? "-", args[3]);
else if (mode === "mcap") await mcap(...args);
else if (mode === "mcap-scene") await mcapScene(...args);
else {
  console.log("usage: foxglove_test.mjs live PORT ROBOT KEYED_PORT|- MESH | mcap FILE STATE.csv COMMANDS.csv ROBOT | mcap-scene FILE ROBOT MESH");
  process.exit(2);
}
process.exit(failures ? 1 : 0);
