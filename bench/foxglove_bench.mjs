// The Foxglove endpoint's latency as a Foxglove client sees it
// (bench/foxglove_bench.sh): subscribes to every channel of ROBOT for
// SECONDS and prints one JSON line: latency_us {n, p50, p99, mean, max} of
// the joint states (arrival on CLOCK_MONOTONIC, process.hrtime, minus the
// message's timestamp, the sample's server time on the same clock), and the
// messages per second on all channels.
//   node foxglove_bench.mjs PORT ROBOT SECONDS
import { createRequire } from "node:module";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";

const require = createRequire(join(dirname(fileURLToPath(import.meta.url)), "../tools/web/package.json"));
const { FoxgloveClient } = require("@foxglove/ws-protocol");
const WebSocket = require("ws");
const [port, robot, seconds] = process.argv.slice(2);
const client = new FoxgloveClient({ ws: new WebSocket(`ws://127.0.0.1:${port}/`, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
const topics = new Map();
const lat = [];
let messages = 0;
let counting = false;
client.on("advertise", (channels) => {
  for (const c of channels) if (c.topic.startsWith(`/${robot}/`)) topics.set(client.subscribe(c.id), c.topic);
});
client.on("message", ({ subscriptionId, timestamp }) => {
  const now = process.hrtime.bigint();
  if (!counting) return;
  messages++;
  if (topics.get(subscriptionId) === `/${robot}/joint_states`) lat.push(Number(now - timestamp) / 1e3);
});
setTimeout(() => (counting = true), 1000);  // after the subscriptions settle
setTimeout(() => {
  lat.sort((a, b) => a - b);
  const q = (p) => (lat.length ? lat[Math.min(lat.length - 1, Math.max(0, Math.ceil(p * lat.length) - 1))] : 0);
  const mean = lat.reduce((s, x) => s + x, 0) / Math.max(1, lat.length);
  console.log(JSON.stringify({ latency_us: { n: lat.length, p50: q(0.5), p99: q(0.99), mean, max: lat.at(-1) ?? 0 },
                               messages_per_s: messages / Number(seconds) }));
  process.exit(0);
}, 1000 + Number(seconds) * 1000);
