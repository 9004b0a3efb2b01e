// web.replay: the page's replay mode in headless Chromium (playwright-core) against a real
// `embra run examples/poq_drape_pinned.json --out TMP --every 30 --frames 300` folder (top and
// bottom corners pinned: thickness errors above tolerance once the sphere has moved), served with the
// built page (host_adapters/web/dist) by a small http server on 127.0.0.1. Checks the mesh, the
// chart, the slider and that every vertex's colour is the shared colour function's for the errors
// file of the shown frame; saves docs/screenshots/poq_replay_errors.png (or EMBRA_SCREENSHOT).
//
//   (cd host_adapters/web && npm run build)
//   EMBRA_CLI=build/host_adapters/cli/embra node --test tests/web/replay.test.mjs
// ctest runs it as web.replay after building the page (web.build), with the screenshot in the
// build folder. Chromium: /usr/bin/chromium (or EMBRA_CHROMIUM), WebGL through SwiftShader.

import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import http from 'node:http';
import os from 'node:os';
import path from 'node:path';
import { after, before, test } from 'node:test';
import { createRequire } from 'node:module';
import { fileURLToPath } from 'node:url';
import { chromiumPath, launchChromium } from '../../host_adapters/web/headless.mjs';

const source = process.env.EMBRA_SOURCE_DIR || path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
const web = path.join(source, 'host_adapters', 'web');
const dist = path.join(web, 'dist');
const cli = process.env.EMBRA_CLI || path.join(source, 'build', 'host_adapters', 'cli', 'embra');
const screenshot = process.env.EMBRA_SCREENSHOT || path.join(source, 'docs', 'screenshots', 'poq_replay_errors.png');

const require = createRequire(import.meta.url);
const { errorColor, GREY, UNMEASURED } = require(path.join(source, 'host_adapters', 'node', 'lib', 'colors.js'));

const TYPES = { '.html': 'text/html', '.js': 'text/javascript', '.css': 'text/css', '.json': 'application/json' };

function serve(mounts) {
  const server = http.createServer((req, res) => {
    const url = new URL(req.url, 'http://127.0.0.1');
    const [, mount, ...rest] = decodeURIComponent(url.pathname).split('/');
    const root = mounts[mount];
    const file = root && path.resolve(root, rest.join('/') || 'index.html');
    if (!file || !file.startsWith(root + path.sep) || !fs.existsSync(file) || !fs.statSync(file).isFile()) {
      res.writeHead(404).end();
      return;
    }
    res.writeHead(200, { 'content-type': TYPES[path.extname(file)] || 'text/plain', 'cache-control': 'no-store' });
    res.end(req.method === 'HEAD' ? undefined : fs.readFileSync(file));
  });
  return new Promise((resolve) => server.listen(0, '127.0.0.1', () => resolve(server)));
}

let tmp;
let run;
let net;
let server;
let context;
let page;
const pageErrors = [];

before(async () => {
  assert.ok(fs.existsSync(path.join(dist, 'app.js')), `${dist} is not built: run \`npm run build\` in ${web}`);
  assert.ok(fs.existsSync(cli), `no embra CLI at ${cli} (set EMBRA_CLI)`);
  assert.ok(fs.existsSync(chromiumPath), `no Chromium at ${chromiumPath} (apt-get install chromium, or set EMBRA_CHROMIUM)`);
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'embra-web-'));
  run = path.join(tmp, 'run');
  execFileSync(cli, ['run', path.join(source, 'examples', 'poq_drape_pinned.json'), '--out', run, '--every', '30', '--frames', '300'],
    { stdio: ['ignore', 'ignore', 'inherit'] });
  // ?replay=URL reads the folder's file list from URL/index.json, which embra run writes: it lists
  // every file in the folder.
  const index = JSON.parse(fs.readFileSync(path.join(run, 'index.json'), 'utf8'));
  assert.deepEqual([...index.files].sort(), fs.readdirSync(run).sort());
  // An edge-only body (the hanging net): its OBJs carry `l` lines, which the page draws.
  net = path.join(tmp, 'net');
  execFileSync(cli, ['run', path.join(source, 'examples', 'hanging_net.json'), '--out', net, '--every', '30', '--frames', '60'],
    { stdio: ['ignore', 'ignore', 'inherit'] });
  server = await serve({ dist, run, net });

  context = await launchChromium(path.join(tmp, 'profile'));
  page = context.pages()[0] || await context.newPage();
  page.on('pageerror', (err) => pageErrors.push(err.message));
  page.on('console', (msg) => { if (msg.type() === 'error') pageErrors.push(msg.text()); });
  const { port } = server.address();
  await page.goto(`http://127.0.0.1:${port}/dist/index.html?replay=/run/`);
  await page.waitForFunction(() => window.embraView && window.embraView.frame !== null, null, { timeout: 60000 });
});

after(async () => {
  await context?.close();
  await new Promise((resolve) => (server ? server.close(resolve) : resolve()));
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
});

function readObj(name) {
  const text = fs.readFileSync(path.join(run, name), 'utf8');
  return {
    vertices: text.split('\n').filter((l) => l.startsWith('v ')).length,
    faces: text.split('\n').filter((l) => l.startsWith('f ')).length,
  };
}

const readErrors = (frame) => JSON.parse(fs.readFileSync(path.join(run, `frame_${String(frame).padStart(5, '0')}.errors.json`), 'utf8'));

/** Checks every vertex colour of the shown frame against errorColor and the errors file. */
async function checkColors(metric, frame) {
  const errors = readErrors(frame);
  const colors = await page.evaluate(() => Array.from(window.embraView.colors));
  const tol = errors.tolerances[metric];
  const values = errors.fields[metric];
  assert.equal(colors.length, 3 * values.length);
  values.forEach((v, i) => {
    const want = errorColor(metric, v, tol);
    for (let k = 0; k < 3; k++) {
      assert.ok(Math.abs(colors[3 * i + k] - want[k]) < 1e-6, `${metric} frame ${frame} vertex ${i}: ${colors.slice(3 * i, 3 * i + 3)} != ${want}`);
    }
  });
  return { values, tol, colors };
}

test('replay opens the folder: mesh, chart, frames, numbers', async () => {
  const view = await page.evaluate(() => ({
    mode: window.embraView.mode,
    connected: window.embraView.connected,
    vertexCount: window.embraView.vertexCount,
    triangleCount: window.embraView.triangleCount,
    particles: window.embraView.scene.particles,
    positions: window.embraView.positions.length,
    plotPoints: window.embraView.plotPoints,
    frames: window.embraView.replayFrames,
    frame: window.embraView.frame,
    fields: window.embraView.scene.fields,
    colliders: window.embraView.scene.colliders.map((c) => c.shape),
    pins: window.embraView.scene.pins.map((p) => p.particle),
    lastError: window.embraView.lastError,
  }));
  const obj = readObj('final.obj');
  assert.equal(view.mode, 'replay');
  assert.equal(view.connected, false);
  assert.equal(obj.vertices, 128);
  assert.equal(view.vertexCount, obj.vertices);
  assert.equal(view.particles, obj.vertices);
  assert.equal(view.positions, 3 * obj.vertices);
  assert.equal(view.triangleCount, obj.faces);
  const metrics = fs.readFileSync(path.join(run, 'metrics.jsonl'), 'utf8').trim().split('\n');
  assert.equal(view.plotPoints, metrics.length);
  assert.deepEqual(view.frames, [30, 60, 90, 120, 150, 180, 210, 240, 270, 300]);
  assert.equal(view.frame, 300, 'opens on the last frame');
  assert.deepEqual(view.fields, ['planarity', 'thickness', 'miter']);
  assert.deepEqual(view.colliders, ['sphere']);
  assert.equal(view.pins.length, 8);
  assert.equal(view.lastError, null);
  assert.match(await page.textContent('.hud-frame .hud-number'), /^300$/);
  // the pinned case ends out of tolerance (README: a bottom pin fights a tilted corner panel)
  assert.match(await page.textContent('.hud-within .hud-number'), /^no$/);
});

test('the slider moves the frame; the geometry is that frame\'s OBJ', async () => {
  await page.locator('#slider').fill('5'); // frames[5] = 180
  await page.waitForFunction(() => window.embraView.frame === 180);
  const positions = await page.evaluate(() => Array.from(window.embraView.positions));
  const want = fs.readFileSync(path.join(run, 'frame_00180.obj'), 'utf8').split('\n')
    .filter((l) => l.startsWith('v ')).flatMap((l) => l.split(/\s+/).slice(1, 4).map(Number));
  assert.equal(positions.length, want.length);
  positions.forEach((p, k) => assert.ok(Math.abs(p - want[k]) < 1e-6 * (1 + Math.abs(want[k])), `coordinate ${k}`));
  const row = fs.readFileSync(path.join(run, 'metrics.jsonl'), 'utf8').trim().split('\n').map((l) => JSON.parse(l))
    .find((r) => r.frame === 180);
  assert.equal(await page.textContent('.hud-frame .hud-number'), '180');
  assert.equal(await page.textContent('.hud-thickness .hud-number'), row.thickness_error_max.toExponential(2));
  const mmPerM = Number(String(row.thickness_error_max * 1250).slice(0, 8)); // unit_scale 1250: mm
  assert.match(await page.textContent('.hud-thickness .hud-unit'), /^[0-9.]+ mm$/);
  assert.ok(Math.abs(parseFloat(await page.textContent('.hud-thickness .hud-unit')) - mmPerM) < 5e-3 * mmPerM);
  assert.equal(await page.textContent('.hud-within .hud-number'), row.within_tolerance ? 'yes' : 'no');
});

test('the sphere is drawn where the run had it: the scene path recorded in index.json', async () => {
  await page.locator('#slider').fill('4'); // frames[4] = 150: halfway along (0.3, 0.2, -1.45) -> (-0.3, 0.2, -1.35)
  await page.waitForFunction(() => window.embraView.frame === 150);
  const at = await page.evaluate(() => window.embraView.colliderPosition(0));
  [0.0, 0.2, -1.4].forEach((v, k) => assert.ok(Math.abs(at[k] - v) < 1e-6, `sphere at ${at}`));
  await page.locator('#slider').fill('5');
  await page.waitForFunction(() => window.embraView.frame === 180);
  const end = await page.evaluate(() => window.embraView.colliderPosition(0));
  [-0.3, 0.2, -1.35].forEach((v, k) => assert.ok(Math.abs(end[k] - v) < 1e-6, `sphere at ${end}`));
});

test('vertex colours follow the errors file through the shared colour function', async () => {
  for (const metric of ['planarity', 'miter', 'thickness']) { // thickness last: the screenshot's
    await page.selectOption('#metric', metric);
    await page.waitForFunction((m) => window.embraView.metric === m, metric);
    await checkColors(metric, 180);
  }
  const { values, tol, colors } = await checkColors('thickness', 180);
  const over = values.findIndex((v) => v !== null && v > tol.target);
  const within = values.findIndex((v) => v !== null && v <= tol.target);
  assert.ok(over >= 0, 'frame 180 has a vertex over the thickness target');
  assert.ok(within >= 0, 'frame 180 has a vertex within the thickness target');
  const [r, g, b] = colors.slice(3 * over, 3 * over + 3);
  assert.ok(r > 0.75 && r > g + 0.2 && r > b + 0.2, `vertex ${over} (${values[over]}) is reddish: ${[r, g, b]}`);
  assert.deepEqual(colors.slice(3 * within, 3 * within + 3).map((c) => Math.round(c * 1e6) / 1e6), GREY);
  assert.deepEqual(errorColor('thickness', null, tol), UNMEASURED);
});

test('screenOf gives the particle\'s pixel: hovering it reads out that vertex', async () => {
  const p = await page.evaluate(() => window.embraView.screenOf(0));
  const box = await page.locator('#view canvas').boundingBox();
  assert.ok(p.x > box.x && p.x < box.x + box.width && p.y > box.y && p.y < box.y + box.height, JSON.stringify(p));
  const centre = await page.evaluate(() => {
    const n = window.embraView.scene.particles;
    return window.embraView.screenOf(Math.floor(n / 2) + 2);
  });
  await page.mouse.move(centre.x, centre.y);
  await page.waitForSelector('#hover:not([hidden])');
  assert.match(await page.textContent('#hover'), /^particle \d+ {2}· {2}planarity /);
  await page.mouse.move(box.x + 5, box.y + 5); // off the mesh: no readout in the screenshot
  await page.waitForSelector('#hover', { state: 'hidden' });
});

test('screenshot: the thickness map of frame 180 is drawn', async () => {
  await page.evaluate(() => document.activeElement?.blur()); // no focus ring on the slider
  await page.waitForTimeout(300); // damping of the camera settles, the chart draws
  // not blank: the WebGL canvas has lit mesh pixels (neither background nor one flat colour)
  const stats = await page.evaluate(() => {
    const canvas = document.querySelector('#view canvas');
    const copy = document.createElement('canvas');
    copy.width = canvas.width;
    copy.height = canvas.height;
    const ctx = copy.getContext('2d');
    ctx.drawImage(canvas, 0, 0);
    const data = ctx.getImageData(0, 0, copy.width, copy.height).data;
    let differing = 0;
    let reddish = 0;
    const shades = new Set();
    for (let k = 0; k < data.length; k += 4) {
      const [r, g, b] = [data[k], data[k + 1], data[k + 2]];
      if (Math.abs(r - 0xf3) + Math.abs(g - 0xf4) + Math.abs(b - 0xf6) > 24) differing++;
      if (r > g + 40 && r > b + 40) reddish++;
      shades.add(r >> 3 << 10 | g >> 3 << 5 | b >> 3);
    }
    return { differing, reddish, shades: shades.size, pixels: data.length / 4 };
  });
  assert.ok(stats.differing > stats.pixels * 0.08, `the view is nearly blank: ${JSON.stringify(stats)}`);
  assert.ok(stats.shades > 50, `the view is flat: ${JSON.stringify(stats)}`);
  assert.ok(stats.reddish > 100, `no red of the thickness errors in the view: ${JSON.stringify(stats)}`);
  fs.mkdirSync(path.dirname(screenshot), { recursive: true });
  await page.screenshot({ path: screenshot });
  assert.deepEqual(pageErrors, []);
});

test('an edge-only net (OBJ `l` lines) renders as lines', async () => {
  const text = fs.readFileSync(path.join(net, 'final.obj'), 'utf8').split('\n');
  const vertices = text.filter((l) => l.startsWith('v ')).length;
  const edges = text.filter((l) => l.startsWith('l ')).reduce((n, l) => n + l.trim().split(/\s+/).length - 2, 0);
  assert.ok(edges > 0, 'the net\'s OBJ has l lines');
  assert.equal(text.filter((l) => l.startsWith('f ')).length, 0, 'and no faces');
  const { port } = server.address();
  await page.goto(`http://127.0.0.1:${port}/dist/index.html?replay=/net/`);
  await page.waitForFunction(() => window.embraView && window.embraView.frame !== null, null, { timeout: 60000 });
  const v = await page.evaluate(() => ({ edges: embraView.edgeCount, vertices: embraView.vertexCount, triangles: embraView.triangleCount }));
  console.log(`hanging net: ${v.edges} edges drawn over ${v.vertices} vertices`);
  assert.deepEqual(v, { edges, vertices, triangles: 0 });
  assert.deepEqual(pageErrors, []);
});
