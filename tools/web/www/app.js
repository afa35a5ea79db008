// The robotalk-web page: one card per robot announced on the bus, fed by the
// bridge's WebSocket (docs/web.md, "Messages"). It reconnects by itself and
// says so when the bridge or a robot goes away.
import { RobotView } from './robot_view.js';
import { JointPlot } from './joint_plot.js';

const cards = new Map();  // robot name -> card state
let socket = null;
let retryMs = 500;
let frame = 0;            // animation frames drawn
let maxFrameLag = 0;      // most frames between a state's arrival and its drawing
let statesDrawn = 0, statesReplaced = 0;
let maxDrawDelayMs = 0;     // longest time from a state's arrival to the frame drawing it
const frameTimes = [];

const $ = (sel, root = document) => root.querySelector(sel);

function setConnection(text, cls) {
  const c = $('#connection');
  c.textContent = text;
  c.className = 'pill ' + cls;
}

function banner(text) {
  const b = $('#banner');
  b.hidden = !text;
  b.textContent = text || '';
}

function connect() {
  const ws = new WebSocket(`${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/ws`);
  socket = ws;
  ws.onopen = () => {
    retryMs = 500;
    // A restarted bridge numbers its models from 1 again: take its models as
    // new. What the page knew through the old connection (a panic it sent)
    // is not current any more; the bridge's robots list says what is.
    for (const c of cards.values()) {
      c.generation = -1;
      c.panicResult = null;
      showMessage(c);
    }
    setConnection('bridge connected', 'ok');
    banner('');
  };
  ws.onmessage = (ev) => onMessage(JSON.parse(ev.data));
  ws.onclose = () => {
    if (socket !== ws) return;
    setConnection('bridge lost', 'bad');
    banner(`Lost the connection to robotalk-web — reconnecting in ${(retryMs / 1000).toFixed(1)} s…` +
           ' (the robots shown are the last known state)');
    for (const c of cards.values()) {  // nothing on the card is known now
      c.el.classList.add('gone');
      c.el.classList.remove('in-panic');
      setStatus(c, 'bridge lost', 'bad');
      $('.driver', c.el).textContent = c.info ? c.info.driver : '';
      $('.panic-state', c.el).hidden = true;
      $('button.panic', c.el).disabled = true;
      c.panicResult = null;
      c.info = c.info && { ...c.info, status: 'unknown', panic: false, message: '' };
      showMessage(c);
    }
    setTimeout(connect, retryMs);
    retryMs = Math.min(5000, retryMs * 2);
  };
}

function onMessage(m) {
  if (m.type === 'robots') updateRobots(m.robots);
  else if (m.type === 'model') setModel(m);
  else if (m.type === 'state') onState(m);
  else if (m.type === 'panic_result') {
    const c = cards.get(m.robot);
    if (!c) return;
    c.panicResult = { text: m.ok ? 'PANIC sent and acknowledged.' : 'PANIC failed: ' + m.message,
                      ok: m.ok, at: performance.now(), server: c.info && c.info.server_id, seenPanic: false };
    c.panicRequested = false;
    showMessage(c);
  }
}

// A panic result stays while it describes the robot: until the panic is
// reset, the robot's server changes or it goes away (a failure: 10 s, or
// until then).
const PANIC_RESULT_UNSEEN_MS = 5000, PANIC_FAILURE_MS = 10000;
function panicResultCurrent(c, r) {
  const p = c.panicResult;
  if (!p || !r) return false;
  if (r.status !== 'live' || (p.server && r.server_id !== p.server)) return false;
  const age = performance.now() - p.at;
  if (!p.ok) return age < PANIC_FAILURE_MS;
  if (r.panic) p.seenPanic = true;
  return r.panic || (!p.seenPanic && age < PANIC_RESULT_UNSEEN_MS);  // the list may not say panic yet
}

// The card's message line, from the current state only.
function showMessage(c) {
  const r = c.info;
  if (c.panicResult && !panicResultCurrent(c, r)) c.panicResult = null;
  const parts = [];
  if (c.panicRequested && !c.panicResult) parts.push('PANIC requested…');
  if (c.panicResult) parts.push(c.panicResult.text);
  if (r && r.status === 'live' && r.message) parts.push(r.message);
  $('.message', c.el).textContent = parts.join(' ');
}

function setStatus(c, text, cls) {
  const status = $('.status', c.el);
  status.textContent = text;
  status.className = 'pill status ' + cls;
}

function card(name) {
  let c = cards.get(name);
  if (c) return c;
  const el = $('#card-template').content.firstElementChild.cloneNode(true);
  el.dataset.robot = name;
  $('.name', el).textContent = name;
  $('button.panic', el).addEventListener('click', () => {
    if (socket && socket.readyState === WebSocket.OPEN) {
      socket.send(JSON.stringify({ type: 'panic', robot: name }));
      c.panicResult = null;
      c.panicRequested = true;
      showMessage(c);
    }
  });
  $('#robots').append(el);
  c = { name, el, info: null, view: null, plot: null, generation: -1, pending: null, arrivalFrame: 0, drawn: null,
        panicResult: null, panicRequested: false };
  cards.set(name, c);
  return c;
}

function updateRobots(list) {
  $('#empty').hidden = list.length > 0;
  for (const r of list) {
    const c = card(r.name);
    c.info = r;
    const live = r.status === 'live';
    setStatus(c, r.status, { live: 'ok', connecting: 'wait' }[r.status] || 'bad');
    // Clients and panic are what the robot's announces say: only while it is heard.
    $('.driver', c.el).textContent = live || r.status === 'connecting'
      ? `${r.driver} · ${r.num_clients} client${r.num_clients === 1 ? '' : 's'}` : `${r.driver} · not announced`;
    $('.panic-state', c.el).hidden = !(live && r.panic);
    c.el.classList.toggle('in-panic', live && r.panic);
    c.el.classList.toggle('gone', r.status === 'gone' || r.status === 'error');
    $('button.panic', c.el).disabled = !live;
    if (c.panicResult || !live) c.panicRequested = false;
    const overlay = $('.overlay', c.el);
    const lost = { gone: `Robot gone: ${r.message}. Waiting for it to be announced again…`,
                   error: `Cannot reach the robot: ${r.message}. Retrying…`,
                   connecting: c.view ? '' : 'Loading the configuration…' }[r.status];
    overlay.hidden = !lost;
    overlay.textContent = lost || '';
    showMessage(c);
  }
}

function setModel(m) {
  const c = card(m.robot);
  if (c.generation === m.generation) return;
  c.generation = m.generation;
  if (c.view) c.view.dispose();
  c.model = m.model;
  const urdf = c.info && c.info.urdf;
  c.view = new RobotView($('.view', c.el), m.model, urdf, urdf ? `/meshes/${encodeURIComponent(m.robot)}` : null);
  const note = $('.mesh-note', c.el);
  note.hidden = true;
  c.view.onNote = (text) => { note.textContent = text; note.hidden = !text; };
  c.plot = new JointPlot($('.plot', c.el), $('.plot-joints', c.el), m.model.dof_names, m.model.joints);
  c.pending = null;
  c.drawn = null;
}

function onState(s) {
  const c = cards.get(s.robot);
  if (!c || !c.view || s.generation !== c.generation) return;
  if (c.pending) ++statesReplaced;
  c.pending = s;
  c.arrivalFrame = frame;
  c.arrivalTime = performance.now();
  c.plot.add(s.t, s.q);
}

function readout(c, s) {
  const [x, y, th, v, w] = s.base;
  return `sample ${s.sample}  t ${s.t.toFixed(2)} s  x ${x.toFixed(3)} y ${y.toFixed(3)} θ ${th.toFixed(3)}  ` +
         `v ${v.toFixed(2)} ω ${w.toFixed(2)}  path ${c.view.pathLength.toFixed(2)} m` + (s.moving ? '  moving' : '') +
         (s.link ? `  link ${s.link}` : '');
}

function animate(now) {
  ++frame;
  frameTimes.push(now);
  while (frameTimes.length && frameTimes[0] < now - 2000) frameTimes.shift();
  for (const c of cards.values()) {
    if (!c.view) continue;
    if (c.pending) {
      c.view.apply(c.pending);
      maxFrameLag = Math.max(maxFrameLag, frame - c.arrivalFrame);
      maxDrawDelayMs = Math.max(maxDrawDelayMs, now - c.arrivalTime);
      ++statesDrawn;
      c.drawn = { sample: c.pending.sample, frame, state: c.pending };
      $('.readout', c.el).textContent = readout(c, c.pending);
      const live = c.info && c.info.status === 'live';
      $('.panic-state', c.el).hidden = !(live && (c.pending.panic || c.info.panic));
      c.pending = null;
      c.plot.draw();
    }
    c.view.render();
  }
  if (frame % 30 === 0) $('#fps').textContent = `${fps().toFixed(0)} frames/s`;
  requestAnimationFrame(animate);
}

function fps() {
  if (frameTimes.length < 2) return 0;
  return (frameTimes.length - 1) * 1000 / (frameTimes[frameTimes.length - 1] - frameTimes[0]);
}

// A small hook for the browser test (tests/web/page_test.mjs) and for anyone
// checking the page from the console.
window.robotalkTest = {
  connected: () => !!socket && socket.readyState === WebSocket.OPEN,
  robots: () => [...cards.values()].map((c) => ({ name: c.name, status: c.info && c.info.status,
    panic: !!(c.info && c.info.panic), hasView: !!c.view, urdf: !!(c.view && c.view.urdfRobot),
    overlay: $('.overlay', c.el).hidden ? '' : $('.overlay', c.el).textContent,
    // What a person reads on the card, and whether it fits inside it.
    statusText: $('.status', c.el).textContent, driverText: $('.driver', c.el).textContent,
    message: $('.message', c.el).textContent, panicPill: !$('.panic-state', c.el).hidden,
    meshNote: $('.mesh-note', c.el).hidden ? '' : $('.mesh-note', c.el).textContent,
    overflow: [...c.el.querySelectorAll('.card-head, .readout, .message, .mesh-note, .plot-joints')].filter((e) => {
      const box = e.getBoundingClientRect(), card = c.el.getBoundingClientRect();
      return e.scrollWidth > e.clientWidth + 1 || box.right > card.right + 0.5;
    }).map((e) => e.className) })),
  // The URDF view of a robot: meshes drawn, the problems noted, which links
  // show the configuration's shapes, and mesh geometry per URDF link.
  meshes: (name) => {
    const c = cards.get(name);
    const v = c && c.view;
    if (!v) return null;
    if (!v.urdfRobot) return { loaded: 0, problems: v.meshProblems, geometry: {}, fallbackLinks: [], error: v.urdfError || 'not loaded' };
    const geometry = {};
    for (const [link, obj] of Object.entries(v.urdfRobot.links)) {
      let vertices = 0;
      for (const visual of obj.children.filter((ch) => ch.isURDFVisual)) {
        visual.traverse((o) => { if (o.isMesh && o.geometry) vertices += o.geometry.attributes.position.count; });
      }
      geometry[link] = vertices;
    }
    return { loaded: v.meshesLoaded, problems: v.meshProblems, geometry,
             fallbackLinks: c.model.links.filter((l, i) => v.linkObjects[i].visible).map((l) => l.name) };
  },
  // The newest drawn state of a robot and the poses the scene graph holds for it.
  drawn: (name) => {
    const c = cards.get(name);
    if (!c || !c.drawn) return null;
    const s = c.drawn.state;
    const root = c.model.roots[0].link;
    return { sample: s.sample, t: s.t, frame: c.drawn.frame, base: s.base, q: s.q, panic: s.panic,
             sentRoot: s.links[root], drawnRoot: c.view.drawnLinkPose(root),
             sentLinks: s.links, drawnLinks: c.model.links.map((l, i) => c.view.drawnLinkPose(i)),
             pathLength: c.view.pathLength, pathPoints: c.view.pathCount,
             plotted: c.plot.lastDrawn, pending: !!c.pending };
  },
  stats: () => ({ frame, fps: fps(), maxFrameLag, maxDrawDelayMs, statesDrawn, statesReplaced }),
  ready: async (name) => { const c = cards.get(name); if (c && c.view && c.view.loading) await c.view.loading; return !!(c && c.view); },
};

connect();
requestAnimationFrame(animate);
