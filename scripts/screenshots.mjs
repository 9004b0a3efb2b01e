// Refreshes the live screenshots under docs/screenshots/ (the replay one comes from
// tests/web/replay.test.mjs run by hand): each scene served by embra-live, opened in headless
// Chromium, shot once the scene reached the given frame.
//
//   node scripts/screenshots.mjs        (needs the page built, and EMBRA_LIBRARY or libembra.so.2)

import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { createRequire } from 'node:module';
import { fileURLToPath } from 'node:url';
import { launchChromium } from '../host_adapters/web/headless.mjs';

const source = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const require = createRequire(import.meta.url);
const { startServer } = require(path.join(source, 'host_adapters', 'node', 'live', 'server.js'));

const shots = [
  { scene: 'examples/poq_drape.json', frame: 170, metric: 'miter', out: 'poq_live_miter.png' },
  { scene: 'examples/cloth_drape.json', frame: 170, metric: 'none', out: 'cloth_drape_live.png' },
];

const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'embra-shots-'));
const context = await launchChromium(path.join(tmp, 'profile'));
for (const shot of shots) {
  const live = await startServer({ scene: path.join(source, shot.scene), port: 0, saveDir: tmp, log: () => {},
                                   web: path.join(source, 'host_adapters', 'web', 'dist') });
  const page = await context.newPage();
  await page.goto(live.url);
  await page.waitForFunction((f) => window.embraView?.frame >= f, shot.frame, { timeout: 120000 });
  await page.click('#pause');
  await page.waitForFunction(() => document.getElementById('pause').textContent === 'Run');
  await page.evaluate((m) => window.embraView.setMetric(m), shot.metric);
  await page.waitForTimeout(500);
  const file = path.join(source, 'docs', 'screenshots', shot.out);
  await page.screenshot({ path: file });
  console.log(`${file}: ${shot.scene} at frame ${await page.evaluate(() => window.embraView.frame)}`);
  await page.close();
  await live.close();
}
await context.close();
fs.rmSync(tmp, { recursive: true, force: true });
