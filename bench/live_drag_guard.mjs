// What a live drag does to the 32 x 32 POQ drape's panels, over the Session API (no page, no
// socket): the drape stepped to rest (200 frames), then particle 58 (a panel by the pinned corner)
// dragged up RISE m, its cursor moved in MOVES equal steps (one step a frame, or all at once for
// MOVES = 1), then held HOLD frames. Prints per schedule the panel's rise, the worst planarity,
// thickness and miter of every frame stepped (and their max) and what the drag's guard did
// (Session.dragGuard: frames kept as stepped, undone and stepped again, ...). A measurement, not a
// test:
//
//   node bench/live_drag_guard.mjs [SESSION.js] [MOVES,MOVES,...] [RISE] [HOLD]
//     (default host_adapters/node/live/session.js, 30,10,3,1, 1.5 m, 120 frames)
//
// SESSION.js may be another checkout's session.js (the drag before the guard, for comparison).
// Needs host_adapters/node's packages and EMBRA_LIBRARY (or libembra.so.2 on the loader's path).

import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { createRequire } from 'node:module';
import { fileURLToPath } from 'node:url';

const source = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const require = createRequire(import.meta.url);
const sessionJs = path.resolve(process.argv[2] || path.join(source, 'host_adapters', 'node', 'live', 'session.js'));
const schedules = (process.argv[3] || '30,10,3,1').split(',').map(Number);
const rise = Number(process.argv[4] || 1.5);
const hold = Number(process.argv[5] || 120);
const PARTICLE = 58;
const SETTLE_FRAMES = 200;

const { World } = require(path.join(source, 'host_adapters', 'node', 'lib'));
const { Session } = require(sessionJs);
const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'embra-drag-guard-'));
const scenePath = path.join(source, 'examples', 'large', 'poq_drape_32.json');
const world = World.loadJson(fs.readFileSync(scenePath, 'utf8'), path.dirname(scenePath));
world.step(SETTLE_FRAMES);
const settled = path.join(tmp, 'poq_drape_32_at_rest.json');
fs.writeFileSync(settled, world.saveJson());
world.close();

for (const moves of schedules) {
  const session = new Session(settled, { saveDir: tmp });
  const t = session.tolerances;
  const at = (i) => Array.from(session.positions.subarray(3 * i, 3 * i + 3));
  const start = at(PARTICLE);
  session.handle({ type: 'drag_start', particle: PARTICLE, target: start }, 'page');
  const worst = { planarity: 0, thickness: 0, miter: 0 };
  let frames = 0;
  const t0 = performance.now();
  const frame = () => {
    const problem = session.step();
    if (problem) throw new Error(problem.message);
    const r = session.record;
    worst.planarity = Math.max(worst.planarity, r.planarity_max);
    worst.thickness = Math.max(worst.thickness, r.thickness_error_max);
    worst.miter = Math.max(worst.miter, r.miter_error_max);
    ++frames;
  };
  for (let k = 1; k <= moves; k++) {
    session.handle({ type: 'drag', target: [start[0], start[1], start[2] + (rise * k) / moves] }, 'page');
    frame();
  }
  for (let k = 0; k < hold; k++) frame();
  const lifted = at(PARTICLE)[2] - start[2];
  const seconds = (performance.now() - t0) / 1000;
  const guard = session.dragGuard ? JSON.stringify(session.dragGuard) : '(no guard)';
  console.log(`cursor up ${rise} m in ${moves} move(s), held ${hold}: lifted ${lifted.toFixed(3)} m over ${frames} frames ` +
              `(${seconds.toFixed(0)} s); planarity ${worst.planarity.toExponential(2)} (max ${t.planarity.max}), ` +
              `thickness ${worst.thickness.toExponential(2)} (max ${t.thickness.max}), miter ${worst.miter.toExponential(2)} ` +
              `(max ${t.miter.max}); guard ${guard}`);
  session.close();
}
fs.rmSync(tmp, { recursive: true, force: true });
