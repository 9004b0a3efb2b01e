// web.live_drag32: a long drag on the 32 x 32 POQ drape (examples/large/poq_drape_32.json, 1024
// panels of 0.1 m, 16 g each) from the page, against a real embra-live server in headless Chromium:
// every panel metric (planarity, thickness, miter) stays within its tolerance's max on every frame
// the server steps while the drag moves and holds, and the drag still moves the panel it holds.
// Which frames the server steps while the mouse moves differs from run to run; the limit must hold
// on every run (the drag's guard in host_adapters/node/live/session.js undoes a frame that leaves
// the panels over DRAG_SAFE of a max), so the log also says what the guard did.
//
// The drape is stepped to rest first (200 frames: the posts drawn in, the sphere moved between
// frames 120 and 180) through the Node package and saved; the server loads that state, so the
// page's frames are the drag's only.
//
//   (cd host_adapters/web && npm run build)
//   EMBRA_LIBRARY=build/libembra.so.2 node --test tests/web/live_drag32.test.mjs
// ctest runs it as web.live_drag32 after web.build. Needs host_adapters/node's packages.

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
const SETTLE_FRAMES = 200; // the sphere stops at frame 180
const HOLD_FRAMES = 120; // frames the drag holds after the mouse's last move

let tmp;
let live;
let context;
let page;
const pageErrors = [];
const stepped = []; // the server's record of every frame it steps: {frame, planarity_max, ...}

const view = (fn, arg) => page.evaluate(fn, arg);
const serverPosition = (i) => Array.from(live.session.positions.subarray(3 * i, 3 * i + 3));

before(async () => {
  assert.ok(fs.existsSync(path.join(web, 'dist', 'app.js')), `the page is not built: run \`npm run build\` in ${web}`);
  assert.ok(fs.existsSync(chromiumPath), `no Chromium at ${chromiumPath}`);
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'embra-web-drag32-'));
  const { World } = require(path.join(source, 'host_adapters', 'node', 'lib'));
  const scenePath = path.join(source, 'examples', 'large', 'poq_drape_32.json');
  const world = World.loadJson(fs.readFileSync(scenePath, 'utf8'), path.dirname(scenePath));
  world.step(SETTLE_FRAMES);
  const settled = path.join(tmp, 'poq_drape_32_at_rest.json');
  fs.writeFileSync(settled, world.saveJson());
  world.close();

  const { startServer } = require(path.join(source, 'host_adapters', 'node', 'live', 'server.js'));
  live = await startServer({ scene: settled, host: '127.0.0.1', port: 0, web: path.join(web, 'dist'), saveDir: tmp,
                             log: () => {} });
  const session = live.session;
  const step = session.step.bind(session);
  session.step = () => {
    const problem = step();
    stepped.push({ ...session.record });
    return problem;
  };
  context = await launchChromium(path.join(tmp, 'profile'), { width: 1280, height: 720 });
  page = context.pages()[0] || await context.newPage();
  page.on('pageerror', (err) => pageErrors.push(err.message));
  await page.goto(live.url);
  await page.waitForFunction(() => window.embraView?.connected && window.embraView.framesReceived > 3, null, { timeout: 120000 });
});

after(async () => {
  await context?.close();
  await live?.close();
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
});

test('a long drag on the 32 x 32 POQ drape keeps every panel metric within its max on every frame', async () => {
  const tol = await view(() => embraView.scene.tolerances);
  const at = await view((i) => embraView.screenOf(i), 58); // a panel by the pinned corner
  const from = stepped.length;
  await page.mouse.move(at.x, at.y);
  await page.mouse.down();
  const particle = await view(() => embraView.dragParticle);
  assert.ok(particle !== null, 'the mouse-down on the mesh started a drag');
  const start = serverPosition(particle);
  // 300 px up (about 1.5 m at this view), 10 px at a time, a frame or more apart, then held.
  for (let k = 1; k <= 30; k++) {
    const f = stepped.length;
    await page.mouse.move(at.x, at.y - 10 * k);
    while (stepped.length === f) await page.waitForTimeout(20);
  }
  const moved = stepped.length;
  while (stepped.length < moved + HOLD_FRAMES) await page.waitForTimeout(100);
  const lifted = serverPosition(particle)[2] - start[2];
  await page.mouse.up();

  const during = stepped.slice(from);
  const worst = { planarity: 0, thickness: 0, miter: 0 };
  for (const r of during) {
    worst.planarity = Math.max(worst.planarity, r.planarity_max);
    worst.thickness = Math.max(worst.thickness, r.thickness_error_max);
    worst.miter = Math.max(worst.miter, r.miter_error_max);
  }
  console.log(`32 x 32 drag: particle ${particle} lifted ${lifted.toFixed(3)} m over ${during.length} frames; worst ` +
              `planarity ${worst.planarity.toExponential(2)} (max ${tol.planarity.max}), thickness ` +
              `${worst.thickness.toExponential(2)} (max ${tol.thickness.max}), miter ${worst.miter.toExponential(2)} ` +
              `(max ${tol.miter.max}); guard ${JSON.stringify(live.session.dragGuard)}`);
  assert.ok(during.length >= 30 + HOLD_FRAMES, `${during.length} frames stepped during the drag`);
  assert.ok(lifted > 0.05, `the drag lifted the panel ${lifted} m`);
  for (const name of ['planarity', 'thickness', 'miter'])
    assert.ok(worst[name] <= tol[name].max, `${name} ${worst[name]} > max ${tol[name].max}`);
  assert.equal(await view(() => embraView.lastError), null);
  assert.deepEqual(pageErrors, []);
});
