// The robotalk-web page tested as a person uses it: a real robotalk-server,
// the bridge and headless Chromium (Debian's, driven by chromedriver); the
// robot is driven with the robotalk CLI and the page is read through its
// window.robotalkTest hook. Screenshots are saved for a person to look at.
//
//   node page_test.mjs pioneer|arms|meshes   (env: see the run_page_test.sh header)
//
// Run it inside a private network namespace (scripts/netns_run.sh): it uses
// LCM multicast on the loopback and listens on 127.0.0.1 only.
import { spawn, execFile } from 'node:child_process';
import { writeFileSync, mkdirSync } from 'node:fs';
import http from 'node:http';
import { WebDriver } from './webdriver.mjs';

const E = process.env;
const scenario = process.argv[2];
const children = new Set();
const t0 = Date.now();
const log = (...a) => console.log(`[${((Date.now() - t0) / 1000).toFixed(1)} s]`, ...a);
let failures = 0;
function check(ok, what, detail = '') {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}${detail ? ': ' + detail : ''}`);
  if (!ok) ++failures;
}
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

function start(cmd, args, name) {
  const p = spawn(cmd, args, { stdio: ['ignore', 'pipe', 'pipe'] });
  p.name = name;
  p.out = '';
  p.stdout.on('data', (d) => { p.out += d; });
  p.stderr.on('data', (d) => { p.err = (p.err || '') + d; });
  children.add(p);
  p.on('exit', () => children.delete(p));
  return p;
}
async function stop(p) {
  if (p.exitCode !== null || p.signalCode !== null) return;
  const gone = new Promise((r) => p.on('exit', r));
  p.kill('SIGTERM');
  await Promise.race([gone, sleep(3000)]);
  if (p.exitCode === null && p.signalCode === null) p.kill('SIGKILL');
}
process.on('exit', () => { for (const p of children) p.kill('SIGKILL'); });

function cli(...args) {
  return new Promise((resolve) => {
    execFile(E.ROBOTALK_CLI, args, { timeout: 30000 }, (err, stdout, stderr) =>
      resolve({ code: err ? (err.code ?? 1) : 0, out: stdout + stderr }));
  });
}

// Sanitizer builds run several times slower (scripts/sanitize.sh sets it).
const timeScale = Math.max(1, Number(process.env.ROBOTALK_TEST_TIME_SCALE) || 1);

async function waitFor(what, fn, unscaledMs) {
  const timeoutMs = unscaledMs * timeScale;
  const end = Date.now() + timeoutMs;
  let last;
  for (let i = 0; Date.now() < end && i < 1000 * timeScale; ++i) {
    last = await fn();
    if (last) return last;
    await sleep(100);
  }
  throw new Error(`timed out after ${timeoutMs} ms waiting for ${what}`);
}

function startServer(robots) {
  const args = ['--url', E.LCM_URL];
  for (const r of robots) args.push('--robot', r);
  return start(E.ROBOTALK_SERVER, args, 'robotalk-server');
}
async function startBridge(port, extra) {
  const b = start(E.ROBOTALK_WEB, ['--lcm-url', E.LCM_URL, '--port', String(port), '--robot-timeout', '2', ...extra], 'robotalk-web');
  const m = await waitFor('the bridge to print its URL', () => b.out.match(/open (http:\/\/127\.0\.0\.1:(\d+)\/)/), 10000);
  return { proc: b, url: m[1], port: Number(m[2]) };
}

// The CLI's independent view of the STATE stream: sample -> {base, q}.
function watch(robot) {
  const w = start(E.ROBOTALK_CLI, ['--url', E.LCM_URL, 'watch', robot, '--period', '0.02'], 'watch ' + robot);
  w.samples = new Map();
  let buf = '';
  w.stdout.on('data', (d) => {
    buf += d;
    const lines = buf.split('\n');
    buf = lines.pop();
    for (const line of lines) {
      const m = line.match(/^(\d+) t=(\S+) base (\S+) (\S+) (\S+) .* q (.*)$/);
      if (m) w.samples.set(Number(m[1]), { t: Number(m[2]), base: [m[3], m[4], m[5]].map(Number), q: m[6].trim().split(' ').map(Number) });
    }
  });
  return w;
}

async function openBrowser(url, size = '1200,900') {
  const port = 9515 + Math.floor(Math.random() * 400);
  start(E.CHROMEDRIVER, [`--port=${port}`, '--allowed-ips=127.0.0.1'], 'chromedriver');
  const wd = new WebDriver(`http://127.0.0.1:${port}`);
  await waitFor('chromedriver', () => fetch(`http://127.0.0.1:${port}/status`).then((r) => r.ok, () => false), 10000);
  // WebGL headless on the CPU: ANGLE over SwiftShader (no GPU on these machines).
  await wd.start(E.CHROMIUM, ['--headless=new', '--no-sandbox', '--disable-dev-shm-usage', `--window-size=${size}`,
    '--use-gl=angle', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist']);
  await wd.open(url);
  return wd;
}

async function shot(wd, name) {
  mkdirSync(E.OUT_DIR, { recursive: true });
  const file = `${E.OUT_DIR}/${name}`;
  writeFileSync(file, await wd.screenshot());
  log('screenshot', file);
}

const drawn = (wd, robot) => wd.run('return window.robotalkTest.drawn(arguments[0]);', robot);
const robots = (wd) => wd.run('return window.robotalkTest ? window.robotalkTest.robots() : [];');
const stats = (wd) => wd.run('return window.robotalkTest.stats();');
const near = (a, b, tol) => a.length === b.length && a.every((v, i) => Math.abs(v - b[i]) <= tol);
// Quaternions q and -q are the same rotation.
const samePose = (a, b, tol) => near(a.slice(0, 3), b.slice(0, 3), tol) &&
  (near(a.slice(3), b.slice(3), tol) || near(a.slice(3), b.slice(3).map((v) => -v), tol));

async function waitLive(wd, names, timeoutMs = 20000) {
  await waitFor(`${names.join(', ')} live on the page`, async () => {
    const rs = await robots(wd);
    return names.every((n) => rs.some((r) => r.name === n && r.status === 'live' && r.hasView));
  }, timeoutMs);
  for (const n of names) await wd.run('return window.robotalkTest.ready(arguments[0]);', n);
  await waitFor(`a state of ${names.join(', ')} drawn`, async () => {
    for (const n of names) if (!(await drawn(wd, n))) return false;
    return true;
  }, 10000);
}

// Polls the page while `action` runs; returns what the page drew.
async function observe(wd, robot, action, minMs = 0) {
  const seen = [];
  let done = false;
  const started = Date.now();
  const result = action().then((r) => { done = true; return r; });
  for (let i = 0; i < 600 && (!done || Date.now() - started < minMs); ++i) {
    seen.push(await drawn(wd, robot));
    await sleep(150);
  }
  return { seen, result: await result };
}

// What the page drew is the bridge's pose of that very STATE sample, and that
// sample is the one the CLI's watch received (an independent subscriber).
function checkFollows(robot, seen, w, withBase) {
  let compared = 0, baseMismatch = 0, qMismatch = 0, drawMismatch = 0;
  for (const d of seen) {
    if (!d) continue;
    if (!d.drawnLinks.every((p, i) => samePose(p, d.sentLinks[i], 2e-4))) ++drawMismatch;
    const ref = w.samples.get(d.sample);
    if (!ref) continue;
    ++compared;
    if (withBase && !near(d.base.slice(0, 3), ref.base, 6e-5)) ++baseMismatch;
    if (!d.q.every((v, i) => Math.abs(v - ref.q[i]) <= 1e-5 + 1e-5 * Math.abs(v))) ++qMismatch;
  }
  check(compared >= 5, `${robot}: drawn samples matched to the CLI's watch`, `${compared} of ${seen.length}`);
  check(drawMismatch === 0, `${robot}: every link is drawn where the state puts it (scene graph read back)`, `${drawMismatch} off`);
  if (withBase) check(baseMismatch === 0, `${robot}: the drawn base pose equals the STATE sample's x y θ`, `${baseMismatch} off`);
  check(qMismatch === 0, `${robot}: the page's joint positions equal the STATE sample's`, `${qMismatch} off`);
}

async function checkFrameLag(wd, robot, w) {
  const s = await stats(wd);
  check(s.maxFrameLag <= 1, 'every state is drawn in the first animation frame after it arrives',
    `max ${s.maxFrameLag} frame(s), ${s.maxDrawDelayMs.toFixed(1)} ms; ${s.fps.toFixed(1)} frames/s`);
  // Freshness: the page's newest sample against the newest the CLI has seen.
  const d = await drawn(wd, robot);
  const newest = Math.max(...w.samples.keys());
  const lag = w.samples.get(newest).t - d.t;
  check(lag < 1.0, `${robot}: the page is at most a few frames behind the stream`, `${(lag * 1000).toFixed(0)} ms behind the CLI's newest sample`);
  log('page stats', JSON.stringify(s));
}

async function pioneer() {
  const urdf = `${E.MODELS_DIR}/pioneer2dx_pantilt.urdf`;
  let server = startServer([`pioneer=ode:${urdf}`]);
  let bridge = await startBridge(0, ['--urdf', `pioneer=${urdf}`]);
  const wd = await openBrowser(bridge.url);
  try {
    await waitLive(wd, ['pioneer']);
    check((await robots(wd))[0].urdf, 'pioneer is drawn from its URDF by urdf-loader');
    const w = watch('pioneer');
    await waitFor('the CLI watch', () => w.samples.size > 0, 10000);
    // One CLI process for the head and the drive: a client that set the robot
    // moving and exits is stopped by the server's watchdog 2 s later.
    mkdirSync(E.OUT_DIR, { recursive: true });
    const seq = `${E.OUT_DIR}/pioneer_sequence.txt`;
    writeFileSync(seq, '0 joint_setpoint pan 0.6\n0 joint_setpoint tilt -0.3\n0 goto 1.0 0.4 0.8\n');
    const go = await observe(wd, 'pioneer', () => cli('--url', E.LCM_URL, 'send', 'pioneer', '--file', seq));
    check(go.result.code === 0, 'robotalk send pioneer --file: pan, tilt, goto 1.0 0.4 0.8', go.result.out.trim().replace(/\n/g, ' | '));
    const arc = await observe(wd, 'pioneer', () => cli('--url', E.LCM_URL, 'send', 'pioneer', 'setspeed', '0.35', '0.9'), 2500);
    await cli('--url', E.LCM_URL, 'send', 'pioneer', 'stop');
    await sleep(800);
    checkFollows('pioneer', [...go.seen, ...arc.seen], w, true);
    const d = await drawn(wd, 'pioneer');
    const q = await cli('--url', E.LCM_URL, 'query', 'pioneer', 'base_pose');
    const pose = (q.out.match(/-?\d+\.\d+(e-?\d+)?/g) || []).map(Number);
    check(pose.length >= 3 && Math.hypot(d.base[0] - pose[0], d.base[1] - pose[1]) < 0.03,
      'the page shows the base where robotalk query base_pose says', `page ${d.base.slice(0, 3).map((v) => v.toFixed(3))} query ${q.out.trim()}`);
    check(d.pathLength > 1.2, 'the base path is drawn on the floor', `${d.pathLength.toFixed(2)} m, ${d.pathPoints} points`);
    check(Math.abs((d.plotted.pan ?? NaN) - 0.6) < 0.05 && Math.abs((d.plotted.tilt ?? NaN) + 0.3) < 0.05,
      'the joint plot shows pan and tilt at their set-points', JSON.stringify(d.plotted));
    await checkFrameLag(wd, 'pioneer', w);
    await shot(wd, 'web_pioneer.png');

    const card = async () => (await robots(wd)).find((r) => r.name === 'pioneer');
    const panicNow = async (what) => {
      await wd.click('article[data-robot="pioneer"] button.panic');
      const c = await waitFor('the panic to show', async () => {
        const r = await card();
        return r && r.panic && r.panicPill && /PANIC sent and acknowledged/.test(r.message) ? r : null;
      }, 5000);
      check(true, `PANIC on the page shows "PANIC sent and acknowledged." and the PANIC pill (${what})`, c.message);
    };
    check(!(await card()).overflow.length, 'nothing on the card runs past its edge (readout, message, head)',
      JSON.stringify((await card()).overflow));
    await panicNow('before a reset');
    const refused = await cli('--url', E.LCM_URL, 'send', 'pioneer', 'goto', '0', '0', '0');
    check(/PANIC/.test(refused.out), 'after PANIC on the page, a CLI command is refused PANIC', refused.out.trim());
    await shot(wd, 'web_pioneer_panic.png');
    await cli('--url', E.LCM_URL, 'reset', 'pioneer');
    const reset = await waitFor('the panic to clear', async () => {
      const r = await card();
      return !r.panic && !r.panicPill ? r : null;
    }, 5000);
    check(!/PANIC/.test(reset.message), 'after PANIC_RESET the card no longer says PANIC sent', JSON.stringify(reset.message));

    // A bridge restart: the server is still in panic (the pill says so), the
    // message of the old connection is gone.
    await panicNow('before a bridge restart');
    await stop(bridge.proc);
    const banner = await waitFor('the page to say the bridge is gone', () =>
      wd.run('const b = document.querySelector("#banner"); return b.hidden ? "" : b.textContent;'), 5000);
    check(/Lost the connection/.test(banner), 'the page says when the bridge goes away', banner);
    const lostCard = await card();
    check(lostCard.statusText === 'bridge lost' && !/client/.test(lostCard.driverText) && !lostCard.panicPill &&
      !/PANIC sent/.test(lostCard.message), 'without the bridge the card claims no status, clients or panic',
      JSON.stringify(lostCard));
    bridge = await startBridge(bridge.port, ['--urdf', `pioneer=${urdf}`]);
    await waitLive(wd, ['pioneer'], 20000);
    const back = await waitFor('the panic pill from the new bridge', async () => {
      const r = await card();
      return r.panicPill ? r : null;
    }, 5000);
    check(!/PANIC sent/.test(back.message), 'after a bridge restart the old "PANIC sent" is gone; the pill shows the server\'s panic',
      JSON.stringify(back.message));
    await cli('--url', E.LCM_URL, 'reset', 'pioneer');

    // A server restart: the robot goes away (no clients, no panic shown), then
    // comes back from a new server that is not in panic.
    await waitFor('the panic to clear', async () => !(await card()).panicPill, 5000);
    await panicNow('before a server restart');
    await stop(w);
    await stop(server);
    const gone = await waitFor('the page to say the robot is gone', async () => {
      const r = await card();
      return r.status === 'gone' && /Robot gone/.test(r.overlay) ? r : null;
    }, 8000);
    check(true, 'the page says when the robot goes away', gone.overlay);
    check(!/client/.test(gone.driverText) && !gone.panicPill && !/PANIC sent/.test(gone.message),
      'a gone robot shows no clients, no panic and no "PANIC sent"', JSON.stringify(gone));
    // The new server starts in the panic it latched (docs/server.md): the
    // pill says so, the old acknowledgement does not come back.
    server = startServer([`pioneer=ode:${urdf}`]);
    await waitLive(wd, ['pioneer'], 20000);
    const fresh = await waitFor('the restarted robot\'s latched panic', async () => {
      const r = await card();
      return r.panicPill ? r : null;
    }, 5000);
    check(!/PANIC sent/.test(fresh.message) && /client/.test(fresh.driverText),
      'the restarted robot shows its own state: clients, its latched panic, not the old acknowledgement', JSON.stringify(fresh));
    await cli('--url', E.LCM_URL, 'reset', 'pioneer');
    check(await wd.run('return window.robotalkTest.connected();'), 'the page reconnects by itself to the restarted bridge and robot');
  } finally {
    await wd.quit();
  }
}

async function arms() {
  const iiwa = `${E.SHARED_ROBOTS}/iiwa14.urdf`, atlas = `${E.SHARED_ROBOTS}/atlas.urdf`;
  startServer([`pioneer=ode:${E.MODELS_DIR}/pioneer2dx_pantilt.urdf`, `iiwa=ode:${iiwa}`,
               `humanoid=ode:${atlas},base=floating,solver=quickstep`]);
  // The iiwa from its URDF: none of its package://drake_models meshes is here.
  const bridge = await startBridge(0, ['--urdf', `iiwa=${iiwa}`]);
  const wd = await openBrowser(bridge.url, '1700,1000');
  try {
    await waitLive(wd, ['pioneer', 'iiwa', 'humanoid'], 30000);
    const w = watch('iiwa');
    const wh = watch('humanoid');
    await waitFor('the CLI watches', () => w.samples.size > 0 && wh.samples.size > 0, 10000);
    const moves = [['iiwa', 'iiwa_joint_2', 0.9], ['iiwa', 'iiwa_joint_4', -1.2], ['iiwa', 'iiwa_joint_1', 0.7],
                   ['humanoid', 'l_arm_shz', -0.8], ['humanoid', 'r_arm_shz', 0.8]];
    mkdirSync(E.OUT_DIR, { recursive: true });
    const seq = `${E.OUT_DIR}/pioneer_arc.txt`;
    writeFileSync(seq, '0 joint_setpoint pan 0.5\n0 setspeed 0.4 0.7\n3 stop\n');
    const seen = await observe(wd, 'iiwa', async () => {
      const arc = cli('--url', E.LCM_URL, 'send', 'pioneer', '--file', seq);
      for (const [r, j, v] of moves) await cli('--url', E.LCM_URL, 'send', r, 'joint_setpoint', j, String(v));
      return arc;
    }, 3000);
    const seenH = await observe(wd, 'humanoid', () => sleep(2000));
    checkFollows('iiwa', seen.seen, w, false);
    checkFollows('humanoid', seenH.seen, wh, true);
    const d = await drawn(wd, 'iiwa');
    check(Math.abs(d.plotted.iiwa_joint_2 - 0.9) < 0.05 && Math.abs(d.plotted.iiwa_joint_1 - 0.7) < 0.05,
      'the iiwa plot shows joints 1 and 2 at their set-points', JSON.stringify(d.plotted));
    await checkFrameLag(wd, 'iiwa', w);
    const p = await drawn(wd, 'pioneer');
    check(p.pathLength > 0.8, 'the Pioneer\'s arc is drawn on the floor', `${p.pathLength.toFixed(2)} m`);
    // Issue 21: the iiwa card was an empty floor.
    const m = await wd.run('return window.robotalkTest.meshes(arguments[0]);', 'iiwa');
    const unresolved = m.problems.filter((x) => /package 'drake_models' not found/.test(x.error));
    check(m.problems.length > 0 && unresolved.length === m.problems.length,
      'every iiwa mesh is reported unresolved, naming its package', `${unresolved.length} of ${m.problems.length}`);
    const meshLinks = [...new Set(m.problems.flatMap((x) => x.link.split(', ')))];
    check(meshLinks.length >= 7 && meshLinks.every((l) => m.fallbackLinks.includes(l)),
      'each link whose mesh did not resolve is drawn from the configuration', `${m.fallbackLinks.length} links: ${m.fallbackLinks.join(' ')}`);
    const iiwaCard = (await robots(wd)).find((r) => r.name === 'iiwa');
    check(/not drawn/.test(iiwaCard.meshNote) && /package:\/\/drake_models\//.test(iiwaCard.meshNote),
      'the iiwa card says which meshes are not drawn', iiwaCard.meshNote);
    await shot(wd, 'web_robots.png');
  } finally {
    await wd.quit();
  }
}

// Issue 21: a URDF of our own (tests/web/data/mesh_bot) naming its meshes
// with package://, a relative ../ path, a package that is not there and a
// path that climbs out of every folder; the bridge gets --package-path.
async function meshes() {
  const data = new URL('./data', import.meta.url).pathname;
  const urdf = `${data}/mesh_bot/urdf/mesh_bot.urdf`;
  startServer([`meshbot=kinematic:${urdf}`]);
  const bridge = await startBridge(0, ['--urdf', `meshbot=${urdf}`, '--package-path', data]);
  const said = await waitFor('the bridge to name the unresolved meshes', () =>
    /meshbot: 2 of 4 meshes not resolved/.test(bridge.proc.err || '') && bridge.proc.err, 5000);
  check(/meshbot: link 'tool': mesh package:\/\/missing_pkg\/meshes\/tool.stl: package 'missing_pkg' not found/.test(said),
    'the bridge names an unresolved mesh on stderr', said.split('\n')[0]);
  const wd = await openBrowser(bridge.url);
  try {
    await waitLive(wd, ['meshbot']);
    const m = await wd.run('return window.robotalkTest.meshes(arguments[0]);', 'meshbot');
    check(m.loaded === 2 && m.geometry.arm > 0 && m.geometry.base_link > 0,
      'the package:// and the relative ../ meshes are loaded and drawn', JSON.stringify({ loaded: m.loaded, geometry: m.geometry, error: m.error }));
    check(m.geometry.tool === 0 && m.geometry.probe === 0, 'the unresolved meshes draw nothing of the URDF', JSON.stringify(m.geometry));
    check(JSON.stringify(m.fallbackLinks.sort()) === '["probe","tool"]',
      'exactly the links whose meshes did not resolve show the configuration\'s shapes', JSON.stringify(m.fallbackLinks));
    const byUri = Object.fromEntries(m.problems.map((x) => [x.uri, x.error]));
    check(/package 'missing_pkg' not found in the package paths/.test(byUri['package://missing_pkg/meshes/tool.stl'] || ''),
      'a missing package is named', byUri['package://missing_pkg/meshes/tool.stl']);
    const climb = Object.keys(byUri).find((u) => /etc\/passwd/.test(u));
    check(/^refused: .* is outside the package paths and the URDF's folder/.test(byUri[climb] || ''),
      'a mesh name that climbs out of the package is refused, not served', byUri[climb]);
    const r = (await robots(wd))[0];
    check(/2 meshes not drawn/.test(r.meshNote) && /missing_pkg/.test(r.meshNote), 'the card notes the meshes not drawn', r.meshNote);
    const w = watch('meshbot');
    await waitFor('the CLI watch', () => w.samples.size > 0, 10000);
    const seen = await observe(wd, 'meshbot', async () => {
      await cli('--url', E.LCM_URL, 'send', 'meshbot', 'joint_setpoint', 'shoulder', '0.8');
      return cli('--url', E.LCM_URL, 'send', 'meshbot', 'joint_setpoint', 'wrist', '1.2');
    }, 1500);
    checkFollows('meshbot', seen.seen, w, false);
    await shot(wd, 'web_meshes.png');

    // What the bridge serves, asked without a browser (which would normalise "../" away).
    const get = (path) => new Promise((resolve) => {
      http.get({ host: '127.0.0.1', port: bridge.port, path }, (res) => {
        let body = '';
        res.on('data', (d) => { body += d; });
        res.on('end', () => resolve({ status: res.statusCode, body }));
      }).on('error', (e) => resolve({ status: 0, body: String(e) }));
    });
    const catalog = JSON.parse((await get('/meshes/meshbot')).body);
    const arm = catalog.meshes.find((x) => x.link === 'arm');
    const stl = await get(arm.url);
    check(stl.status === 200 && stl.body.startsWith('solid arm'), `the resolved mesh is served at ${arm.url}`, stl.status);
    for (const path of ['/mesh/meshbot/../../../../etc/passwd', '/urdf/meshbot/../../../../../../etc/passwd',
                        '/mesh/meshbot/1/%2e%2e/%2e%2e/etc/passwd', '/..%2f..%2fetc/passwd']) {
      const res = await get(path);
      check(res.status === 403 && /path traversal/.test(res.body) && !/root:/.test(res.body),
        `path traversal is refused with a clear error: ${path}`, `${res.status} ${res.body.trim()}`);
    }
    const other = await get(`/mesh/meshbot/${catalog.meshes.findIndex((x) => x.link === 'probe')}/passwd`);
    check(other.status === 404 && !/root:/.test(other.body), 'a refused mesh is not served under its index', other.status);
    await stop(w);
  } finally {
    await wd.quit();
  }
}

const scenarios = { pioneer, arms, meshes };
if (!scenarios[scenario]) {
  console.error('usage: node page_test.mjs pioneer|arms|meshes');
  process.exit(2);
}
const limit = setTimeout(() => { console.error('FAIL: the test took longer than 140 s'); process.exit(1); }, 140000);
try {
  await scenarios[scenario]();
} catch (e) {
  check(false, 'scenario ran to its end', e.message);
  for (const p of children) if (p.err) console.error(`--- ${p.name} stderr (tail):\n${p.err.slice(-1500)}`);
}
clearTimeout(limit);
const passed = failures === 0;
console.log(`${scenario}: ${passed ? 'PASS' : 'FAIL'} (${((Date.now() - t0) / 1000).toFixed(1)} s)`);
for (const p of children) p.kill('SIGTERM');
process.exit(passed ? 0 : 1);
