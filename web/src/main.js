// The page `rccx view` serves: the robots in 3D (three.js), drawn from their chains (DH or URDF), with the
// tool path traced, named frames (the cell's, and the goals of the positions the program moves
// to, the running motion's marked), the cell's objects and capsules; live joint, Cartesian and
// velocity plots (uPlot) of each robot, one robot's at a time (the selector above them); and, for
// a recorded run (one robot's), a replay with a time slider.
//
// What the page draws is also in window.rccxView (for the end-to-end test): the joint values
// and time of the pose drawn, per robot, the goal each robot's running motion goes to, the
// frames drawn, which robot's plots are shown, how many points they hold, plotData(name):
// the last point of a robot's joint plot as uPlot holds it, back in rad / m, and
// plotSeries(name): how many points its uPlot plots hold, framesAt(name, q): the world frames
// the page computes for a robot at joint values q (base, links, tool), capsuleCount(name).
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { CSS2DRenderer, CSS2DObject } from 'three/examples/jsm/renderers/CSS2DRenderer.js';
import uPlot from 'uplot';
import 'uplot/dist/uPlot.min.css';
import './style.css';

const view = {
  ready: false,
  mode: 'live',
  errors: [],
  frames: 0,
  robots: [],
  plotPoints: { joints: 0, cart: 0, vel: 0 },  // the plots shown
  plotted: null,       // the name of the robot whose plots are shown
  plots: {},           // per robot name: its points { joints, cart, vel }
  frameNames: [],      // the frames drawn, "name" (the cell's) or "robot:name" (a goal)
  plotData: () => null,
  plotSeries: () => null,  // (name): the points in that robot's uPlot plots as drawn
  framesAt: () => null,    // (name, q): the frames the page computes, RobotView.framesAt
  capsuleCount: () => null,  // (name): how many collision capsules the page draws
};
window.rccxView = view;

const $ = (id) => document.getElementById(id);
const status = (text, bad = false) => {
  $('status').textContent = text;
  $('status').className = bad ? 'bad' : '';
};

// --- The live samples -----------------------------------------------------------------------
// The socket opens at once, beside the scene's request and the 3D set-up (seconds in software
// WebGL on a loaded machine): samples that come before the page can draw them wait in `queue`
// and are taken, in order, when it can (link.take). The status line says where the page is:
// loading the scene, connecting, waiting for samples, live, ended.
const pageRobot = location.pathname.match(/^\/robot\/([^/]+)$/);
const only = pageRobot ? decodeURIComponent(pageRobot[1]) : null;
const link = { ws: null, opened: false, queue: [], take: null, scene: false, samples: 0, ended: false };
function showLink() {
  if (view.errors.length || view.mode === 'replay') return;  // their own status lines
  if (link.ended) status(link.opened ? 'the program has ended (no more samples)'
    : `cannot connect to ${location.host}: is rccx view still running?`, true);
  else if (!link.scene) status(link.opened ? 'connected; loading the scene' : 'loading the scene');
  else if (!link.opened) status('connecting');
  else status(link.samples ? 'live' : 'connected; waiting for samples');
}
function openLink() {
  const ws = new WebSocket(`ws://${location.host}/ws${only ? `?robot=${encodeURIComponent(only)}` : ''}`);
  link.ws = ws;
  ws.onopen = () => { link.opened = true; showLink(); };
  ws.onclose = () => { link.ended = true; showLink(); };
  ws.onmessage = (ev) => {
    const msg = JSON.parse(ev.data);
    if (msg.type === 'hello' && msg.mode === 'replay') {
      ws.onclose = null;  // a replay has no live samples: its page reads /api/log
      ws.close();
      return;
    }
    if (msg.type !== 'frames') return;
    if (link.take) link.take(msg.frames);
    else link.queue.push(msg.frames);
  };
}
openLink();
showLink();

// --- Kinematics: one rule for DH and URDF chains, as rccx::kin::link_frames --------------------
// The scene gives each joint as a general chain step (rccx::view::to_json): frame i = frame i-1
// origin Motion(axis, q) after, a DH link being origin = I, axis z, after = Rz(theta) Tz(d)
// Tx(a) Rx(alpha).
function jointSteps(j) {
  return {
    origin: new THREE.Matrix4().fromArray(j.origin),
    axis: new THREE.Vector3(...j.axis).normalize(),
    after: new THREE.Matrix4().fromArray(j.after),
    via: new THREE.Vector3(...j.via),
  };
}
function motion(step, prismatic, q) {
  return prismatic
    ? new THREE.Matrix4().makeTranslation(step.axis.x * q, step.axis.y * q, step.axis.z * q)
    : new THREE.Matrix4().makeRotationAxis(step.axis, q);
}

/// base, base L1, base L1 L2, ... (dof + 1 frames); with `bends`, also where each drawn link
/// bends: the joint's origin and its `via` point (world).
function linkFrames(robot, q, bends = null) {
  const frames = [robot.baseMatrix.clone()];
  for (let i = 0; i < robot.joints.length; ++i) {
    const step = robot.steps[i];
    const atJoint = frames[i].clone().multiply(step.origin);
    const moved = atJoint.clone().multiply(motion(step, robot.joints[i].prismatic, q[i]));
    if (bends) {
      bends.push([new THREE.Vector3().setFromMatrixPosition(atJoint),
        step.via.clone().applyMatrix4(moved)]);
    }
    frames.push(moved.multiply(step.after));
  }
  return frames;
}

// --- Scene ----------------------------------------------------------------------------------
const container = $('scene');
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
container.appendChild(renderer.domElement);
const labels = new CSS2DRenderer();
labels.domElement.style.position = 'absolute';
labels.domElement.style.top = '0';
labels.domElement.style.pointerEvents = 'none';
container.appendChild(labels.domElement);

const scene = new THREE.Scene();
scene.background = new THREE.Color(0x15171c);
const camera = new THREE.PerspectiveCamera(45, 1, 0.01, 100);
camera.up.set(0, 0, 1);
camera.position.set(1.2, -1.4, 1.0);
const controls = new OrbitControls(camera, renderer.domElement);
controls.target.set(0, 0, 0.25);
controls.update();
scene.add(new THREE.HemisphereLight(0xffffff, 0x334455, 2.0));
const sun = new THREE.DirectionalLight(0xffffff, 1.5);
sun.position.set(2, -1, 3);
scene.add(sun);
const grid = new THREE.GridHelper(2, 20, 0x555a66, 0x30343c);
grid.rotation.x = Math.PI / 2;
scene.add(grid);
scene.add(new THREE.AxesHelper(0.15));

/// The canvas takes the pane's size; the pane's size comes from the layout (style.css), which
/// may change without a window resize (the panes stacked, the replay's footer shown).
function resize() {
  const w = container.clientWidth, h = container.clientHeight;
  renderer.setSize(w, h);
  labels.setSize(w, h);
  camera.aspect = w / Math.max(h, 1);
  camera.updateProjectionMatrix();
}
new ResizeObserver(resize).observe(container);
resize();

function label(text) {
  const div = document.createElement('div');
  div.className = 'label';
  div.textContent = text;
  return new CSS2DObject(div);
}

const Y = new THREE.Vector3(0, 1, 0);
/// A unit cylinder (height 1 along y) put between p0 and p1.
function placeBetween(mesh, p0, p1) {
  const dir = new THREE.Vector3().subVectors(p1, p0);
  const len = dir.length();
  mesh.visible = len > 1e-6;
  if (!mesh.visible) return;
  mesh.position.copy(p0).addScaledVector(dir, 0.5);
  mesh.quaternion.setFromUnitVectors(Y, dir.divideScalar(len));
  mesh.scale.y = len;
}

const colours = [0xe0a040, 0x50a0e0, 0x80d080, 0xd070d0];

class RobotView {
  constructor(desc, index) {
    this.name = desc.name;
    this.index = desc.index;
    this.goal = null;
    this.joints = desc.joints;
    this.steps = desc.joints.map(jointSteps);
    this.baseMatrix = new THREE.Matrix4().fromArray(desc.base);
    this.toolMatrix = desc.tool ? new THREE.Matrix4().fromArray(desc.tool) : new THREE.Matrix4();
    this.radii = desc.radii || [];
    // The links' size sets the drawing's scale.
    const offset = (m) => Math.hypot(m[12], m[13], m[14]);
    const reach = desc.joints.reduce((s, j) => s + offset(j.origin) + offset(j.after), 0) || 0.5;
    this.thick = Math.max(0.008, reach * 0.02);
    const colour = colours[index % colours.length];
    const linkMat = new THREE.MeshStandardMaterial({ color: colour, metalness: 0.2, roughness: 0.6 });
    const jointMat = new THREE.MeshStandardMaterial({ color: 0x30343c, metalness: 0.4, roughness: 0.5 });
    const capsuleMat = new THREE.MeshStandardMaterial({ color: 0xff5050, transparent: true,
      opacity: 0.3, depthWrite: false });
    this.group = new THREE.Group();
    scene.add(this.group);
    const cyl = new THREE.CylinderGeometry(1, 1, 1, 16);
    this.links = [];   // per joint: to the joint's origin, on to its via point, on to its frame
    this.jointMeshes = [];
    for (let i = 0; i < desc.joints.length; ++i) {
      const parts = [];
      for (let k = 0; k < 3; ++k) {
        const m = new THREE.Mesh(cyl, linkMat);
        m.scale.set(this.thick, 1, this.thick);
        this.group.add(m);
        parts.push(m);
      }
      this.links.push(parts);
      const jm = new THREE.Mesh(cyl, jointMat);
      jm.scale.set(this.thick * 1.6, this.thick * 3, this.thick * 1.6);
      this.group.add(jm);
      this.jointMeshes.push(jm);
    }
    // The collision model as the cell checks it (rccx::cell::RobotCapsules): the links' capsules
    // of the cell's radii, the robot's own (a URDF's <collision>), the shapes (pedestal, flange,
    // hand, tool); each in its frame (0: the base, i: link i's, the last: T6).
    this.capsules = (desc.capsules || []).map((k) => {
      const body = new THREE.Mesh(cyl, capsuleMat);
      body.scale.set(k.radius, 1, k.radius);
      const ends = [0, 1].map(() => new THREE.Mesh(new THREE.SphereGeometry(k.radius, 16, 12), capsuleMat));
      this.group.add(body, ...ends);
      return { k, body, ends, from: new THREE.Vector3(...k.from), to: new THREE.Vector3(...k.to) };
    });
    const baseMesh = new THREE.Mesh(cyl, jointMat);
    baseMesh.scale.set(this.thick * 3, this.thick * 1.5, this.thick * 3);
    baseMesh.quaternion.setFromUnitVectors(Y, new THREE.Vector3(0, 0, 1));
    baseMesh.position.setFromMatrixPosition(this.baseMatrix);
    baseMesh.applyMatrix4(new THREE.Matrix4().extractRotation(this.baseMatrix));
    baseMesh.position.setFromMatrixPosition(this.baseMatrix);
    this.group.add(baseMesh);
    this.tool = new THREE.AxesHelper(Math.max(0.05, reach * 0.12));
    this.tool.matrixAutoUpdate = false;
    this.group.add(this.tool);
    const nameLabel = label(desc.name);
    nameLabel.position.setFromMatrixPosition(this.baseMatrix);
    this.group.add(nameLabel);
    // The tool path: a line through the last points the tool passed.
    this.pathCapacity = 20000;
    this.pathPositions = new Float32Array(this.pathCapacity * 3);
    this.pathCount = 0;
    const pg = new THREE.BufferGeometry();
    pg.setAttribute('position', new THREE.BufferAttribute(this.pathPositions, 3));
    pg.setDrawRange(0, 0);
    this.path = new THREE.Line(pg, new THREE.LineBasicMaterial({ color: 0xffff66 }));
    this.path.frustumCulled = false;
    scene.add(this.path);
    this.state = { name: desc.name, t: null, q: desc.joints.map((j) => j.ready), seg: 0, goal: null };
    view.robots.push(this.state);
    this.pose(this.state.q);
  }

  /// Draws the arm at joint values q.
  pose(q) {
    const bends = [];
    const f = linkFrames(this, q, bends);
    const o = f.map((m) => new THREE.Vector3().setFromMatrixPosition(m));
    for (let i = 0; i < this.joints.length; ++i) {
      // Link i+1: to joint i+1's origin, on to its via point (a DH link's d part), on to its
      // frame (the a part; a chain's flange offset).
      const [at, via] = bends[i];
      placeBetween(this.links[i][0], o[i], at);
      placeBetween(this.links[i][1], at, via);
      placeBetween(this.links[i][2], via, o[i + 1]);
      const jm = this.jointMeshes[i];
      jm.position.copy(at);
      const axis = this.steps[i].axis.clone().transformDirection(f[i].clone().multiply(this.steps[i].origin));
      jm.quaternion.setFromUnitVectors(Y, axis);
    }
    for (const { k, body, ends, from, to } of this.capsules) {
      const frame = f[Math.min(k.frame, f.length - 1)];
      const p0 = from.clone().applyMatrix4(frame);
      let p1;
      if (k.motion === 'dh_prismatic') {  // the d part of a prismatic DH joint: d + q along z
        const z = new THREE.Vector3().setFromMatrixColumn(frame, 2);
        p1 = new THREE.Vector3().setFromMatrixPosition(frame).addScaledVector(z, this.joints[k.joint].d + q[k.joint]);
      } else if (k.motion === 'chain_prismatic') {  // a chain's prismatic travel along its axis
        p1 = p0.clone().add(to.clone().transformDirection(frame).multiplyScalar(q[k.joint] * to.length()));
      } else {
        p1 = to.clone().applyMatrix4(frame);
      }
      placeBetween(body, p0, p1);
      ends[0].position.copy(p0);
      ends[1].position.copy(p1);
    }
    this.tool.matrix.copy(f[f.length - 1]).multiply(this.toolMatrix);
  }

  /// The world frames the page computes at q (base, link 1 .. n, the tool), 16 numbers each,
  /// column-major: what the end-to-end test compares with the C++ forward kinematics.
  framesAt(q) {
    const f = linkFrames(this, q);
    f.push(f[f.length - 1].clone().multiply(this.toolMatrix));
    return f.map((m) => m.toArray());
  }

  addPathPoint(p) {
    if (this.pathCount === this.pathCapacity) {
      this.pathPositions.copyWithin(0, 3 * (this.pathCapacity / 2));
      this.pathCount = this.pathCapacity / 2;
    }
    this.pathPositions.set(p, 3 * this.pathCount++);
    this.path.geometry.setDrawRange(0, this.pathCount);
    this.path.geometry.attributes.position.needsUpdate = true;
  }

  clearPath() {
    this.pathCount = 0;
    this.path.geometry.setDrawRange(0, 0);
  }
}

function addObject(o) {
  let geometry;
  if (o.kind === 'box') {
    geometry = new THREE.BoxGeometry(o.size[0], o.size[1], o.size[2]);
  } else {
    geometry = new THREE.CylinderGeometry(o.radius, o.radius, o.height, 32);
    geometry.rotateX(Math.PI / 2);  // its axis is the pose's z
  }
  const mesh = new THREE.Mesh(geometry, new THREE.MeshStandardMaterial({
    color: 0x6a7080, transparent: true, opacity: 0.55 }));
  mesh.matrixAutoUpdate = false;
  mesh.matrix.fromArray(o.pose);
  scene.add(mesh);
  const l = label(o.name);
  l.position.setFromMatrixPosition(mesh.matrix);
  scene.add(l);
}

// A goal is its robot's: two robots may each have a "P1".
const frameObjects = new Map();
const activeGoals = new Set();  // the keys of the goals running motions go to
const frameKey = (robot, name) => (robot >= 0 ? `${robot}:${name}` : name);
/// Puts a frame at its pose, drawn larger and its label marked while a motion goes there.
function placeFrame(key, entry) {
  const on = activeGoals.has(key);
  const k = on ? 2 : 1;
  entry.axes.matrix.fromArray(entry.pose).multiply(new THREE.Matrix4().makeScale(k, k, k));
  entry.label.position.setFromMatrixPosition(entry.axes.matrix);
  entry.label.element.classList.toggle('active', on);
}
function addFrame(f, robotNames) {
  const key = frameKey(f.robot ?? -1, f.name);
  let entry = frameObjects.get(key);
  if (!entry) {
    const axes = new THREE.AxesHelper(0.06);
    axes.matrixAutoUpdate = false;
    scene.add(axes);
    const text = f.robot >= 0 && robotNames[f.robot] ? `${robotNames[f.robot]}: ${f.name}` : f.name;
    const l = label(text);
    scene.add(l);
    entry = { axes, label: l, pose: null };
    frameObjects.set(key, entry);
    view.frameNames.push(key);
  }
  // A goal moved to again with other values of its transforms moves its frame.
  if (entry.pose === null || entry.pose.some((v, i) => v !== f.pose[i])) {
    entry.pose = f.pose.slice();
    placeFrame(key, entry);
  }
  entry.label.element.title = f.note || f.name;
}
/// Marks the goal robot `r`'s running motion goes to, and unmarks its last one.
function markGoal(r, goal) {
  goal = goal || null;
  if (r.goal === goal) return;
  const before = r.goal ? frameKey(r.index, r.goal) : null;
  const now = goal ? frameKey(r.index, goal) : null;
  if (before) activeGoals.delete(before);
  if (now) activeGoals.add(now);
  for (const key of [before, now]) {
    const entry = key ? frameObjects.get(key) : null;
    if (entry) placeFrame(key, entry);
  }
  r.goal = goal;
  r.state.goal = goal;
}

// --- Plots ------------------------------------------------------------------------------------
const plotWidth = () => Math.max(200, $('plots').clientWidth - 12);
const axisStyle = { stroke: '#aab', grid: { stroke: '#2c3038' }, ticks: { stroke: '#2c3038' } };
const seriesColours = ['#e0a040', '#50a0e0', '#80d080', '#d070d0', '#e06060', '#60d0d0', '#c0c060', '#a080ff'];

function makePlot(el, title, names, unit) {
  const series = [{ label: 't s' }].concat(names.map((n, i) => ({
    label: n, stroke: seriesColours[i % seriesColours.length], width: 1.5,
  })));
  return new uPlot({
    title, width: plotWidth(), height: 170, series,
    scales: { x: { time: false } },
    axes: [{ ...axisStyle, label: 's' }, { ...axisStyle, label: unit, size: 55 }],
    legend: { live: true },
  }, [[], ...names.map(() => [])], el);
}

/// One robot's three plots, in their own group of the aside; only the group shown is drawn.
class Plots {
  constructor(robot, desc) {
    this.robot = robot;
    this.name = desc.name;
    this.units = desc.joints.map((j) => (j.prismatic ? 1000 : 180 / Math.PI));
    const names = desc.joints.map((j, i) => `q${i + 1} ${j.prismatic ? 'mm' : 'deg'}`);
    this.group = document.createElement('div');
    this.group.className = 'plot-group';
    this.group.dataset.robot = desc.name;
    this.group.hidden = true;
    const div = (kind) => {
      const d = document.createElement('div');
      d.className = `plot plot-${kind}`;
      this.group.appendChild(d);
      return d;
    };
    $('plot-groups').appendChild(this.group);
    this.shown = false;
    this.joints = makePlot(div('joints'), `${desc.name}: joints (measured)`, names, 'deg / mm');
    this.cart = makePlot(div('cart'), `${desc.name}: tool position (world)`, ['x', 'y', 'z'], 'mm');
    this.vel = makePlot(div('vel'), `${desc.name}: speeds`,
      desc.joints.map((j, i) => `qd${i + 1} ${j.prismatic ? 'mm/s' : 'deg/s'}`).concat(['tool mm/s']),
      'deg/s, mm/s');
    this.limit = 3000;
    this.data = {
      joints: [[], ...names.map(() => [])],
      cart: [[], [], [], []],
      vel: [[], ...names.map(() => []), []],
    };
    this.dirty = false;
  }
  push(f) {
    const n = this.units.length;
    const d = this.data;
    d.joints[0].push(f.t);
    d.cart[0].push(f.t);
    d.vel[0].push(f.t);
    for (let i = 0; i < n; ++i) {
      d.joints[i + 1].push(f.qm[i] * this.units[i]);
      d.vel[i + 1].push(f.qd[i] * this.units[i]);
    }
    d.vel[n + 1].push(f.v * 1000);
    for (let k = 0; k < 3; ++k) d.cart[k + 1].push(f.p[k] * 1000);
    for (const key of ['joints', 'cart', 'vel']) {
      if (d[key][0].length > this.limit) for (const a of d[key]) a.splice(0, a.length - this.limit);
    }
    this.dirty = true;
  }
  /// A whole recorded run (replay).
  setRun(log) {
    const n = this.units.length;
    const d = this.data;
    d.joints = [log.t, ...Array.from({ length: n }, (_, i) => log.qm.map((q) => q[i] * this.units[i]))];
    d.cart = [log.t, ...[0, 1, 2].map((k) => log.p.map((p) => p[k] * 1000))];
    const speed = log.p.map((p, i) => {
      if (i === 0) return 0;
      const a = log.p[i - 1], dt = log.t[i] - log.t[i - 1];
      return (1000 * Math.hypot(p[0] - a[0], p[1] - a[1], p[2] - a[2])) / dt;
    });
    const qd = Array.from({ length: n }, (_, i) => log.qm.map((q, k) => (k === 0 ? 0
      : ((q[i] - log.qm[k - 1][i]) * this.units[i]) / (log.t[k] - log.t[k - 1]))));
    d.vel = [log.t, ...qd, speed];
    this.dirty = true;
  }
  points() {
    return { joints: this.data.joints[0].length, cart: this.data.cart[0].length, vel: this.data.vel[0].length };
  }
  /// How many points each of the three uPlot plots holds now (what is drawn, not what is kept).
  drawn() {
    return { joints: this.joints.data[0].length, cart: this.cart.data[0].length, vel: this.vel.data[0].length };
  }
  /// Draws what came since the last flush; a hidden group only counts (drawn when shown).
  flush() {
    view.plots[this.name] = this.points();
    if (!this.dirty || !this.shown) return;
    this.dirty = false;
    this.joints.setData(this.data.joints);
    this.cart.setData(this.data.cart);
    this.vel.setData(this.data.vel);
    view.plotPoints = this.points();
  }
  show(on) {
    this.shown = on;
    this.group.hidden = !on;
    if (on) {
      this.dirty = true;
      this.resize();
      this.flush();
    }
  }
  /// The last point of the joint plot as drawn, in rad / m.
  last() {
    const d = this.joints.data;
    const n = d[0].length;
    if (n === 0) return null;
    return { t: d[0][n - 1], qm: this.units.map((u, i) => d[i + 1][n - 1] / u), title: this.joints.root.querySelector('.u-title')?.textContent };
  }
  resize() {
    for (const p of [this.joints, this.cart, this.vel]) p.setSize({ width: plotWidth(), height: 170 });
  }
}

// --- Readout ------------------------------------------------------------------------------------
function readout(robot, desc, t) {
  const q = robot.state.q;
  const parts = desc.joints.map((j, i) => (j.prismatic ? `${(q[i] * 1000).toFixed(1)}mm`
    : `${((q[i] * 180) / Math.PI).toFixed(2)}°`));
  $('readout').textContent = `${desc.name}  t ${t == null ? '-' : t.toFixed(3)} s  seg ${robot.state.seg}\n${parts.join('  ')}`;
}

// --- Start ------------------------------------------------------------------------------------
async function main() {
  const res = await fetch(only ? `/api/scene?robot=${encodeURIComponent(only)}` : '/api/scene');
  const desc = await res.json();
  if (!res.ok) throw new Error(desc.error || `the scene: HTTP ${res.status}`);
  view.mode = desc.mode;
  $('title').textContent = `rccx view: ${desc.title}`;
  document.title = `rccx view: ${desc.title}`;
  if (desc.robots.length > 1 || only) {
    $('robots').innerHTML = ['<a href="/">all</a>'].concat(desc.robots.length > 1
      ? desc.robots.map((r) => `<a href="/robot/${encodeURIComponent(r.name)}">${r.name}</a>`) : []).join('');
  }
  const robots = new Map();
  desc.robots.forEach((r, i) => robots.set(r.index, new RobotView(r, i)));
  const byName = (name) => [...robots.values()].find((r) => r.name === name);
  view.framesAt = (name, q) => byName(name)?.framesAt(q) ?? null;
  view.capsuleCount = (name) => byName(name)?.capsules.length ?? null;
  // A goal's label names its robot when the page shows several.
  const robotNames = [];
  if (desc.robots.length > 1) for (const r of desc.robots) robotNames[r.index] = r.name;
  desc.objects.forEach(addObject);
  desc.frames.forEach((f) => addFrame(f, robotNames));
  // The camera takes in every robot at its ready pose and the objects.
  const box = new THREE.Box3();
  for (const r of robots.values()) {
    for (const m of linkFrames(r, r.state.q)) box.expandByPoint(new THREE.Vector3().setFromMatrixPosition(m));
  }
  for (const o of desc.objects) box.expandByPoint(new THREE.Vector3(o.pose[12], o.pose[13], o.pose[14]));
  if (!box.isEmpty()) {
    const centre = box.getCenter(new THREE.Vector3());
    const size = Math.max(0.3, box.getSize(new THREE.Vector3()).length());
    controls.target.copy(centre);
    camera.position.copy(centre).add(new THREE.Vector3(0.9, -1.2, 0.7).multiplyScalar(size * 0.95));
    controls.update();
  }
  const first = desc.robots[0];
  // Every robot's plots fill as its samples come; the selector chooses the ones shown.
  const plots = new Map();
  for (const r of desc.robots) plots.set(r.index, new Plots(robots.get(r.index), r));
  let shown = plots.get(first.index);
  const select = $('plot-robot');
  const choose = (index) => {
    shown.show(false);
    shown = plots.get(index);
    shown.show(true);
    view.plotted = shown.name;
    view.plotPoints = shown.points();
    readout(shown.robot, desc.robots.find((r) => r.index === index), shown.robot.state.t);
  };
  if (desc.robots.length > 1 && desc.mode !== 'replay') {
    select.innerHTML = desc.robots.map((r) => `<option value="${r.index}">${r.name}</option>`).join('');
    select.hidden = false;
    select.addEventListener('change', () => choose(Number(select.value)));
  }
  shown.show(true);
  view.plotted = shown.name;
  view.plotData = (name) => {
    for (const p of plots.values()) if (p.name === name) return p.last();
    return null;
  };
  view.plotSeries = (name) => {
    for (const p of plots.values()) if (p.name === name) return p.drawn();
    return null;
  };
  // The plots take their pane's width (the panes stack in a narrow window).
  new ResizeObserver(() => shown.resize()).observe($('plots'));

  // Frames the program adds while it runs (the goals of the positions it moves to).
  const refreshFrames = async () => {
    try {
      const s = await (await fetch(only ? `/api/scene?robot=${encodeURIComponent(only)}` : '/api/scene')).json();
      s.frames.forEach((f) => addFrame(f, robotNames));
    } catch { /* the program ended: the status line says so */ }
  };
  setInterval(refreshFrames, 2000);

  let latest = null;
  let refreshing = false;
  // The plots and the readout are drawn on a timer, not in the animation frame: they fill even
  // when the 3D pane draws slowly or not at all (software WebGL, a page in the background).
  let drawPending = null;
  const drawPlots = () => {
    drawPending = null;
    for (const p of plots.values()) p.flush();
    const d = desc.robots.find((r) => r.index === shown.robot.index);
    readout(shown.robot, d, latest ? shown.robot.state.t : null);
  };
  const take = (frames) => {
    for (const f of frames) {
      const r = robots.get(f.r);
      if (!r) continue;
      // The scene graph takes the pose at once (a few matrix products); the next animation
      // frame shows it. rccxView holds what the scene graph holds.
      r.pose(f.q);
      r.state.t = f.t;
      r.state.q = f.q.slice();
      r.state.seg = f.seg;
      r.addPathPoint(f.p);
      plots.get(f.r).push(f);
      // A goal not drawn yet (moved to since the last look at the scene): look again soon.
      if (f.goal && !frameObjects.has(frameKey(f.r, f.goal)) && !refreshing) {
        refreshing = true;
        refreshFrames().finally(() => { refreshing = false; });
      }
      markGoal(r, f.goal);
      view.frames++;
      latest = f;
    }
    if (frames.length && !link.samples++) showLink();
    if (!drawPending) drawPending = setTimeout(drawPlots, 100);
  };
  if (desc.mode === 'replay') {
    await replay(robots.get(first.index), first, shown);
  } else {
    // What came while the scene was built, then each message as it comes.
    for (const frames of link.queue.splice(0)) take(frames);
    link.take = take;
    link.scene = true;
    showLink();
    drawPlots();
  }

  function frame() {
    for (const r of robots.values()) {
      if (r.pending) {
        r.pose(r.pending.q);
        r.state.t = r.pending.t;
        r.state.q = r.pending.q.slice();
        r.state.seg = r.pending.seg;
        r.pending = null;
      }
    }
    controls.update();
    renderer.render(scene, camera);
    labels.render(scene, camera);
    requestAnimationFrame(frame);
  }
  requestAnimationFrame(frame);
  view.ready = true;
}

async function replay(robot, desc, plots) {
  const log = await (await fetch('/api/log')).json();
  $('replay').hidden = false;
  status(`replay: ${log.t.length} samples, ${(log.t[log.t.length - 1] - log.t[0]).toFixed(2)} s`);
  robot.clearPath();
  for (const p of log.p) robot.addPathPoint(p);
  plots.setRun(log);
  plots.flush();
  plots.resize();
  const slider = $('slider');
  slider.max = String(log.t.length - 1);
  let index = 0;
  const show = (i) => {
    index = Math.max(0, Math.min(log.t.length - 1, i));
    slider.value = String(index);
    robot.pending = { q: log.q[index], t: log.t[index], seg: log.seg[index] };
    robot.state.t = log.t[index];
    robot.state.q = log.q[index].slice();
    robot.state.seg = log.seg[index];
    robot.state.index = index;
    $('replay-time').textContent = `${log.t[index].toFixed(3)} s`;
    readout(robot, desc, log.t[index]);
  };
  slider.addEventListener('input', () => { playing = false; $('play').textContent = 'Play'; show(Number(slider.value)); });
  let playing = false;
  let last = 0;
  $('play').addEventListener('click', () => {
    playing = !playing;
    $('play').textContent = playing ? 'Pause' : 'Play';
    if (playing && index >= log.t.length - 1) show(0);
    last = performance.now();
  });
  const step = (now) => {
    if (playing) {
      const speed = Number($('speed').value);
      const target = log.t[index] + ((now - last) / 1000) * speed;
      last = now;
      let i = index;
      while (i < log.t.length - 1 && log.t[i + 1] <= target) ++i;
      show(i);
      if (i >= log.t.length - 1) { playing = false; $('play').textContent = 'Play'; }
    }
    requestAnimationFrame(step);
  };
  requestAnimationFrame(step);
  show(0);
}

window.addEventListener('error', (e) => view.errors.push(String(e.message)));
main().catch((e) => {
  view.errors.push(String(e.message || e));
  status(`error: ${e.message || e}`, true);
  console.error(e);
});
