'use strict';
// Fields through Node: the section 3 scenes with their fields made by the World methods instead of the
// scene file give the bits the C host gives (`embra run`); pressure on a closed surface inflates it
// and keep_volume holds its volume; a destroyed field stops acting; refusals change nothing.

const assert = require('node:assert/strict');
const fs = require('node:fs');
const path = require('node:path');
const test = require('node:test');

const { embra, sourceDir, readObjVertices, runCli, assertSameBits, snapshot } = require('./helpers');

const FRAMES = 40;

function loadScene(name) {
  return JSON.parse(fs.readFileSync(path.join(sourceDir, 'examples', `${name}.json`), 'utf8'));
}

function withoutFields(scene) {
  const { fields, ...rest } = scene;
  return rest;
}

/** Creates the scene's fields through the World methods; body names become the ids the loader gave
 * the bodies (in file order, first generation). */
function addFields(world, scene) {
  const bodies = new Map(scene.bodies.map((b, k) => [b.name, new embra.BodyId(k, 1)]));
  const create = { wind: 'createWind', pressure: 'createPressure', surface_tension: 'createSurfaceTension',
    vortex: 'createVortex' };
  return scene.fields.map((field) => {
    const { type, name, ...fields } = field;
    if ('body' in fields) fields.body = bodies.get(fields.body);
    return world[create[type]](fields);
  });
}

for (const name of ['flag_wind', 'minimal_surface', 'interacting_elements']) {
  test(`${name}: fields made in Node match the C host bit for bit`, () => {
    const scene = loadScene(name);
    assert.ok(!('actions' in scene), '`embra run` steps exactly what World.step steps');
    const expected = readObjVertices(path.join(runCli(['run', path.join(sourceDir, 'examples', `${name}.json`),
      '--frames', String(FRAMES)], name), 'final.obj'));
    let w = embra.World.loadJson(JSON.stringify(withoutFields(scene)));
    assert.equal(w.fieldCount, 0);
    const ids = addFields(w, scene);
    assert.equal(ids.length, 1);
    assert.equal(w.fieldCount, 1);
    assert.ok(ids[0] instanceof embra.FieldId);
    w.step(FRAMES);
    const got = w.positions();
    w.close();
    assert.ok(expected.length > 0);
    assertSameBits(got, expected, `${name} positions`);
    w = embra.World.loadJson(JSON.stringify(withoutFields(scene))); // the field is what moved them
    w.step(FRAMES);
    assert.notDeepEqual(w.positions(), expected);
    w.close();
  });
}

test('shrink wrap: the pressure made in Node steps as the scene loaded, and is saved', () => {
  const scene = loadScene('shrink_wrap');
  const loaded = embra.World.loadJson(JSON.stringify(scene));
  assert.equal(loaded.fieldCount, 1);
  loaded.step(10);
  const built = embra.World.loadJson(JSON.stringify(withoutFields(scene)));
  addFields(built, scene);
  built.step(10);
  assertSameBits(built.positions(), loaded.positions(), 'shrink wrap');
  const saved = JSON.parse(built.saveJson());
  assert.deepEqual(saved.fields.map((f) => f.type), ['pressure']);
  assert.equal(saved.fields[0].outside_pressure, 30.0);
  loaded.close();
  built.close();
});

const OCTAHEDRON = [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]];
const OCTAHEDRON_TRIANGLES = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];

function enclosedVolume(xyz) {
  const p = (k) => xyz.subarray(3 * k, 3 * k + 3);
  let v = 0.0;
  for (const [a, b, c] of OCTAHEDRON_TRIANGLES) {
    const [pa, pb, pc] = [p(a), p(b), p(c)];
    v += (pa[0] * (pb[1] * pc[2] - pb[2] * pc[1]) - pa[1] * (pb[0] * pc[2] - pb[2] * pc[0]) +
      pa[2] * (pb[0] * pc[1] - pb[1] * pc[0])) / 6.0;
  }
  return v;
}

function octahedronWorld() {
  const w = new embra.World({ gravity: [0, 0, 0], substeps: 4 });
  const body = w.createBody(OCTAHEDRON, { triangles: OCTAHEDRON_TRIANGLES, mass: 1.0, stretchCompliance: 1e-2,
    generate: ['stretch'] });
  return { w, body };
}

test('pressure inflates a closed surface, and keep_volume holds it', () => {
  const rest = 4.0 / 3.0; // the unit octahedron
  let { w, body } = octahedronWorld();
  assert.ok(Math.abs(enclosedVolume(w.positions()) - rest) <= 1e-15 * rest);
  w.createPressure({ body, insidePressure: 50.0, outsidePressure: 10.0 });
  w.step(30);
  assert.ok(enclosedVolume(w.positions()) > 1.05 * rest);
  w.close();
  ({ w, body } = octahedronWorld());
  w.createPressure({ body, inside_pressure: 50.0, outside_pressure: 10.0, keep_volume: 1 });
  w.step(30); // the same pressures grew the free one by over 5%
  assert.ok(Math.abs(enclosedVolume(w.positions()) - rest) <= 1e-4 * rest);
  w.close();
});

test('field defaults are the documented ones', () => {
  const wind = embra.defaultWindDef();
  assert.deepEqual([wind.version, wind.direction, wind.speed, wind.air_density, wind.drag, wind.lift],
    [embra.capi.WIND_DEF_VERSION, [1, 0, 0], 0, 1.2, 1, 1]);
  assert.ok(wind.body.equals(new embra.BodyId()));
  assert.deepEqual(embra.defaultPressureDef(), { version: 1, keep_volume: 0, body: new embra.BodyId(),
    inside_pressure: 0, outside_pressure: 0, volume_compliance: 0, rest_volume: 0 });
  const tension = embra.defaultSurfaceTensionDef();
  assert.deepEqual([tension.tension, tension.regularisation], [0, 1]);
  const vortex = embra.defaultVortexDef();
  assert.deepEqual([vortex.center, vortex.axis, vortex.strength, vortex.radius, vortex.decay],
    [[0, 0, 0], [0, 0, 1], 0, 1, 0]);
});

test('a destroyed field stops acting and its id is stale', () => {
  const { w, body } = octahedronWorld();
  const field = w.createVortex({ strength: 3.0, axis: [0, 0, 1] });
  const other = w.createWind({ body, speed: 2.0 });
  assert.equal(w.fieldCount, 2);
  assert.ok(!field.equals(other));
  w.destroyField(field);
  assert.equal(w.fieldCount, 1);
  assert.throws(() => w.destroyField(field), (e) => e instanceof embra.StaleIdError &&
    e.message.startsWith('embra_field_destroy: ') && e.message === embra.lastErrorMessage());
  assert.equal(w.fieldCount, 1);
  w.destroyField(other);
  assert.equal(w.fieldCount, 0);
  const before = Buffer.from(w.positions().buffer);
  w.step(5); // no field, no gravity, at rest: nothing moves
  assert.ok(Buffer.from(w.positions().buffer).equals(before));
  w.close();
});

test('refused field calls raise the C message and change nothing', () => {
  const { w, body } = octahedronWorld();
  w.createWind({ body, speed: 1.0 });
  w.step(3);
  const before = [w.fieldCount, snapshot(w)];
  const byC = (fn, cls, prefix) => assert.throws(fn, (e) => e instanceof cls && e.message.startsWith(prefix) &&
    e.message === embra.lastErrorMessage());
  byC(() => w.createWind({ version: 99 }), embra.VersionError, 'embra_wind_create: ');
  byC(() => w.createWind({ body, speed: NaN }), embra.InvalidArgumentError, 'embra_wind_create: ');
  byC(() => w.createWind({ direction: [0, 0, 0] }), embra.InvalidArgumentError, 'embra_wind_create: ');
  byC(() => w.createPressure({ body, insidePressure: NaN }), embra.InvalidArgumentError, 'embra_pressure_create: ');
  byC(() => w.createPressure({ body, keepVolume: 2 }), embra.InvalidArgumentError, 'embra_pressure_create: ');
  byC(() => w.createPressure(), embra.InvalidArgumentError, 'embra_pressure_create: '); // the body is required
  byC(() => w.createSurfaceTension({ body, tension: 1.0, version: 0 }), embra.VersionError,
    'embra_surface_tension_create: ');
  byC(() => w.createSurfaceTension({ body, tension: -1.0 }), embra.InvalidArgumentError,
    'embra_surface_tension_create: ');
  byC(() => w.createVortex({ radius: 0.0 }), embra.InvalidArgumentError, 'embra_vortex_create: ');
  byC(() => w.createVortex({ strength: Infinity }), embra.InvalidArgumentError, 'embra_vortex_create: ');
  for (const create of ['createWind', 'createPressure', 'createSurfaceTension', 'createVortex']) {
    assert.throws(() => w[create]({ body: new embra.BodyId(7, 1) }),
      (e) => e instanceof embra.StaleIdError && /^embra_\w+_create: /.test(e.message));
  }
  byC(() => w.destroyField(new embra.FieldId(5, 1)), embra.StaleIdError, 'embra_field_destroy: ');
  assert.throws(() => w.createWind({ velocity: 3.0 }),
    { name: 'TypeError', message: /WindDef has no field 'velocity'/ });
  assert.throws(() => w.destroyField(body), { name: 'TypeError', message: /expected a FieldId/ });
  assert.deepEqual([w.fieldCount, snapshot(w)], before);
  w.close();
  assert.throws(() => w.fieldCount,
    (e) => e instanceof embra.InvalidArgumentError && /world is NULL.*closed/.test(e.message));
});
