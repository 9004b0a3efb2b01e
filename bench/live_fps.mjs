// The frame rate of embra-live: starts the server on a scene, opens the page in headless Chromium,
// lets it run, and reports the frames the server stepped per second (the page's frame numbers), the
// frames the page received per second (it acknowledges each one it draws, and the server sends it
// two ahead at most: docs/live-protocol.md) and the server's ms per step. A measurement, not a test:
//
//   node bench/live_fps.mjs [SCENE.json] [SECONDS]     (default examples/large/poq_drape_32.json, 20)
//
// Needs the page built (cd host_adapters/web && npm run build), host_adapters/node's packages and
// EMBRA_LIBRARY (or libembra.so.2 on the loader's path).

import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { createRequire } from 'node:module';
import { fileURLToPath } from 'node:url';
import { launchChromium } from '../host_adapters/web/headless.mjs';

const source = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const require = createRequire(import.meta.url);
const scene = path.resolve(process.argv[2] || path.join(source, 'examples', 'large', 'poq_drape_32.json'));
const seconds = Number(process.argv[3] || 20);
const { startServer } = require(path.join(source, 'host_adapters', 'node', 'live', 'server.js'));

const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'embra-live-fps-'));
const live = await startServer({ scene, port: 0, web: path.join(source, 'host_adapters', 'web', 'dist'), saveDir: tmp,
                                 log: () => {} });
const context = await launchChromium(path.join(tmp, 'profile'), { width: 1280, height: 800 });
const page = context.pages()[0] || await context.newPage();
await page.goto(live.url);
await page.waitForFunction(() => window.embraView?.connected && window.embraView.framesReceived > 0, null,
  { timeout: 60000 });
const at = () => page.evaluate(() => ({ frames: window.embraView.framesReceived, frame: window.embraView.frame }));
const serverMs = [];
const a = await at();
const t0 = performance.now();
const sampler = setInterval(() => serverMs.push(live.session.lastMs), 100);
await new Promise((r) => setTimeout(r, 1000 * seconds));
clearInterval(sampler);
const b = await at();
const elapsed = (performance.now() - t0) / 1000;
serverMs.sort((x, y) => x - y);
const median = serverMs[Math.floor(serverMs.length / 2)];
console.log(JSON.stringify({
  scene: path.relative(source, scene), particles: live.session.particles, seconds: Number(elapsed.toFixed(1)),
  frames_received: b.frames - a.frames, page_fps: Number(((b.frames - a.frames) / elapsed).toFixed(1)),
  frames_stepped: b.frame - a.frame, steps_per_second: Number(((b.frame - a.frame) / elapsed).toFixed(1)),
  step_ms_median: Number(median.toFixed(1)),
  realtime_fps: Number((1 / live.session.dt).toFixed(1)),
}));
await context.close();
await live.close();
fs.rmSync(tmp, { recursive: true, force: true });
