// web.live_shape: shaping the POQ drape from the page against a real embra-live server in headless
// Chromium: the server waits for the first page (frame 0 after a delay), a 150 px drag keeps the
// panels within their tolerances' max, a drag with "pin here" leaves a pin at the release point, a
// pin dot dragged moves its pin.
//
//   (cd host_adapters/web && npm run build)
//   EMBRA_LIBRARY=build/libembra.so.2 node --test tests/web/live_shape.test.mjs
// ctest runs it as web.live_shape after web.build. Needs host_adapters/node's packages.

import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { after, before, test } from 'node:test';
import { createRequire } from 'node:module';
import { fileURLToPath } from 'node:url';
import { chromiumPath, launchChromium } from '../../host_adapters/web/headless.mjs';

const source = process.env.EMBRA_SOURCE_DIR || path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
const web = path.join(source, 'host_adapters', 'web');
const require = createRequire(import.meta.url);
const LAUNCH_DELAY_MS = 3000; // the page opens this long after the server starts

let tmp;
let live;
let context;
let page;
let waitedBeforePage;
const pageErrors = [];

const view = (fn, arg) => page.evaluate(fn, arg);
const distance = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
const serverPosition = (i) => Array.from(live.session.positions.subarray(3 * i, 3 * i + 3));

before(async () => {
  assert.ok(fs.existsSync(path.join(web, 'dist', 'app.js')), `the page is not built: run \`npm run build\` in ${web}`);
  assert.ok(fs.existsSync(chromiumPath), `no Chromium at ${chromiumPath}`);
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'embra-web-shape-'));
  const { startServer } = require(path.join(source, 'host_adapters', 'node', 'live', 'server.js'));
  live = await startServer({
    scene: path.join(source, 'examples', 'poq_drape.json'), host: '127.0.0.1', port: 0,
    web: path.join(web, 'dist'), saveDir: tmp, log: () => {},
  });
  await new Promise((resolve) => setTimeout(resolve, LAUNCH_DELAY_MS));
  waitedBeforePage = { waiting: live.waiting(), frame: live.session.record.frame };
  context = await launchChromium(path.join(tmp, 'profile'), { width: 1280, height: 720 });
  page = context.pages()[0] || await context.newPage();
  page.on('pageerror', (err) => pageErrors.push(err.message));
  await page.goto(live.url);
  await page.waitForFunction(() => window.embraView?.connected && window.embraView.framesReceived > 20, null, { timeout: 30000 });
});

after(async () => {
  await context?.close();
  await live?.close();
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
});

test('the server waits for the first page: opened 3 s after launch, it starts at frame 0', async () => {
  assert.deepEqual(waitedBeforePage, { waiting: true, frame: 0 });
  assert.equal(live.waiting(), false);
  assert.equal(await view(() => embraView.firstFrame), 0);
  const rows = await view(() => embraView.rows.map((r) => r.frame));
  assert.equal(rows[0], 0);
  assert.ok(rows[rows.length - 1] > 20, JSON.stringify(rows.slice(-3)));
});

/** Drags particle `aimed` with the mouse by `pixels` up in 10 px moves; returns the particle held. */
async function dragUp(aimed, pixels, { release = true } = {}) {
  const at = await view((i) => embraView.screenOf(i), aimed);
  await page.mouse.move(at.x, at.y);
  await page.mouse.down();
  const particle = await view(() => embraView.dragParticle);
  assert.ok(particle !== null, 'the mouse-down on the mesh started a drag');
  const start = serverPosition(particle);
  for (let k = 1; k <= pixels / 10; k++) {
    await page.mouse.move(at.x, at.y - 10 * k);
    await page.waitForTimeout(30);
  }
  if (release) await page.mouse.up();
  return { particle, start };
}

test('a 150 px drag on the POQ drape keeps every panel metric within its tolerance max', async () => {
  await page.waitForFunction(() => embraView.frame > 200, null, { timeout: 60000 }); // the sphere has stopped
  const tol = await view(() => embraView.scene.tolerances);
  const first = await view(() => embraView.frame);
  // Every frame the server steps during the drag, as its record (the metrics the page is sent). The
  // page draws only some of them when it draws slower than the server steps (it is sent two ahead
  // at most: docs/live-protocol.md), so the frames it shows are checked too, not counted.
  const stepped = [];
  const step = live.session.step.bind(live.session);
  live.session.step = () => {
    const problem = step();
    stepped.push(live.session.record);
    return problem;
  };
  let particle, start, lifted, rows;
  try {
    ({ particle, start } = await dragUp(58, 150, { release: false }));
    const held = await view(() => embraView.frame);
    await page.waitForFunction((f) => embraView.frame > f + 90, held, { timeout: 30000 });
    lifted = serverPosition(particle)[2] - start[2];
    await page.mouse.up();
    rows = await view((f) => embraView.rows.filter((r) => r.frame > f), first);
  } finally {
    live.session.step = step;
  }
  assert.ok(stepped.length > 90, `${stepped.length} frames stepped during the drag`);
  assert.ok(rows.length > 0, 'the page drew frames of the drag');
  const worst = { planarity: 0, thickness: 0, miter: 0 };
  for (const r of [...stepped, ...rows]) {
    worst.planarity = Math.max(worst.planarity, r.planarity_max);
    worst.thickness = Math.max(worst.thickness, r.thickness_error_max);
    worst.miter = Math.max(worst.miter, r.miter_error_max);
  }
  console.log(`150 px drag: particle ${particle} lifted ${lifted.toFixed(3)} m over ${stepped.length} frames stepped ` +
              `(${rows.length} drawn); worst ${JSON.stringify(worst)}`);
  // The lift depends on how many frames the server steps while the mouse moves (real time: a loaded
  // machine steps fewer) and on the reach and speed, which halve each frame a panel metric passes 0.3 of
  // its max: measured 0.072 m (0.011 to 0.090 m with the former, reach-only drag). What the drag must do
  // is move the corner visibly and never take a panel past its tolerance (below).
  assert.ok(lifted > 0.01, `the drag lifted the corner ${lifted} m`);
  for (const name of ['planarity', 'thickness', 'miter'])
    assert.ok(worst[name] <= tol[name].max, `${name} ${worst[name]} > max ${tol[name].max}`);
});

test('"pin here": the particle stays at the release point 120 frames later', async () => {
  await page.check('#pin-here');
  const pinsBefore = live.session.pins.length;
  const { particle } = await dragUp(40, 80);
  await page.uncheck('#pin-here');
  await page.waitForFunction((n) => embraView.scene.pins.length === n + 1, pinsBefore, { timeout: 10000 });
  const pin = live.session.pins[pinsBefore];
  assert.equal(pin.particle, particle);
  const target = live.session.world.pinTarget(pin.id);
  const released = await view(() => embraView.frame);
  await page.waitForFunction((f) => embraView.frame >= f + 120, released, { timeout: 30000 });
  const shown = await view((i) => Array.from(embraView.positions.subarray(3 * i, 3 * i + 3)), particle);
  const off = distance(serverPosition(particle), target);
  console.log(`pin here: particle ${particle} ${off.toExponential(2)} m from the release point after 120 frames`);
  assert.ok(off < 1e-3, `${off} m from the release point`);
  assert.ok(distance(shown, target) < 1e-3, 'the page shows it there');
  assert.equal(await view(() => embraView.lastError), null);
});

test('a pin dot dragged moves its pin, and its particle follows', async () => {
  const pin = live.session.pins[0];
  const before = live.session.world.pinTarget(pin.id);
  const at = await view((i) => embraView.screenOf(i), pin.particle);
  await page.mouse.move(at.x, at.y);
  await page.mouse.down();
  assert.equal(await view(() => embraView.dragPin), 0);
  for (let k = 1; k <= 6; k++) { // 60 px: about 0.35 m at this view
    await page.mouse.move(at.x - 10 * k, at.y);
    await page.waitForTimeout(30);
  }
  await page.mouse.up();
  await page.waitForTimeout(200);
  const moved = live.session.world.pinTarget(pin.id);
  assert.ok(distance(moved, before) > 0.2, `${before} -> ${moved}`);
  const now = await view(() => embraView.frame);
  await page.waitForFunction((f) => embraView.frame >= f + 60, now, { timeout: 30000 });
  const off = distance(serverPosition(pin.particle), moved);
  console.log(`pin dot: target moved ${distance(moved, before).toFixed(3)} m; particle ${off.toExponential(2)} m from it`);
  assert.ok(off < 1e-3, `${off} m from the moved target`);
  assert.deepEqual(pageErrors, []);
});

test('at 1280 x 720 the help line is whole and inside the view; numbers carry units', async () => {
  const box = await view(() => {
    const help = document.getElementById('help-live');
    const side = document.getElementById('side').getBoundingClientRect();
    const r = help.getBoundingClientRect();
    return { x: r.x, y: r.y, right: r.right, bottom: r.bottom, w: innerWidth, h: innerHeight,
             sideTop: side.top, sideBottom: side.bottom, clipped: help.scrollHeight > help.clientHeight || help.scrollWidth > help.clientWidth,
             text: help.textContent, hud: document.getElementById('hud').textContent,
             legend: document.getElementById('legend').textContent,
             cut: [...document.querySelectorAll('#hud .hud-value, #hud .hud-sub, #hud .hud-label')]
               .filter((e) => e.scrollWidth > e.clientWidth + 1).map((e) => e.textContent) };
  });
  const shot = process.env.EMBRA_SCREENSHOT_DIR ? path.join(process.env.EMBRA_SCREENSHOT_DIR, 'live_1280x720.png') : path.join(tmp, 'live_1280x720.png');
  await page.screenshot({ path: shot });
  console.log(`help line at ${JSON.stringify(box)}; screenshot ${shot}`);
  assert.equal(box.w, 1280);
  assert.equal(box.h, 720);
  assert.ok(box.x >= 0 && box.right <= box.w && box.y >= box.sideTop && box.bottom <= Math.min(box.h, box.sideBottom), JSON.stringify(box));
  assert.equal(box.clipped, false);
  assert.deepEqual(box.cut, [], 'no number, unit or tolerance of the HUD cut off');
  assert.match(box.text, /pin here/);
  assert.match(box.hud, /mrad/); // planarity (fold angle) and miter
  assert.match(box.hud, /\d mm/); // thickness
  assert.doesNotMatch(box.hud, /mm\/m/);
  assert.match(box.legend, /target [\d.e+-]+ mrad/);
});

test('what fights: a cable pulled by two soft pins in two groups lists them first and colours the particle', async () => {
  const { startServer } = require(path.join(source, 'host_adapters', 'node', 'live', 'server.js'));
  const tug = await startServer({
    scene: path.join(source, 'tests', 'web', 'scenes', 'tug.json'), host: '127.0.0.1', port: 0,
    web: path.join(web, 'dist'), saveDir: tmp, log: () => {},
  });
  const other = await context.newPage();
  try {
    other.on('pageerror', (err) => pageErrors.push(err.message));
    await other.goto(tug.url);
    await other.waitForFunction(() => embraView.fights && embraView.fights.frame >= 120, null, { timeout: 60000 });
    const f = await other.evaluate(() => embraView.fights);
    const listed = await other.$$eval('#fights-list li', (els) => els.map((e) => e.textContent));
    const pairs = await other.$$eval('#fights-conflicts li', (els) => els.map((e) => e.textContent));
    console.log(`fights at frame ${f.frame}: ${listed.slice(0, 2).join(' | ')}; ${pairs[0]}`);
    assert.deepEqual(f.worst.slice(0, 2).map((c) => c.pin).sort(), ['pull_left', 'pull_right']);
    for (const c of f.worst.slice(0, 2)) {
      assert.deepEqual(c.particles, [0]);
      assert.equal(c.unit, 'm');
      assert.ok(Math.abs(c.violation - 0.5) < 0.05, `${c.pin} off ${c.violation} m`);
      assert.ok(Math.abs(c.force - 500) < 50, `${c.pin} ${c.force} N`);
    }
    assert.match(listed[0], /^pin pull_(left|right) · (left|right) · particles 0 · off 0\.5\d* m, 5\d\d N$/);
    assert.deepEqual([f.conflicts[0].a, f.conflicts[0].b], ['left', 'right']);
    assert.match(pairs[0], /^left against right: \d+ N on 1 particle$/);
    assert.equal(await other.evaluate(() => embraView.edgeCount), 10, 'the cable drawn as its 10 links');
    await other.selectOption('#metric', 'fights');
    const colors = await other.evaluate(() => Array.from(embraView.colors));
    assert.ok(colors[1] < 0.2 && colors[0] > 0.6, `particle 0 full magenta: ${colors.slice(0, 3)}`);
    // The free end's link stretches by micrometres at tens of newtons: 6 decades below, the lightest.
    assert.ok(colors[3 * 10 + 1] > 0.7, `the free end light: ${colors.slice(30, 33)}`);
  } finally {
    await other.close();
    await tug.close();
  }
  assert.deepEqual(pageErrors, []);
});
