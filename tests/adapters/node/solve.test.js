'use strict';
// World.residuals and World.solve through Node: residuals by kind in their own units (a rod's is
// | |x1 - x0| - L | from the positions); a pendulum with no damping oscillates with period 2 pi sqrt(L / g) (to
// 1 %); a panel whose top corners are pinned off one plane comes to rest out of tolerance, naming
// that panel; bad options are refused before any step.

const assert = require('node:assert/strict');
const test = require('node:test');

const { embra } = require('./helpers');

test('a pendulum with no damping oscillates with its period', () => {
  const w = new embra.World();
  const theta = 0.1;
  const b = w.createBody([0, 0, 0, Math.sin(theta), 0, -Math.cos(theta)], { masses: [0, 1] });
  w.addConstraint('distance', [b.first, b.first + 1]);
  const solved = w.solve({ maxFrames: 900 });
  const expected = 2 * Math.PI * Math.sqrt(1 / 9.81) * (1 + theta * theta / 16);
  assert.equal(solved.outcome, 'oscillating');
  assert.equal(solved.settled, false);
  assert.equal(solved.frames, 900);
  assert.ok(Math.abs(solved.period - expected) < 0.01 * expected, `period ${solved.period} vs ${expected}`);
  assert.equal(solved.worst, null);
  w.close();
});

test('a panel pinned off its plane comes to rest out of tolerance, named', () => {
  const w = new embra.World({ ...embra.formFindingSolverDef(), damping: 2.0 });
  const body = w.createPanelMesh({ gridColumns: 1, gridRows: 1, pins: 'top_corners' });
  for (const pin of w.pins()) {
    if (w.pinParticle(pin) === body.first + 2) {
      const t = w.pinTarget(pin);
      w.setPinTarget(pin, [t[0], t[1], t[2] + 0.05]);
    }
  }
  const solved = w.solve();
  assert.equal(solved.outcome, 'settled_out_of_tolerance');
  assert.equal(solved.settled, true);
  assert.ok(solved.frames < 1000);
  assert.ok(['planarity', 'corner_distance'].includes(solved.worst.metric));
  assert.ok(solved.worst.body.equals(body.id));
  assert.equal(solved.worst.element, 0);
  assert.equal(solved.worst.layer, 'top');
  assert.ok(solved.worst.value > 100 * solved.worst.target);
  w.close();
});

test('bad solve options are refused and nothing steps', () => {
  const w = new embra.World();
  w.createBody([0, 0, 0]);
  assert.throws(() => w.solve({ until: 'forever' }), RangeError);
  assert.throws(() => w.solve({ maxFrames: 0 }), embra.InvalidArgumentError);
  assert.throws(() => w.solve({ maxSeconds: NaN }), embra.InvalidArgumentError);
  assert.throws(() => w.solve({ maxFrame: 10 }), TypeError);
  assert.equal(w.report().frame, 0);
  w.close();
});

test('residuals by kind, each in its unit: a rod residual from the positions', () => {
  const w = new embra.World();
  const b = w.createBody([0, 0, 0, 0.6, 0, -0.8], { masses: [0, 1] });
  w.addConstraint('distance', [b.first, b.first + 1]);
  assert.deepEqual(w.residuals(), {});
  w.step(10);
  const res = w.residuals();
  assert.deepEqual(Object.keys(res), ['distance']);
  const x = w.positions();
  const length = Math.hypot(x[3] - x[0], x[4] - x[1], x[5] - x[2]);
  assert.equal(res.distance.unit, 'm');
  assert.equal(res.distance.count, 1);
  assert.ok(Math.abs(res.distance.max - Math.abs(length - 1)) <= 1e-15);
  assert.equal(res.distance.rms, res.distance.max);
  w.close();
});

test('two groups pulling a cable apart are named first', () => {
  // A hanging cable's top held by two soft pins (1e-3 m/N) 0.5 m to either side, each in its own
  // group: 500 N each way on one particle.
  const w = new embra.World({ damping: 5.0 });
  const xyz = [];
  for (let i = 0; i < 11; i++) xyz.push(0, 0, -0.1 * i);
  const b = w.createBody(xyz, { mass: 1.0 });
  for (let i = 0; i < 10; i++) w.addConstraint('distance', [b.first + i, b.first + i + 1]);
  const left = w.createGroup({ order: 1 });
  const right = w.createGroup({ order: 2 });
  const pa = w.createPin(b.first, [-0.5, 0, 0], { compliance: 1e-3, group: left });
  const pb = w.createPin(b.first, [0.5, 0, 0], { compliance: 1e-3, group: right });
  w.step(300);
  const first = w.groupConflicts()[0];
  assert.ok(first.a.equals(left) && first.b.equals(right));
  assert.ok(Math.abs(first.force - 500) < 10, `force ${first.force}`);
  assert.equal(first.particles, 1);
  const worst = w.worstConstraints(3);
  assert.ok((worst[0].pin.equals(pa) && worst[1].pin.equals(pb)) || (worst[0].pin.equals(pb) && worst[1].pin.equals(pa)));
  assert.equal(worst[0].kind, 'pins');
  assert.deepEqual(worst[0].particles, [b.first]);
  assert.ok(Math.abs(worst[0].violation - 0.5) < 0.02 && Math.abs(worst[0].force - 500) < 10);
  assert.equal(worst[2].kind, 'distance');
  assert.equal(worst[2].particles.length, 2);
  const links = w.groupResiduals(w.defaultGroup(), 'distance');
  assert.equal(links.length, 10);
  assert.ok(Math.max(...links) < 2e-4);
  w.close();
});
