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

test('masses set without a rebuild: m g c for the new mass, saved and loaded to the same bits', () => {
  const w = new embra.World({ settleSpeed: 1e-7, damping: 6.0, tethers: 0 });
  const b = w.createBody([0, 0, 0, 0, 0, -1], { edges: [0, 1], masses: [0, 1], stretchCompliance: 2e-3 });
  near(drop(w, b), 1.0 * G * 2e-3, 1e-6, 'm g c');
  assert.deepEqual(Array.from(w.bodyMasses(b)), [0, 1]);
  const before = JSON.parse(w.saveJson());
  w.setBodyMasses(b, [0, 3.5]);
  const saved = w.saveJson();
  assert.deepEqual(differences(before, JSON.parse(saved)), ['/bodies/0/mesh/masses/1']);
  assert.deepEqual(Array.from(w.bodyMasses(b)), [0, 3.5]);
  const loaded = embra.World.loadJson(saved);
  for (let k = 0; k < 40; k++) {
    w.step();
    loaded.step();
  }
  assert.deepEqual(Array.from(loaded.positions()), Array.from(w.positions()));
  assert.deepEqual(Array.from(loaded.velocities()), Array.from(w.velocities()));
  loaded.close();
  near(drop(w, b), 3.5 * G * 2e-3, 1e-6, "m' g c");

  const text = w.saveJson();
  for (const bad of [[0], [0, 1, 1], [0, -1], [0, NaN], [0, Infinity], [0, 1e-310]]) {
    assert.throws(() => w.setBodyMasses(b, bad), embra.InvalidArgumentError, JSON.stringify(bad));
  }
  assert.throws(() => w.setBodyMasses(b, null), TypeError);
  assert.throws(() => w.setBodyMasses(b, [0, 'x']), TypeError);
  assert.throws(() => w.setBodyMasses(new embra.BodyId(5, 1), [0, 1]), embra.StaleIdError);
  assert.equal(w.saveJson(), text);
  w.close();
});

test('a uniform mass scale changes no motion (a pendulum and a free particle, masses x7)', () => {
  const worlds = [0, 1].map(() => {
    const w = new embra.World({ tethers: 0 });
    const b = w.createBody([0, 0, 0, 1, 0, 0, 3, 0, 0], { edges: [0, 1], masses: [0, 0.4, 0.25] });
    return [w, b];
  });
  let worst = 0;
  let p;
  for (let frame = 0; frame < 210; frame++) {
    if (frame === 10) worlds[1][0].setBodyMasses(worlds[1][1], new Float64Array([0, 2.8, 1.75]));
    for (const [w] of worlds) w.step();
    const a = worlds[0][0].positions();
    p = worlds[1][0].positions();
    for (let i = 0; i < a.length; i++) worst = Math.max(worst, Math.abs(a[i] - p[i]));
  }
  assert.ok(worst < 1e-9, `paths ${worst} m apart`);
  near(Math.hypot(p[3], p[5]), 1.0, 1e-6, 'the link held');
  for (const [w] of worlds) w.close();
});

test('plasticity keeps a set, and rupture breaks with an event', () => {
  // Elastic strain under the weight: m g c / L = 0.0196, past a yield of 0.01: the rest grows to
  // m g c / 0.01 (approached from below, by 1 / (1 + yield) a frame), the elastic part at rest m g c.
  let [w, b] = hanging({ damping: 6.0 });
  w.addConstraint('distance', [b.first, b.first + 1], { rest: 1.0, compliance: 1e-3 });
  assert.deepEqual(w.constraintPlasticity(null, 'distance', 0), { yield: 0, rupture: 0 });
  w.setConstraintPlasticity(null, 'distance', 0, 0.01, 0.0);
  assert.deepEqual(w.constraintPlasticity(null, 'distance', 0), { yield: 0.01, rupture: 0 });
  const d = drop(w, b);
  const rest = w.constraint(null, 'distance', 0).rest;
  near(rest, (2.0 * G * 1e-3) / 0.01, 1e-5 * rest, 'rest m g c / yield');
  near(1.0 + d - rest, 2.0 * G * 1e-3, 1e-6, 'elastic part m g c');
  assert.deepEqual(w.broken(), []);
  assert.throws(() => w.setConstraintPlasticity(null, 'tether', 0, 0.01, 0.0), /distance and dihedral/);
  [w, b] = hanging({ damping: 6.0 });
  w.addConstraint('distance', [b.first, b.first + 1], { rest: 1.0, compliance: 1e-3 });
  w.setConstraintPlasticity(null, 'distance', 0, 0.0, 0.015);
  w.step(60);
  const events = w.broken();
  assert.equal(events.length, 1);
  assert.equal(events[0].kind, 'distance');
  assert.equal(events[0].index, 0);
  assert.deepEqual(events[0].particles, [b.first, b.first + 1]);
  assert.ok(events[0].strain > 0.015 && events[0].frame > 0 && events[0].frame <= 60);
  assert.deepEqual(w.broken(), []);
});
