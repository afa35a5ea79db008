// RobotView: one robot drawn in 3D with three.js, in its own canvas.
//
// The robot is built either from its RoboTalk configuration (default: each
// link's equivalent-inertia box at its centre of mass, bones to its joint
// centres, axes at its control frames — the configuration carries no visual
// geometry), or from a URDF file by urdf-loader when the bridge was given one
// (--urdf NAME=PATH); a link whose mesh the bridge could not resolve, or the
// page could not load, keeps the configuration's shapes, with a note. Either way it is posed from the bridge's state frames:
// world poses of every link (computed by the bridge with RoboTalk's own
// kinematics) and the joint positions. The base's path is drawn on the floor.
// Coordinates are RoboTalk's (z up, metres); one group turns them into
// three.js's y-up world.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { STLLoader } from 'three/examples/jsm/loaders/STLLoader.js';
import { ColladaLoader } from 'three/examples/jsm/loaders/ColladaLoader.js';
import { OBJLoader } from 'three/examples/jsm/loaders/OBJLoader.js';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import URDFLoader from 'urdf-loader';

const PATH_MAX_POINTS = 20000;
const PATH_MIN_STEP = 0.005;  // m between recorded path points

// A software WebGL (SwiftShader in headless Chromium, llvmpipe) draws several
// times faster without multisampling.
let software = null;
function softwareGl() {
  if (software === null) {
    const gl = document.createElement('canvas').getContext('webgl2');
    const info = gl && gl.getExtension('WEBGL_debug_renderer_info');
    software = !!info && /swiftshader|llvmpipe|software/i.test(gl.getParameter(info.UNMASKED_RENDERER_WEBGL));
  }
  return software;
}

// The floor: a 40 m square with a 1 m grid (0.25 m minor lines) drawn into a
// texture. Triangles, not GL lines: long lines passing behind the camera were
// dropped by SwiftShader's line clipping.
function floor() {
  const canvas = document.createElement('canvas');
  canvas.width = canvas.height = 256;
  const g = canvas.getContext('2d');
  g.fillStyle = '#141a22';
  g.fillRect(0, 0, 256, 256);
  g.strokeStyle = '#27313d';
  g.lineWidth = 2;
  for (let i = 1; i < 4; ++i) {
    g.beginPath(); g.moveTo(i * 64, 0); g.lineTo(i * 64, 256); g.moveTo(0, i * 64); g.lineTo(256, i * 64); g.stroke();
  }
  g.strokeStyle = '#4a5a6e';
  g.lineWidth = 4;
  g.strokeRect(0, 0, 256, 256);
  const texture = new THREE.CanvasTexture(canvas);
  texture.wrapS = texture.wrapT = THREE.RepeatWrapping;
  texture.repeat.set(40, 40);
  texture.anisotropy = 4;
  const plane = new THREE.Mesh(new THREE.PlaneGeometry(40, 40), new THREE.MeshBasicMaterial({ map: texture }));
  plane.rotation.x = -Math.PI / 2;
  plane.position.y = -0.001;
  return plane;
}

function quat(p) { return new THREE.Quaternion(p[4], p[5], p[6], p[3]); }

export class RobotView {
  constructor(container, model, urdfUrl, meshesUrl) {
    this.model = model;
    this.renderer = new THREE.WebGLRenderer({ antialias: !softwareGl() });
    this.renderer.setPixelRatio(1);
    this.renderer.setSize(container.clientWidth, container.clientHeight);
    container.prepend(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0x0d1117);
    this.camera = new THREE.PerspectiveCamera(45, container.clientWidth / container.clientHeight, 0.01, 200);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.scene.add(new THREE.HemisphereLight(0xeef4ff, 0x445566, 3.0));
    const sun = new THREE.DirectionalLight(0xffffff, 2.5);
    sun.position.set(3, 6, 4);
    this.scene.add(sun);
    this.world = new THREE.Group();  // RoboTalk's z-up frame
    this.world.rotation.x = -Math.PI / 2;
    this.scene.add(this.world);
    this.scene.add(floor());
    this.linkObjects = [];
    this.urdfRobot = null;
    this.loading = null;
    this.buildFromSpec();
    this.meshProblems = [];
    if (urdfUrl) this.loadUrdf(urdfUrl, meshesUrl);
    this.buildPath();
    this.framed = false;  // the camera is aimed once the first state has posed the links
    this.followBase = this.model.roots.length > 0 && this.model.roots[0].base !== 'fixed';
    this.camera.position.set(2, 1.5, 2.5);
  }

  buildFromSpec() {
    const boxMat = new THREE.MeshStandardMaterial({ color: 0x5fb0ff, roughness: 0.5, transparent: true, opacity: 0.9 });
    const jointMat = new THREE.MeshStandardMaterial({ color: 0xf5a623, roughness: 0.4 });
    const boneMat = new THREE.MeshStandardMaterial({ color: 0xc7d0dc, roughness: 0.5 });
    this.specGroup = new THREE.Group();
    this.world.add(this.specGroup);
    for (const link of this.model.links) {
      const g = new THREE.Group();
      g.name = link.name;
      g.matrixAutoUpdate = true;
      const com = new THREE.Vector3(...link.com);
      if (link.mass > 0) {
        const box = new THREE.Mesh(new THREE.BoxGeometry(...link.box), boxMat);
        box.position.copy(com);
        const r = link.box_rotation;
        box.quaternion.set(r[1], r[2], r[3], r[0]);
        g.add(box);
      }
      for (const p of link.points) {
        const pt = new THREE.Vector3(...p);
        const ball = new THREE.Mesh(new THREE.SphereGeometry(0.012, 12, 8), jointMat);
        ball.position.copy(pt);
        g.add(ball);
        const len = pt.distanceTo(com);
        if (len > 1e-4) {
          const bone = new THREE.Mesh(new THREE.CylinderGeometry(0.006, 0.006, len, 8), boneMat);
          bone.position.copy(com).add(pt).multiplyScalar(0.5);
          bone.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), pt.clone().sub(com).normalize());
          g.add(bone);
        }
      }
      this.specGroup.add(g);
      this.linkObjects.push(g);
    }
    for (const f of this.model.frames) {
      const axes = new THREE.AxesHelper(0.08);
      axes.position.set(f.pose[0], f.pose[1], f.pose[2]);
      axes.quaternion.copy(quat(f.pose));
      this.linkObjects[f.link].add(axes);
    }
  }

  // The URDF's own geometry, mesh by mesh: the bridge's catalog (/meshes/NAME,
  // docs/web.md "Meshes") says where each mesh filename is served, or why it
  // is not; a link whose mesh did not resolve or load keeps the
  // configuration's shapes, and `meshProblems` (shown under the view) names
  // the mesh and the reason.
  loadUrdf(url, meshesUrl) {
    this.meshProblems = [];
    this.meshesLoaded = 0;
    this.failedLinks = new Set();
    this.loading = this.loadUrdfAsync(url, meshesUrl).catch((err) => {
      this.urdfError = String(err.message || err);
      this.problem({ link: '', uri: url, error: 'the URDF did not load: ' + this.urdfError });
      return false;
    });
  }

  async loadUrdfAsync(url, meshesUrl) {
    // Without the catalog no mesh can be placed on its link: the whole URDF
    // is then given up and the configuration drawn (with the note).
    const catalog = await fetch(meshesUrl).then((r) => {
      if (!r.ok) throw new Error(`${meshesUrl}: HTTP ${r.status}`);
      return r.json();
    });
    const byUri = new Map();
    // The page draws the visuals; the collision meshes are Foxglove's scene's.
    for (const m of catalog.meshes.filter((e) => !e.collision)) byUri.set(m.uri, [...(byUri.get(m.uri) || []), m]);
    const text = await fetch(url).then((r) => {
      if (!r.ok) throw new Error(`${url}: HTTP ${r.status}`);
      return r.text();
    });
    const pending = [];
    const loader = new URDFLoader();
    loader.parseVisual = true;
    loader.parseCollision = false;
    loader.packages = (pkg) => 'package://' + pkg;  // filenames reach loadMeshCb as the URDF writes them
    loader.loadMeshCb = (path, manager, material, done) => {
      pending.push(this.loadMesh(path, byUri.get(path) || [], material).then((obj) => done(obj), (err) => done(null, err)));
    };
    const robot = loader.parse(text, '');
    this.urdfRobot = robot;
    this.world.add(robot);
    this.showFallback();
    if (this.lastFrame) this.apply(this.lastFrame);
    await Promise.all(pending);
    if (this.lastFrame) this.frameCamera();
    return true;
  }

  async loadMesh(uri, entries, material) {
    const links = entries.map((e) => e.link);
    const served = entries.find((e) => e.url);
    const fail = (error) => {
      this.problem({ link: links.join(', '), uri, error }, links);
      throw new Error(`${uri}: ${error}`);
    };
    if (!served) return fail(entries.length ? entries[0].error : 'not in the bridge\'s mesh catalog');
    if (!material || !material.name) material = new THREE.MeshStandardMaterial({ color: 0x6f93c8, roughness: 0.6 });
    const ext = (served.url.match(/\.([a-z0-9]+)$/i) || [])[1]?.toLowerCase();
    try {
      let obj;
      if (ext === 'stl') {
        const geometry = await new STLLoader().loadAsync(served.url);
        // Many STL files leave their facet normals zero: they would draw black.
        if (!geometry.attributes.normal || geometry.attributes.normal.array.every((v) => v === 0)) geometry.computeVertexNormals();
        obj = new THREE.Mesh(geometry, material);
      } else if (ext === 'dae') obj = (await new ColladaLoader().loadAsync(served.url)).scene;
      else if (ext === 'gltf' || ext === 'glb') obj = (await new GLTFLoader().loadAsync(served.url)).scene;
      else if (ext === 'obj') {
        obj = await new OBJLoader().loadAsync(served.url);
        obj.traverse((o) => { if (o.isMesh) o.material = material; });
      } else return fail(`the page draws .stl, .dae, .obj, .gltf and .glb meshes, not .${ext}`);
      ++this.meshesLoaded;
      return obj;
    } catch (err) {
      if (String(err.message || '').startsWith(uri + ':')) throw err;
      return fail(`${served.url}: ${err.message || err}`);
    }
  }

  problem(p, links = []) {
    this.meshProblems.push(p);
    for (const l of links) this.failedLinks.add(l);
    this.showFallback();
    if (this.onNote) this.onNote(this.meshNote());
  }

  // The configuration's shapes of exactly the links the URDF cannot draw.
  showFallback() {
    if (!this.urdfRobot) return;
    this.model.links.forEach((l, i) => {
      this.linkObjects[i].visible = this.failedLinks.has(l.name) || !this.urdfRobot.links[l.name];
    });
  }

  meshNote() {
    const n = this.meshProblems.length;
    if (n === 0) return '';
    const shown = this.meshProblems.slice(0, 2).map((p) => `${p.uri}${p.link ? ` (link ${p.link})` : ''}: ${p.error}`);
    return `${n} mesh${n === 1 ? '' : 'es'} not drawn; ${n === 1 ? 'its link is' : 'their links are'} shown ` +
           `as the configuration's shapes. ${shown.join('; ')}${n > 2 ? `; and ${n - 2} more` : ''}`;
  }

  buildPath() {
    const geom = new THREE.BufferGeometry();
    this.pathPositions = new Float32Array(PATH_MAX_POINTS * 3);
    geom.setAttribute('position', new THREE.BufferAttribute(this.pathPositions, 3));
    geom.setDrawRange(0, 0);
    this.path = new THREE.Line(geom, new THREE.LineBasicMaterial({ color: 0x5dffb0, depthTest: false }));
    this.path.frustumCulled = false;
    this.world.add(this.path);
    this.pathCount = 0;
    this.pathLength = 0;
  }

  frameCamera() {
    this.world.updateMatrixWorld(true);
    // The configuration's shapes always (meshes may be missing), with the URDF's.
    const box = new THREE.Box3().setFromObject(this.specGroup);
    if (this.urdfRobot) box.union(new THREE.Box3().setFromObject(this.urdfRobot));
    // A mobile base gets room around it for its path.
    const size = Math.max(this.followBase ? 2.2 : 1.0, box.getSize(new THREE.Vector3()).length());
    const centre = box.getCenter(new THREE.Vector3());
    this.controls.target.copy(centre);
    this.camera.position.copy(centre).add(new THREE.Vector3(0.75 * size, 0.6 * size, 1.1 * size));
    this.controls.update();
    this.framed = true;
  }

  // Applies one state frame from the bridge to the scene.
  apply(frame) {
    this.lastFrame = frame;
    const links = frame.links;
    for (let i = 0; i < this.linkObjects.length && i < links.length; ++i) {
      const p = links[i];
      this.linkObjects[i].position.set(p[0], p[1], p[2]);
      this.linkObjects[i].quaternion.copy(quat(p));
    }
    if (this.urdfRobot) this.applyUrdf(frame);
    this.extendPath(frame.base[0], frame.base[1]);
    if (!this.framed) this.frameCamera();
  }

  applyUrdf(frame) {
    const root = this.model.roots[0].link;
    const p = frame.links[root];
    this.urdfRobot.position.set(p[0], p[1], p[2]);
    this.urdfRobot.quaternion.copy(quat(p));
    for (const j of this.model.joints) {
      const uj = this.urdfRobot.joints[j.name];
      if (!uj || j.dofs.length === 0 || j.mimic) continue;
      uj.setJointValue(...frame.q.slice(j.dof_offset, j.dof_offset + j.dofs.length));
    }
  }

  extendPath(x, y) {
    if (this.pathCount > 0) {
      const k = 3 * (this.pathCount - 1);
      const d = Math.hypot(x - this.pathPositions[k], y - this.pathPositions[k + 1]);
      if (d < PATH_MIN_STEP) return;
      this.pathLength += d;
      if (this.followBase) {  // the camera follows the base
        const delta = new THREE.Vector3(x - this.pathPositions[k], 0, -(y - this.pathPositions[k + 1]));
        this.camera.position.add(delta);
        this.controls.target.add(delta);
      }
    }
    if (this.pathCount >= PATH_MAX_POINTS) {  // keep the newest half
      this.pathPositions.copyWithin(0, 3 * (PATH_MAX_POINTS / 2));
      this.pathCount = PATH_MAX_POINTS / 2;
    }
    this.pathPositions.set([x, y, 0.003], 3 * this.pathCount);
    this.pathCount += 1;
    this.path.geometry.setDrawRange(0, this.pathCount);
    this.path.geometry.attributes.position.needsUpdate = true;
  }

  render() {
    this.controls.update();
    this.renderer.render(this.scene, this.camera);
  }

  // World pose of link `i` as the scene graph holds it (z-up), read back from
  // the drawn objects: [x, y, z, qw, qx, qy, qz]. The URDF's own link object
  // when the robot is drawn from a URDF.
  drawnLinkPose(i) {
    let obj = this.linkObjects[i];
    if (this.urdfRobot && this.urdfRobot.links[this.model.links[i].name]) obj = this.urdfRobot.links[this.model.links[i].name];
    this.scene.updateMatrixWorld(true);
    const m = new THREE.Matrix4().copy(this.world.matrixWorld).invert().multiply(obj.matrixWorld);
    const t = new THREE.Vector3(), q = new THREE.Quaternion(), s = new THREE.Vector3();
    m.decompose(t, q, s);
    return [t.x, t.y, t.z, q.w, q.x, q.y, q.z];
  }

  dispose() {
    this.controls.dispose();
    this.renderer.dispose();
    this.renderer.forceContextLoss();
    this.renderer.domElement.remove();
  }
}
