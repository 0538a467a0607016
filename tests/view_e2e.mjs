// End-to-end test of `rccx view` in Debian's Chromium, headless, through playwright-core:
//   1. live: the page loads with no console error; the joint values it draws are the session's
//      (the server's sample at the page's time, exactly) and no older than one decimated sample
//      behind the newest; the three plots fill; a second page is open meanwhile; a page for an
//      unknown robot is a 404 and the server goes on serving;
//   2. replay: a run recorded with RCCX_LOG, replayed with `rccx view --log`: moving the slider
//      puts the robot in the logged pose;
//   3. a cell of two robots (cells/cvarl.json): a selector chooses whose plots are shown; each
//      robot's plots hold its own samples (the last point plotted is the server's sample of that
//      robot at that time), the second's as well as the first's; the goals of both robots'
//      moves are drawn without the program showing them, the running ones marked; the page
//      loaded afresh five times (the socket, the scene and the 3D set-up race at each load) ends
//      "live" with both robots' uPlot plots holding points, each time;
//   4. layout: at 1280 x 760 and at 800 x 600 the live, replay and cell pages fit the window (no
//      scrollbar) with the 3D canvas inside the viewport;
//   5. URDF robots: `rccx view --urdf` of the UR5e and the Panda: every link frame the page
//      computes at a known configuration is `rccx kin fk --urdf --tip-link` of that link
//      (within 1e-9), and the URDF's collision capsules are drawn; the UR5e and Panda cell
//      (cells/ur5e_panda.json): each robot's tool point as the page draws it is the server's
//      (C++ forward kinematics, base and turn included) at that sample.
// Screenshots go to ARTIFACT_DIR (view-live.png, view-replay.png, view-cell.png, and the
// live and cell pages at 800 x 600: view-live-800x600.png, view-cell-800x600.png).
//
//   node view_e2e.mjs RCCX ARTIFACT_DIR NODE_MODULES
// Exit 0 pass, 1 fail, 77 skipped (no chromium or no node_modules: said why).
import { spawn } from 'node:child_process';
import { existsSync, mkdirSync, readFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

const [rccx, artifacts, nodeModules] = process.argv.slice(2);
const chromium = process.env.RCCX_CHROMIUM || '/usr/bin/chromium';
if (!existsSync(chromium)) {
  console.log(`SKIP: no ${chromium} (apt-get install chromium; scripts/install-deps does)`);
  process.exit(77);
}
if (!existsSync(join(nodeModules, 'playwright-core'))) {
  console.log(`SKIP: no ${nodeModules}/playwright-core (npm ci in web/; the build runs it)`);
  process.exit(77);
}
const require = createRequire(join(resolve(nodeModules), 'x.js'));
const { chromium: pw } = require('playwright-core');
mkdirSync(artifacts, { recursive: true });

let failures = 0;
const check = (ok, what) => {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) failures++;
};

/// Starts rccx with args; resolves with the process and the base URL it prints.
function start(args, env = {}) {
  return new Promise((resolve, reject) => {
    const p = spawn(rccx, args, { env: { ...process.env, ...env }, stdio: ['ignore', 'pipe', 'pipe'] });
    let err = '';
    const timer = setTimeout(() => reject(new Error(`rccx ${args.join(' ')}: no address in 20 s: ${err}`)), 20000);
    p.stderr.on('data', (d) => {
      err += d;
      const m = err.match(/open (http:\/\/127\.0\.0\.1:\d+\/)/);
      if (m) { clearTimeout(timer); resolve({ proc: p, url: m[1] }); }
    });
    p.on('exit', (code, signal) => {
      console.log(`rccx ${args.join(' ')} exited (${code ?? signal}): ${err}`);
      reject(new Error(`rccx ${args.join(' ')} exited ${code ?? signal}`));
    });
  });
}
const stop = (p) => new Promise((resolve) => {
  if (p.exitCode !== null) return resolve(p.exitCode);
  p.removeAllListeners('exit');
  p.on('exit', (code) => resolve(code));
  p.kill('SIGINT');
});
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

const defaultSize = { width: 1280, height: 760 };
async function openPage(browser, url, errors, viewport = defaultSize) {
  const page = await browser.newPage({ viewport });
  page.on('console', (m) => { if (m.type() === 'error') errors.push(`console: ${m.text()}`); });
  page.on('pageerror', (e) => errors.push(`page: ${e.message}`));
  await page.goto(url);
  try {
    await page.waitForFunction(() => window.rccxView && window.rccxView.ready, null, { timeout: 45000 });
  } catch (e) {
    const state = await page.evaluate(() => JSON.stringify(window.rccxView)).catch(() => '?');
    throw new Error(`${url} not ready in 45 s: ${state}; ${errors.join('; ')}`);
  }
  return page;
}

/// After a resize the page lays itself out on its next frames: waits until the 3D canvas is
/// inside the new viewport (up to 10 s: a loaded machine's browser is slow to), then
/// checkLayout judges the whole layout.
async function settle(page) {
  await page.waitForFunction(() => {
    const r = document.querySelector('#scene canvas').getBoundingClientRect();
    return r.right <= innerWidth + 0.5 && r.bottom <= innerHeight + 0.5;
  }, null, { timeout: 10000 }).catch(() => {});
}

/// The page fits its window: no horizontal (nor vertical) scrollbar, the 3D canvas whole and
/// inside the viewport, the plots' pane inside it too.
async function checkLayout(page, what) {
  const l = await page.evaluate(() => {
    const box = (sel) => {
      const r = document.querySelector(sel).getBoundingClientRect();
      return { left: r.left, top: r.top, right: r.right, bottom: r.bottom, width: r.width, height: r.height };
    };
    const se = document.scrollingElement;
    return { w: innerWidth, h: innerHeight, sw: se.scrollWidth, sh: se.scrollHeight,
      canvas: box('#scene canvas'), plots: box('#plots') };
  });
  const inside = (b) => b.left >= 0 && b.top >= 0 && b.right <= l.w + 0.5 && b.bottom <= l.h + 0.5;
  check(l.sw <= l.w && l.sh <= l.h,
    `${what}: the page fits ${l.w} x ${l.h} without scrollbars (scroll size ${l.sw} x ${l.sh})`);
  check(inside(l.canvas) && l.canvas.width >= 200 && l.canvas.height >= 150 && inside(l.plots),
    `${what}: the 3D canvas (${l.canvas.width} x ${l.canvas.height} at ${l.canvas.left}, ` +
    `${l.canvas.top}) and the plots are inside the viewport`);
}

/// A fresh page of the cell: its status leaves "loading" / "connecting" for "live" and each
/// robot's uPlot plots, chosen in turn with the selector, hold points; the layout fits.
async function checkCellPage(browser, url, names, viewport, what) {
  const errors = [];
  const page = await openPage(browser, url, errors, viewport);
  const live = await page.waitForFunction(() => document.getElementById('status').textContent === 'live',
    null, { timeout: 30000 }).then(() => true, () => false);
  const statusText = await page.textContent('#status');
  const drawn = [];
  for (const name of names) {
    await page.selectOption('#plot-robot', { label: name });
    const ok = await page.waitForFunction((n) => {
      const s = window.rccxView.plotSeries(n);
      return window.rccxView.plotted === n && s && s.joints > 0 && s.cart > 0 && s.vel > 0;
    }, name, { timeout: 30000 }).then(() => true, () => false);
    const s = await page.evaluate((n) => window.rccxView.plotSeries(n), name);
    drawn.push(`${name} ${ok ? `${s.joints} / ${s.cart} / ${s.vel}` : `EMPTY ${JSON.stringify(s)}`}`);
    if (!ok) break;
  }
  const allDrawn = drawn.length === names.length && drawn.every((d) => !d.includes('EMPTY'));
  check(live && allDrawn, `${what}: status "${statusText}", each robot's plots hold points (${drawn.join(', ')})`);
  await checkLayout(page, what);
  check(errors.length === 0, `${what}: no console error (${errors.join('; ') || 'none'})`);
  return page;
}

const browser = await pw.launch({
  executablePath: chromium,
  headless: true,
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
});
const procs = [];
try {
  // --- 1. Live ------------------------------------------------------------------------------
  const live = await start(['view', '--robot', 'microbo', '--port', '0', '--seconds', '120']);
  procs.push(live.proc);
  const errors = [];
  const page = await openPage(browser, live.url, errors);
  const second = await openPage(browser, `${live.url}robot/microbo`, errors);
  await page.waitForFunction(() => window.rccxView.frames > 40, null, { timeout: 30000 });
  const rate = (await (await fetch(`${live.url}api/scene`)).json()).rate_hz;

  // The pose drawn, and the server's state, read together in the page.
  const lags = [];
  let exact = 0;
  for (let i = 0; i < 15; ++i) {
    const { drawn, latest } = await page.evaluate(async () => {
      const r = window.rccxView.robots[0];
      const drawn = { t: r.t, q: r.q.slice() };
      const latest = (await (await fetch('/api/state')).json()).robots[0];
      return { drawn, latest };
    });
    const at = await (await fetch(`${live.url}api/state?robot=microbo&t=${drawn.t}`)).json();
    const diff = Math.max(...drawn.q.map((q, k) => Math.abs(q - at.q[k])));
    if (diff < 1e-9) exact++;
    lags.push(latest.t - drawn.t);
    await sleep(120);
  }
  check(exact === 15, `the drawn joints are the session's decimated sample at the page's time (${exact}/15 exact)`);
  // How far the pose drawn is behind the newest sample the server has: one decimated sample in
  // flight, plus whatever the page's main thread was busy with (software WebGL on a loaded
  // machine); the median must be within one decimated sample and 100 ms of network and page.
  lags.sort((a, b) => a - b);
  const median = lags[Math.floor(lags.length / 2)];
  const period = 1 / rate;
  const samplePeriod = 0.028;  // the Microbo's: the tap sends one sample of every
  const decimated = Math.max(period, samplePeriod);
  check(median <= decimated + 0.1 + 1e-9,
    `the pose drawn follows the session: median ${(median * 1000).toFixed(0)} ms behind the newest sample ` +
    `(one decimated sample is ${(decimated * 1000).toFixed(0)} ms), worst ${(lags[lags.length - 1] * 1000).toFixed(0)} ms`);
  const points = await page.evaluate(() => window.rccxView.plotPoints);
  check(points.joints > 40 && points.cart > 40 && points.vel > 40,
    `the plots fill (${points.joints} / ${points.cart} / ${points.vel} points)`);
  const moved = await page.evaluate(() => window.rccxView.robots[0].q);
  check(moved.some((q) => Number.isFinite(q)), 'the robot is drawn');
  const goals = await page.evaluate(() => window.rccxView.frameNames);
  check(goals.includes('0:P1') && goals.includes('0:P2'),
    `the goals of the moves are drawn though the program never calls show() (${goals.join(', ')})`);

  // Bad input: an unknown robot is a 404 that says which robots there are; the server goes on.
  const bad = await browser.newPage();
  const res = await bad.goto(`${live.url}robot/nope`);
  const badText = await bad.textContent('body');
  check(res.status() === 404 && /no robot "nope" here; the robots are: microbo/.test(badText),
    `an unknown robot's page is a 404 naming the robots (${res.status()})`);
  await bad.close();
  const framesBefore = await page.evaluate(() => window.rccxView.frames);
  await sleep(600);
  const framesAfter = await page.evaluate(() => window.rccxView.frames);
  check(framesAfter > framesBefore, `the server goes on serving after it (${framesAfter - framesBefore} samples more)`);
  const api = await fetch(`${live.url}api/scene?robot=nope`);
  check(api.status === 404 && /no robot "nope"/.test((await api.json()).error), '/api/scene?robot=nope is a 404 with a message');

  await checkLayout(page, 'the live page');
  await page.screenshot({ path: join(artifacts, 'view-live.png') });
  await page.setViewportSize({ width: 800, height: 600 });
  await settle(page);
  await checkLayout(page, 'the live page at 800 x 600');
  await page.screenshot({ path: join(artifacts, 'view-live-800x600.png') });
  check(errors.length === 0, `no console error (${errors.join('; ') || 'none'})`);
  await second.close();
  await page.close();
  check((await stop(live.proc)) === 130, 'rccx view ends on Ctrl-C with 130');

  // --- 2. Replay ----------------------------------------------------------------------------
  const csv = join(artifacts, 'view-run.csv');
  const rec = await new Promise((resolve) => {
    const p = spawn(rccx, ['view', '--robot', 'microbo', '--port', '0', '--fast', '--seconds', '1.5'],
      { env: { ...process.env, RCCX_LOG: csv }, stdio: 'inherit' });
    p.on('exit', resolve);
  });
  check(rec === 0 && existsSync(csv), `a run recorded with RCCX_LOG (${rec})`);
  // The log's first line names its robot (`# rccx-log 1 robot=...`); the column line follows.
  const lines = readFileSync(csv, 'utf8').trim().split('\n').filter((l) => !l.startsWith('#'));
  check(readFileSync(csv, 'utf8').startsWith('# rccx-log 1 robot=microbo '), 'the log says its robot');
  const header = lines[0].split(',');
  const dof = (header.length - 8) / 2;
  const rows = lines.slice(1).map((l) => l.split(',').map(Number));
  const replay = await start(['view', '--log', csv, '--robot', 'microbo', '--port', '0', '--seconds', '120']);
  procs.push(replay.proc);
  const rerrors = [];
  const rpage = await openPage(browser, replay.url, rerrors);
  check(await rpage.isVisible('#slider'), 'the replay shows its slider');
  const k = Math.floor(rows.length * 0.6);
  await rpage.evaluate((k) => {
    const s = document.getElementById('slider');
    s.value = String(k);
    s.dispatchEvent(new Event('input'));
  }, k);
  await rpage.waitForTimeout(300);
  const shown = await rpage.evaluate(() => window.rccxView.robots[0]);
  const logged = rows[k].slice(2, 2 + dof);
  const rdiff = Math.max(...logged.map((q, i) => Math.abs(q - shown.q[i])));
  check(Math.abs(shown.t - rows[k][0]) < 1e-6 && rdiff < 1e-6,
    `the slider at sample ${k} puts the robot in the logged pose (t ${shown.t}, joints within ${rdiff.toExponential(1)})`);
  await rpage.click('#play');
  await rpage.waitForTimeout(500);
  const played = await rpage.evaluate(() => window.rccxView.robots[0].t);
  check(played > shown.t, `play moves on (${shown.t.toFixed(3)} -> ${played.toFixed(3)} s)`);
  const rpoints = await rpage.evaluate(() => window.rccxView.plotPoints);
  check(rpoints.joints === rows.length, `the replay's plots hold the run (${rpoints.joints} of ${rows.length})`);
  await checkLayout(rpage, 'the replay');
  await rpage.screenshot({ path: join(artifacts, 'view-replay.png') });
  await rpage.setViewportSize({ width: 800, height: 600 });
  await settle(rpage);
  await checkLayout(rpage, 'the replay at 800 x 600');
  check(await rpage.isVisible('#slider'), 'the replay\'s slider is visible at 800 x 600');
  check(rerrors.length === 0, `no console error in the replay (${rerrors.join('; ') || 'none'})`);
  await stop(replay.proc);

  // --- 3. A cell of two robots --------------------------------------------------------------
  const cellFile = resolve(dirname(fileURLToPath(import.meta.url)), '..', 'cells', 'cvarl.json');
  const cell = await start(['view', '--cell', cellFile, '--port', '0', '--seconds', '120']);
  procs.push(cell.proc);
  const cerrors = [];
  const cpage = await openPage(browser, cell.url, cerrors);
  const cscene = await (await fetch(`${cell.url}api/scene`)).json();
  const names = cscene.robots.map((r) => r.name);
  check(names.length === 2, `the cell has two robots (${names.join(', ')})`);
  const options = await cpage.$$eval('#plot-robot option', (os) => os.map((o) => o.textContent));
  check(await cpage.isVisible('#plot-robot') && options.join() === names.join(),
    `a selector chooses whose plots are shown (${options.join(', ')})`);
  check(await cpage.evaluate(() => window.rccxView.plotted) === names[0], 'the first robot\'s plots are shown first');
  // Both robots' plots fill, the hidden one's too.
  await cpage.waitForFunction((ns) => ns.every((n) => (window.rccxView.plots[n]?.joints ?? 0) > 30),
    names, { timeout: 30000 });
  await cpage.selectOption('#plot-robot', { label: names[1] });
  await cpage.waitForTimeout(400);
  const shownGroups = await cpage.$$eval('.plot-group', (gs) => gs.filter((g) => !g.hidden).map((g) => g.dataset.robot));
  check(await cpage.evaluate(() => window.rccxView.plotted) === names[1] && shownGroups.join() === names[1],
    `choosing ${names[1]} shows its plots alone (${shownGroups.join(', ')})`);
  const shownPoints = await cpage.evaluate(() => window.rccxView.plotPoints);
  check(shownPoints.joints > 30 && shownPoints.cart > 30 && shownPoints.vel > 30,
    `${names[1]}'s plots fill (${shownPoints.joints} / ${shownPoints.cart} / ${shownPoints.vel} points)`);
  // Each robot's joint plot holds that robot's samples: its last point is the server's sample of
  // that robot at that time, in as many joints as it has.
  for (const [i, name] of [[1, names[1]], [0, names[0]]]) {
    const last = await cpage.evaluate((n) => window.rccxView.plotData(n), name);
    const at = await (await fetch(`${cell.url}api/state?robot=${name}&t=${last.t}`)).json();
    const dof = cscene.robots[i].joints.length;
    const diff = at.qm ? Math.max(...at.qm.map((q, k) => Math.abs(q - last.qm[k]))) : Infinity;
    check(last.qm.length === dof && diff < 1e-9 && last.title.startsWith(`${name}:`),
      `${name}'s joint plot holds its own samples (${last.qm.length} joints at t ${last.t.toFixed(3)} s, ` +
      `within ${diff.toExponential(1)} of the server's; "${last.title}")`);
  }
  // The goals of both robots' moves, drawn though rccx view never calls show(); the running ones marked.
  await cpage.waitForFunction((ns) => ns.every((n, i) => window.rccxView.frameNames.includes(`${i}:${n}_P1`)),
    names, { timeout: 30000 });
  await cpage.waitForFunction(() => window.rccxView.robots.every((r) => r.goal), null, { timeout: 30000 });
  // Each robot's running goal marked: at the sample a new motion starts its goal's label may
  // come a frame later (the goal is drawn when the move is queued), so wait for a frame where
  // every robot's is.
  const allMarked = await cpage.waitForFunction(() => {
    const active = [...document.querySelectorAll('.label.active')].map((e) => e.textContent);
    return window.rccxView.robots.every((r) => r.goal && active.some((t) => t.endsWith(r.goal)));
  }, null, { timeout: 30000 }).then(() => true, () => false);
  const marks = await cpage.evaluate(() => ({
    goals: window.rccxView.robots.map((r) => r.goal),
    active: [...document.querySelectorAll('.label.active')].map((e) => e.textContent),
  }));
  check(allMarked && marks.goals.every((g, i) => g.startsWith(`${names[i]}_P`)) && marks.active.length >= 1,
    `each robot's running goal is marked (${marks.goals.join(', ')}; marked: ${marks.active.join(', ')})`);
  await cpage.screenshot({ path: join(artifacts, 'view-cell.png') });
  check(cerrors.length === 0, `no console error on the cell's page (${cerrors.join('; ') || 'none'})`);
  await cpage.close();
  // The page loaded afresh, five times, while the cell runs: the socket, the scene's request and
  // the 3D set-up race each time; every load must end live with both robots' plots drawn.
  for (let i = 1; i <= 5; ++i) {
    await (await checkCellPage(browser, cell.url, names, defaultSize, `cell page, load ${i}`)).close();
  }
  const small = await checkCellPage(browser, cell.url, names, { width: 800, height: 600 },
    'cell page at 800 x 600');
  await small.screenshot({ path: join(artifacts, 'view-cell-800x600.png') });
  await small.close();
  await stop(cell.proc);

  // --- 5. URDF robots: the page's chain against the C++ forward kinematics ------------------
  // rccx view --urdf: every link frame the page computes at a known configuration equals
  // `rccx kin fk --urdf FILE --tip-link LINK` of the chain cut at that link (the C++ forward
  // kinematics, base to that link), within 1e-9.
  const here = dirname(fileURLToPath(import.meta.url));
  const urdfs = [
    { file: 'ur5e.urdf', name: 'ur5e', q: [0.1, -1.2, 1.0, -0.5, 0.7, 0.3],
      tips: ['shoulder_link', 'upper_arm_link', 'forearm_link', 'wrist_1_link', 'wrist_2_link', 'tool0'] },
    { file: 'panda.urdf', name: 'panda', q: [0.3, -0.4, 0.2, -2.0, 0.5, 1.9, -0.6],
      tips: ['panda_link1', 'panda_link2', 'panda_link3', 'panda_link4', 'panda_link5', 'panda_link6', 'panda_link8'] },
  ];
  const fk = (file, tip, q) => new Promise((resolve, reject) => {
    const p = spawn(rccx, ['kin', 'fk', '--urdf', file, '--tip-link', tip, '--json', '--', ...q.map(String)],
      { stdio: ['ignore', 'pipe', 'pipe'] });
    let out = '', err = '';
    p.stdout.on('data', (d) => { out += d; });
    p.stderr.on('data', (d) => { err += d; });
    p.on('exit', (code) => (code === 0 ? resolve(JSON.parse(out).T) : reject(new Error(`rccx kin fk: ${err}`))));
  });
  for (const u of urdfs) {
    const file = resolve(here, '..', 'robots', u.file);
    const run = await start(['view', '--urdf', file, '--port', '0', '--seconds', '120']);
    procs.push(run.proc);
    const uerrors = [];
    const upage = await openPage(browser, run.url, uerrors);
    const frames = await upage.evaluate(([n, q]) => window.rccxView.framesAt(n, q), [u.name, u.q]);
    let worst = 0;
    for (let k = 0; k < u.tips.length; ++k) {
      const T = await fk(file, u.tips[k], u.q.slice(0, k + 1));
      const m = frames[k + 1];  // column-major; frames[0] is the base
      for (let r = 0; r < 3; ++r) for (let c = 0; c < 4; ++c) worst = Math.max(worst, Math.abs(m[c * 4 + r] - T[r][c]));
    }
    check(frames.length === u.q.length + 2 && worst < 1e-9,
      `rccx view --urdf ${u.file}: the page's ${u.q.length} link frames are the C++ forward kinematics' (within ${worst.toExponential(1)} m)`);
    const scene = await (await fetch(`${run.url}api/scene`)).json();
    const drawn = await upage.evaluate((n) => window.rccxView.capsuleCount(n), u.name);
    check(scene.robots[0].capsules.length > 0 && drawn === scene.robots[0].capsules.length,
      `${u.name}: the page draws its URDF's ${drawn} collision capsules`);
    check(uerrors.length === 0, `no console error for ${u.file} (${uerrors.join('; ') || 'none'})`);
    await upage.close();
    check((await stop(run.proc)) === 130, `rccx view --urdf ${u.file} ends on Ctrl-C with 130`);
  }

  // rccx view --cell with URDF robots (cells/ur5e_panda.json): each robot's tool point, as the
  // page computes it at the pose it draws, is the server's (base * forward(q) * tool, C++) for
  // that sample, the Panda turned half a turn and placed 1 m away as the cell says.
  const pairFile = resolve(here, '..', 'cells', 'ur5e_panda.json');
  const pair = await start(['view', '--cell', pairFile, '--port', '0', '--seconds', '120']);
  procs.push(pair.proc);
  const perrors = [];
  const ppage = await openPage(browser, pair.url, perrors);
  await ppage.waitForFunction(() => window.rccxView.robots.every((r) => r.t !== null), null, { timeout: 30000 });
  const pnames = (await (await fetch(`${pair.url}api/scene`)).json()).robots.map((r) => r.name);
  check(pnames.join() === 'ur5e,panda', `the UR5e and Panda cell has both robots (${pnames.join(', ')})`);
  for (const [i, name] of pnames.entries()) {
    const { t, q, tool } = await ppage.evaluate(([i, n]) => {
      const r = window.rccxView.robots[i];
      const f = window.rccxView.framesAt(n, r.q);
      const m = f[f.length - 1];
      return { t: r.t, q: r.q, tool: [m[12], m[13], m[14]] };
    }, [i, name]);
    const at = await (await fetch(`${pair.url}api/state?robot=${name}&t=${t}`)).json();
    const qdiff = Math.max(...q.map((v, k) => Math.abs(v - at.q[k])));
    const pdiff = Math.max(...tool.map((v, k) => Math.abs(v - at.p[k])));
    check(qdiff < 1e-12 && pdiff < 1e-9,
      `${name}: the tool point the page draws is the server's at t ${t.toFixed(3)} s (within ${pdiff.toExponential(1)} m)`);
  }
  const counts = await ppage.evaluate((ns) => ns.map((n) => window.rccxView.capsuleCount(n)), pnames);
  check(counts.every((c) => c > 0), `both robots' collision capsules are drawn (${counts.join(', ')})`);
  await ppage.screenshot({ path: join(artifacts, 'view-ur5e-panda.png') });
  check(perrors.length === 0, `no console error on the UR5e and Panda cell (${perrors.join('; ') || 'none'})`);
  await ppage.close();
  await stop(pair.proc);
} catch (e) {
  console.log(`FAIL ${e.stack || e}`);
  failures++;
} finally {
  for (const p of procs) await stop(p);
  await browser.close();
}
console.log(failures === 0 ? 'PASS' : `${failures} check(s) failed`);
process.exit(failures === 0 ? 0 : 1);
