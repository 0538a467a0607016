// A picture of a cell as `rccx view` draws it (docs/cell-capsules.png): starts
// `RCCX view --cell CELL --port 0`, opens the page in Debian's Chromium, headless, through
// playwright-core (as tests/view_e2e.mjs does), hides the plots so that the 3D pane fills the
// page, waits until the robots are drawn at the session's poses, moves the camera with the
// mouse (OrbitControls: left drag orbits, right drag pans, the wheel zooms) and saves a PNG.
//
//   node scripts/view-screenshot.mjs RCCX CELL OUT.png [WIDTH [HEIGHT]] [options]
//     RCCX          the rccx executable (e.g. build/tools/rccx; the page is its build's web/dist)
//     WIDTH HEIGHT  the picture's size in pixels (default 1200 800)
//     --drag DX,DY  left-drag this many pixels on the canvas: orbit (default 0,0)
//     --pan DX,DY   right-drag this many pixels: move the camera's target (default 0,0)
//     --zoom N      wheel delta: < 0 zooms in, > 0 out; 100 is a factor of 0.95 (default 0)
//     --wait S      seconds the arms move before the picture is taken (default 3)
//     --hide-labels RE  hide the 3D labels whose text matches RE (e.g. ': ', the goals' of a cell)
//   e.g. node scripts/view-screenshot.mjs build/tools/rccx cells/cvarl.json docs/cell-capsules.png
//
// Needs /usr/bin/chromium (or RCCX_CHROMIUM) and web/node_modules (or RCCX_NODE_MODULES; the
// build's npm ci makes it). Exit 0 when the picture is written, 1 with a message otherwise.
import { spawn } from 'node:child_process';
import { existsSync } from 'node:fs';
import { createRequire } from 'node:module';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

const fail = (msg) => { console.error(`view-screenshot: ${msg}`); process.exit(1); };
const opts = { drag: '0,0', pan: '0,0', zoom: '0', wait: '3', 'hide-labels': '' };
const pos = [];
const argv = process.argv.slice(2);
for (let i = 0; i < argv.length; ++i) {
  const m = argv[i].match(/^--(drag|pan|zoom|wait|hide-labels)$/);
  if (m && i + 1 < argv.length) opts[m[1]] = argv[++i];
  else if (argv[i].startsWith('-') && !/^-\d/.test(argv[i])) fail(`unknown option ${argv[i]} (see the script's header)`);
  else pos.push(argv[i]);
}
if (pos.length < 3 || pos.length > 5) fail('usage: view-screenshot.mjs RCCX CELL OUT.png [WIDTH [HEIGHT]] [--drag DX,DY] [--pan DX,DY] [--zoom N] [--wait S] [--hide-labels RE]');
const [rccx, cell, out] = pos;
const width = Number(pos[3] ?? 1200), height = Number(pos[4] ?? 800);
const pair = (s, name) => {
  const v = s.split(',').map(Number);
  if (v.length !== 2 || v.some((x) => !Number.isFinite(x))) fail(`--${name} ${s}: want DX,DY`);
  return v;
};
const drag = pair(opts.drag, 'drag'), pan = pair(opts.pan, 'pan');
const zoom = Number(opts.zoom), wait = Number(opts.wait);
if (!(width >= 100 && height >= 100) || !Number.isFinite(zoom) || !(wait >= 0)) fail('bad size, --zoom or --wait');
if (!existsSync(rccx)) fail(`no ${rccx}`);
if (!existsSync(cell)) fail(`no ${cell}`);
const chromium = process.env.RCCX_CHROMIUM || '/usr/bin/chromium';
const nodeModules = resolve(process.env.RCCX_NODE_MODULES
  || join(dirname(fileURLToPath(import.meta.url)), '..', 'web', 'node_modules'));
if (!existsSync(chromium)) fail(`no ${chromium} (apt-get install chromium; scripts/install-deps does)`);
if (!existsSync(join(nodeModules, 'playwright-core'))) fail(`no ${nodeModules}/playwright-core (npm ci in web/)`);
const { chromium: pw } = createRequire(join(nodeModules, 'x.js'))('playwright-core');

/// Starts the view; resolves with the process and the address it prints ("open http://...").
const start = () => new Promise((res, rej) => {
  const p = spawn(rccx, ['view', '--cell', cell, '--port', '0', '--seconds', String(wait + 90)],
    { stdio: ['ignore', 'pipe', 'pipe'] });
  let text = '';
  const timer = setTimeout(() => rej(new Error(`no address from rccx in 20 s: ${text}`)), 20000);
  const read = (d) => {
    text += d;
    const m = text.match(/open (http:\/\/\S+\/)/);
    if (m) { clearTimeout(timer); res({ proc: p, url: m[1] }); }
  };
  p.stdout.on('data', read);
  p.stderr.on('data', read);
  p.on('error', (e) => { clearTimeout(timer); rej(e); });
  p.on('exit', (code, sig) => { clearTimeout(timer); rej(new Error(`rccx exited (${code ?? sig}): ${text}`)); });
});

let view = null, browser = null;
try {
  view = await start();
  browser = await pw.launch({ executablePath: chromium, headless: true,
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'] });
  const page = await browser.newPage({ viewport: { width, height } });
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  await page.goto(view.url);
  await page.waitForFunction(() => window.rccxView?.ready || window.rccxView?.errors.length, null, { timeout: 45000 });
  // The plots aside hidden: the 3D pane takes the page's width (the page resizes on 'resize').
  await page.addStyleTag({ content: '#plots, .shot-hidden { display: none !important; }' });
  await page.evaluate(() => window.dispatchEvent(new Event('resize')));
  await page.waitForFunction(() => window.rccxView.frames > 20 || window.rccxView.errors.length, null, { timeout: 30000 });
  const errs = await page.evaluate(() => window.rccxView.errors);
  if (errs.length || errors.length) throw new Error(`the page: ${errs.concat(errors).join('; ')}`);
  // The camera: mouse on the canvas, in steps (OrbitControls follows pointer moves).
  const box = await page.locator('#scene canvas').boundingBox();
  const cx = box.x + box.width / 2, cy = box.y + box.height / 2;
  for (const [[dx, dy], button] of [[drag, 'left'], [pan, 'right']]) {
    if (!dx && !dy) continue;
    await page.mouse.move(cx, cy);
    await page.mouse.down({ button });
    await page.mouse.move(cx + dx, cy + dy, { steps: 20 });
    await page.mouse.up({ button });
  }
  if (zoom) { await page.mouse.move(cx, cy); await page.mouse.wheel(0, zoom); }
  await page.mouse.move(0, 0);
  await new Promise((r) => setTimeout(r, wait * 1000));
  if (opts['hide-labels']) {
    await page.evaluate((re) => document.querySelectorAll('.label').forEach((l) => {
      if (new RegExp(re).test(l.textContent)) l.classList.add('shot-hidden');
    }), opts['hide-labels']);
  }
  await page.screenshot({ path: out });
  console.log(`view-screenshot: ${out} (${width} x ${height})`);
} catch (e) {
  console.error(`view-screenshot: ${e.message}`);
  process.exitCode = 1;
} finally {
  if (browser) await browser.close().catch(() => {});
  if (view && view.proc.exitCode === null) { view.proc.removeAllListeners('exit'); view.proc.kill('SIGINT'); }
}
