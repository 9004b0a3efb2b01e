'use strict';
// Edits without a rebuild through Node: a particle of mass m hanging on a link of compliance c rests
// stretched m g c, and after each edit (compliance, rest, material) where the new values put it; the
// saved scene differs from the one before an edit at that one value only (a JSON diff); a disabled group
// steps to the bits of a world without it; a vortex edited between steps pushes at s exp(-r^2/R^2) r/R;
// refusals change nothing.

const assert = require('node:assert/strict');
const test = require('node:test');

const { embra } = require('./helpers');

const G = 9.81;

function hanging(settings = {}, m = 2.0) {
  const w = new embra.World({ settleSpeed: 1e-7, ...settings });
  const b = w.createBody([0, 0, 0, 0, 0, -1], { masses: [0, m] });
  return [w, b];
}

/** How far below 1 m the hanging particle rests. */
function drop(w, b) {
  assert.equal(w.solve({ until: 'settled', maxFrames: 3000 }).outcome, 'settled_within_tolerance');
  return -w.positions()[3 * (b.first + 1) + 2] - 1.0;
}

/** The JSON pointers where two documents differ. */
function differences(a, b, at = '') {
  if (a && b && typeof a === 'object' && typeof b === 'object' && Array.isArray(a) === Array.isArray(b)) {
    const ka = Object.keys(a);
    const kb = Object.keys(b);
    if (ka.length === kb.length && ka.every((k, i) => k === kb[i])) {
      return ka.flatMap((k) => differences(a[k], b[k], `${at}/${k}`));
    }
  }
  return a === b ? [] : [at];
}

function near(actual, expected, tol, what) {
  assert.ok(Math.abs(actual - expected) <= tol, `${what}: ${actual} vs ${expected}`);
}

test('compliance and rest edits move the rest state, and the saved scene at that value only', () => {
  const [w, b] = hanging({ damping: 6.0 });
  w.addConstraint('distance', [b.first, b.first + 1], { rest: 1.0, compliance: 1e-3 });
  assert.deepEqual(w.constraintCount(null, 'distance'), { count: 1, generated: 0 });
  near(drop(w, b), 2.0 * G * 1e-3, 1e-6, 'm g c');
  let before = JSON.parse(w.saveJson());
  const xyz = w.positions().slice();
  w.setConstraintCompliance(null, 'distance', 0, 4e-3);
  assert.deepEqual(w.positions(), xyz);
  assert.deepEqual(differences(before, JSON.parse(w.saveJson())), ['/constraints/0/compliance/0']);
  const c = w.constraint(null, 'distance', 0);
  assert.equal(c.compliance, 4e-3);
  assert.deepEqual(Array.from(c.particles), [b.first, b.first + 1]);
  near(drop(w, b), 2.0 * G * 4e-3, 1e-6, "m g c'");
  before = JSON.parse(w.saveJson());
  w.setConstraintRest(null, 'distance', 0, 1.5);
  assert.deepEqual(differences(before, JSON.parse(w.saveJson())), ['/constraints/0/rest/0']);
  near(drop(w, b) - 0.5, 2.0 * G * 4e-3, 1e-6, 'rest 1.5');
  w.close();
});

test('a disabled group steps to the bits of a world without its constraint', () => {
  const [w, b] = hanging();
  const [free] = hanging();
  const g = w.createGroup();
  w.addConstraint('distance', [b.first, b.first + 1], { group: g });
  w.setGroupEnabled(g, false);
  assert.equal(w.groupEnabled(g), false);
  w.step(20);
  free.step(20);
  assert.deepEqual(w.positions(), free.positions());
  assert.deepEqual(w.velocities(), free.velocities());
  assert.deepEqual(JSON.parse(w.saveJson()).groups.map((x) => x.enabled), [true, true, false]);
  assert.throws(() => w.setGroupEnabled(w.contactGroup(), false), /contact/);
  assert.throws(() => w.setGroupEnabled(g, 1), TypeError);
  w.close();
  free.close();
});

test('move and remove renumber the group', () => {
  const [w, b] = hanging();
  for (const rest of [1, 2, 3]) w.addConstraint('distance', [b.first, b.first + 1], { rest });
  const g = w.createGroup();
  assert.equal(w.setConstraintGroup(null, 'distance', 1, g), 0);
  assert.equal(w.constraint(g, 'distance', 0).rest, 2);
  w.removeConstraint(null, 'distance', 0);
  assert.equal(w.constraint(null, 'distance', 0).rest, 3);
  assert.throws(() => w.removeConstraint(null, 'distance', 1), /outside \[0, 1\)/);
  w.close();
});

test('a material edit moves the generated stretch; the generated link itself is refused', () => {
  const w = new embra.World({ settleSpeed: 1e-7, damping: 6.0, tethers: 0 });
  const b = w.createBody([0, 0, 0, 0, 0, -1], { edges: [0, 1], masses: [0, 2], stretchCompliance: 1e-3 });
  assert.deepEqual(w.constraintCount(null, 'distance'), { count: 1, generated: 1 });
  near(drop(w, b), 2.0 * G * 1e-3, 1e-6, 'm g c');
  assert.throws(() => w.setConstraintCompliance(null, 'distance', 0, 0), /embra_body_set_material/);
  const before = JSON.parse(w.saveJson());
  w.setMaterial(b, { stretchCompliance: 3e-3 });
  assert.deepEqual(differences(before, JSON.parse(w.saveJson())), ['/bodies/0/material/stretch_compliance']);
  assert.equal(w.material(b).stretch_compliance, 3e-3);
  near(drop(w, b), 2.0 * G * 3e-3, 1e-6, "m g c'");
  assert.throws(() => w.setMaterial(b, { mass: 5 }), /mass/);
  assert.throws(() => w.setMaterial(b, { stiffness: 1 }), TypeError);
  w.close();
});

test('a vortex edited between steps pushes at s exp(-r^2/R^2) r/R', () => {
  const w = new embra.World({ gravity: [0, 0, 0] });
  w.createBody([0.5, 0, 0]);
  const f = w.createVortex();
  w.step();
  assert.equal(w.positions()[1], 0);
  w.setVortex(f, { strength: 2.0 });
  assert.equal(w.vortex(f).strength, 2.0);
  w.step();
  const a = 2.0 * Math.exp(-0.25) * 0.5;
  near(w.velocities()[1], a / 60, 1e-3 * a / 60, 'vortex push');
  const before = w.saveJson();
  assert.throws(() => w.setWind(f, { speed: 1 }), embra.InvalidArgumentError);
  assert.throws(() => w.setVortex(f, { radius: 0 }), embra.InvalidArgumentError);
  assert.equal(w.saveJson(), before);
  w.close();
});
