'use strict';
// Every refusal is the EmbraError subclass of its C status carrying the C message verbatim (or a
// TypeError / RangeError for what JS refuses before C), and changes nothing: the world's positions,
// velocities, counts, tolerances and saved scene are as before the refused call.

const assert = require('node:assert/strict');
const test = require('node:test');

const { embra, snapshot } = require('./helpers');

const SQUARE = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]];
const SQUARE_TRIS = [[0, 1, 2], [0, 2, 3]];

function square() {
  const w = new embra.World();
  w.createBody(SQUARE, { triangles: SQUARE_TRIS, mass: 1.0 });
  w.step(3);
  return w;
}

/** Runs `fn`, which must throw an instance of `cls` whose message matches `pattern`; returns the error. */
function refused(fn, cls, pattern) {
  let error = null;
  try {
    fn();
  } catch (e) {
    error = e;
  }
  assert.ok(error !== null, `expected ${cls.name}, nothing was thrown`);
  assert.ok(error instanceof cls, `expected ${cls.name}, got ${error && error.name}: ${error && error.message}`);
  if (pattern) assert.match(error.message, pattern);
  return error;
}

/** An EmbraError of `cls` from C: its message is the C library's last message, starting with `fn`. */
function refusedByC(fn, cls, cFunction, pattern) {
  const e = refused(fn, cls, pattern);
  assert.ok(e instanceof embra.EmbraError);
  assert.equal(e.status, cls.STATUS);
  assert.ok(e.message.startsWith(`${cFunction}: `), `'${e.message}' does not start with ${cFunction}`);
  assert.equal(e.message, embra.lastErrorMessage(), 'the C message, verbatim');
  return e;
}

test('an out-of-range particle index', () => {
  const w = square();
  const before = snapshot(w);
  const e = refusedByC(() => w.createPin(4, [0, 0, 0]), embra.InvalidArgumentError, 'embra_pin_create');
  assert.equal(e.status, -1);
  assert.equal(e.statusName, 'EMBRA_ERROR_INVALID_ARGUMENT');
  assert.equal(e.name, 'InvalidArgumentError');
  refusedByC(() => w.positions(2, 5), embra.InvalidArgumentError, 'embra_world_get_positions');
  refusedByC(() => w.addConstraints('distance', [[0, 1], [2, 99]]), embra.InvalidArgumentError,
    'embra_constraints_add');
  refusedByC(() => w.createBody(SQUARE, { triangles: [[0, 1, 7]] }), embra.InvalidArgumentError, 'embra_body_create');
  refusedByC(() => w.setPositions([[0, 0, 0]], 4), embra.InvalidArgumentError, 'embra_world_set_positions');
  // does not fit the C int32 at all (koffi would wrap it to 0): refused before C
  refused(() => w.createPin(2 ** 40, [0, 0, 0]), RangeError, /particle: 1099511627776 does not fit in int32/);
  refused(() => w.createPin(1.5, [0, 0, 0]), TypeError, /particle: expected an integer/);
  refused(() => w.positions(0, 2 ** 31), RangeError, /count/);
  assert.deepEqual(snapshot(w), before);
  w.close();
});

test('NaN and infinities', () => {
  const w = square();
  const before = snapshot(w);
  refusedByC(() => w.setGravity([0, NaN, 0]), embra.InvalidArgumentError, 'embra_world_set_gravity', /finite/);
  refusedByC(() => w.setPositions([[NaN, 0, 0]], 1), embra.InvalidArgumentError, 'embra_world_set_positions');
  refusedByC(() => w.setVelocities([[0, 0, Infinity]], 1), embra.InvalidArgumentError, 'embra_world_set_velocities');
  refusedByC(() => w.createBody([[0, 0, 0], [1, 0, 0], [0, NaN, 0]], { triangles: [[0, 1, 2]] }),
    embra.InvalidArgumentError, 'embra_body_create');
  refusedByC(() => w.createPin(0, [0, 0, Infinity]), embra.InvalidArgumentError, 'embra_pin_create');
  refusedByC(() => w.setSolver({ dt: NaN }), embra.InvalidArgumentError, 'embra_world_set_solver');
  refusedByC(() => w.setRestScale(new embra.BodyId(0, 1), NaN), embra.InvalidArgumentError,
    'embra_body_set_rest_scale');
  refused(() => w.setGravity([0, '1', 0]), TypeError, /gravity\[1\]: expected a number, got string/);
  assert.deepEqual(snapshot(w), before);
  w.close();
});

test('stale ids: a destroyed pin, group, collider, field', () => {
  const w = square();
  const pin = w.createPin(0, [0, 0, 0]);
  w.destroyPin(pin);
  const group = w.createGroup();
  w.destroyGroup(group);
  const sphere = w.createCollider('sphere', { position: [0, 0, -2], radius: 1.0 });
  w.destroyCollider(sphere);
  const wind = w.createWind({ speed: 1.0 });
  w.destroyField(wind);
  const before = snapshot(w);
  const e = refusedByC(() => w.setPinTarget(pin, [1, 0, 0]), embra.StaleIdError, 'embra_pin_set_target');
  assert.equal(e.statusName, 'EMBRA_ERROR_STALE_ID');
  refusedByC(() => w.destroyPin(pin), embra.StaleIdError, 'embra_pin_destroy');
  refusedByC(() => w.setGroupWeight(group, 3), embra.StaleIdError, 'embra_group_set_weight');
  refusedByC(() => w.addConstraint('distance', [0, 1], { group }), embra.StaleIdError, 'embra_constraint_add');
  refusedByC(() => w.setColliderTransform(sphere, [0, 0, -3]), embra.StaleIdError, 'embra_collider_set_transform');
  refusedByC(() => w.destroyField(wind), embra.StaleIdError, 'embra_field_destroy');
  refusedByC(() => w.bodyParticles(new embra.BodyId(5, 1)), embra.StaleIdError, 'embra_body_get_particles');
  refusedByC(() => w.pinParticle(pin), embra.StaleIdError, 'embra_pin_get_particle');
  refusedByC(() => w.colliderTransform(sphere), embra.StaleIdError, 'embra_collider_get_transform');
  // an id of the wrong kind is refused before C
  refused(() => w.setPinTarget(group, [1, 0, 0]), TypeError, /pin: expected a PinId, got GroupId/);
  assert.deepEqual(snapshot(w), before);
  assert.equal(w.counts().pins, 0);
  assert.equal(w.counts().colliders, 0);
  assert.equal(w.fieldCount, 0);
  w.close();
});

test('use of a closed world', () => {
  const w = new embra.World();
  w.close();
  w.close(); // idempotent
  assert.ok(w.closed);
  for (const call of [() => w.step(), () => w.counts(), () => w.saveJson(), () => w.positions(0, 1),
    () => w.createBody([[0, 0, 0]]), () => w.solver, () => w.tolerances, () => w.bodies(), () => w.pins()]) {
    const e = refused(call, embra.InvalidArgumentError, /world is NULL.*\(this World was closed\)/);
    assert.equal(e.status, embra.capi.ERROR_INVALID_ARGUMENT);
  }
  refused(() => w.step(), embra.InvalidArgumentError, /^embra_world_step: world is NULL/);
});

test('a buffer too small writes nothing', () => {
  const w = square();
  const before = snapshot(w);
  const out = new Float64Array(6).fill(7.0); // room for 2 particles, asked for 4
  const e = refusedByC(() => w.positions(0, 4, out), embra.BufferTooSmallError, 'embra_world_get_positions');
  assert.equal(e.statusName, 'EMBRA_ERROR_BUFFER_TOO_SMALL');
  assert.deepEqual(Array.from(out), [7, 7, 7, 7, 7, 7]);
  refusedByC(() => w.velocities(0, 4, out), embra.BufferTooSmallError, 'embra_world_get_velocities');
  assert.deepEqual(Array.from(out), [7, 7, 7, 7, 7, 7]);
  refused(() => w.positions(0, 2, [0, 0, 0, 0, 0, 0]), TypeError, /out: expected a Float64Array, got an array/);
  assert.deepEqual(snapshot(w), before);
  w.close();
});

test('a bad def version, bad values, unknown fields', () => {
  refusedByC(() => new embra.World({ version: 7 }), embra.VersionError, 'embra_world_create',
    /embra_solver_def.version is 7/);
  refusedByC(() => new embra.World({ dt: -1.0 }), embra.InvalidArgumentError, 'embra_world_create');
  refused(() => new embra.World({ gravty: [0, 0, 1] }), TypeError, /SolverDef has no field 'gravty'/);
  refused(() => new embra.World({ settleSpeed: 1, settle_speed: 2 }), TypeError, /given twice/);
  refused(() => new embra.World({ gravity: [0, 0] }), RangeError, /gravity: expected 3 numbers, got 2/);
  refused(() => new embra.World({ substeps: 2 ** 32 }), RangeError, /does not fit in int32/);
  refusedByC(() => embra.checkAbi(embra.ABI_VERSION + 1), embra.VersionError, 'embra_check_abi');
});

test('a bad scene', () => {
  const e = refusedByC(() => embra.World.loadJson('{"format": "embra-scene", "version": 1, "solver": {"dt": 0}}'),
    embra.SchemaError, 'embra_world_load_json_with_options');
  assert.match(e.message, /\/solver\/dt/);
  refusedByC(() => embra.World.loadJson('{ not json'), embra.SchemaError, 'embra_world_load_json_with_options');
  refusedByC(() => embra.World.loadFile('/nonexistent-embra-dir/scene.json'), embra.InvalidArgumentError,
    'embra_world_load_file');
  refused(() => embra.World.loadFile('a\0b'), RangeError, /NUL/);
  refused(() => embra.World.loadJson(42), TypeError, /text: expected a string or a Uint8Array/);
});

test('wrong lengths and types are refused before C', () => {
  const w = square();
  const before = snapshot(w);
  refused(() => w.setPositions([0.0, 1.0]), RangeError, /whole number of xyz/);
  refused(() => w.createBody(SQUARE, { triangles: SQUARE_TRIS, masses: [1.0, 1.0] }), RangeError, /masses/);
  refused(() => w.createBody(SQUARE, { triangles: [0, 1] }), RangeError, /triangles: 2 indices/);
  refused(() => w.createBody(SQUARE, { triangles: SQUARE_TRIS, stiffness: 2 }), TypeError,
    /Material has no field 'stiffness'/);
  refused(() => w.addConstraints('distance', [[0, 1], [1, 2]], { rest: [1.0] }), RangeError, /rest/);
  refused(() => w.addConstraint('distance', [0, 1, 2]), RangeError, /takes 2 particles/);
  refused(() => w.addConstraint('spring', [0, 1]), RangeError, /unknown name 'spring'/);
  refused(() => w.createCollider('cone'), RangeError, /unknown name 'cone'/);
  refused(() => w.createPin(0, [0, 0, 0], { stiff: true }), TypeError, /unknown option 'stiff'/);
  refused(() => w.setColliderTransform(new embra.ColliderId(), [0, 0, 0], [1, 0, 0]), RangeError, /rotation/);
  refused(() => w.createBody(SQUARE, { triangles: [[0, 1, 2.5]] }), TypeError, /triangles\[0\]\[2\]/);
  refused(() => w.step(-1), RangeError, /negative/);
  assert.deepEqual(snapshot(w), before);
  w.close();
});

test('a step that goes non-finite restores the world and records where', () => {
  // 1e300 m/s, the largest value a world accepts, overflows in the step (the stretch constraints
  // square lengths of 1e297 m)
  const w = square();
  w.setVelocities([[embra.capi.MAX_ABS_VALUE, 0.0, 0.0]], 1);
  const before = snapshot(w);
  const frame = w.report().frame;
  const e = refusedByC(() => w.step(), embra.NumericalError, 'embra_world_step', /^embra_world_step: non-finite/);
  assert.equal(e.statusName, 'EMBRA_ERROR_NUMERICAL');
  assert.deepEqual(snapshot(w), before);
  assert.equal(w.report().frame, frame);
  assert.equal(w.warning().frame, frame);
  assert.ok(w.warning().particle >= 0);
  w.setVelocities([[0.0, 0.0, 0.0]], 1); // the cause removed, the world steps on
  w.step();
  assert.equal(w.report().frame, frame + 1);
  w.close();
});

test('values beyond the ranges of embra.h are refused and change nothing', () => {
  // |v| > 1e300, masses and positives below 1e-300, dt > 1e6, substeps x iterations > 1e5, unit_scale > 1e12
  const { capi } = embra;
  const big = 1e308;
  const tiny = capi.MIN_POSITIVE / 10;
  const w = square();
  const pin = w.createPin(0, [0, 0, 0]);
  const state = () => ({ ...snapshot(w), solver: w.solver, target: w.pinTarget(pin) });
  const before = state();
  const I = embra.InvalidArgumentError;
  refusedByC(() => w.setVelocities([[big, 0, 0]], 1), I, 'embra_world_set_velocities', /1e\+?300/);
  refusedByC(() => w.setPositions([[0, -2 * capi.MAX_ABS_VALUE, 0]], 2), I, 'embra_world_set_positions');
  refusedByC(() => w.setGravity([0, 0, big]), I, 'embra_world_set_gravity');
  refusedByC(() => w.setPinTarget(pin, [big, 0, 0]), I, 'embra_pin_set_target');
  refusedByC(() => w.createPin(1, [0, big, 0]), I, 'embra_pin_create');
  refusedByC(() => w.createBody(SQUARE, { triangles: SQUARE_TRIS, masses: [1, 1, 1, tiny] }), I, 'embra_body_create');
  refusedByC(() => w.setSolver({ dt: 2 * capi.MAX_DT }), I, 'embra_world_set_solver');
  refusedByC(() => w.setSolver({ dt: tiny }), I, 'embra_world_set_solver');
  refusedByC(() => w.setSolver({ substeps: 1000, iterations: capi.MAX_PASSES_PER_STEP / 1000 + 1 }), I,
    'embra_world_set_solver');
  refusedByC(() => w.setTolerances({ unitScale: 10 * capi.MAX_UNIT_SCALE }), I, 'embra_world_set_tolerances');
  refusedByC(() => w.createCollider('sphere', { position: [0, 0, big], radius: 1 }), I, 'embra_collider_create');
  assert.deepEqual(state(), before);
  w.close();
});

test('values at the limits are accepted, and the saved scene loads back', () => {
  const { capi } = embra;
  const top = capi.MAX_ABS_VALUE;
  const w = new embra.World({ dt: capi.MAX_DT, substeps: 1000, iterations: capi.MAX_PASSES_PER_STEP / 1000,
    gravity: [top, -top, 0] });
  w.createBody([[top, 0, -top]], { masses: [capi.MIN_POSITIVE] }); // one particle each: no element measure
  w.createBody([[0, top, 0]], { masses: [top] });
  w.createPin(0, [-top, top, top]);
  w.setTolerances({ unitScale: capi.MAX_UNIT_SCALE });
  const text = w.saveJson();
  const back = embra.World.loadJson(text);
  assert.equal(back.saveJson(), text);
  assert.deepEqual(back.positions(), w.positions());
  back.close();
  w.close();
});

test('refused panel calls and queries raise the C message and change nothing', () => {
  const w = new embra.World();
  const body = w.createPanelMesh({ grid_columns: 2, grid_rows: 2, pins: 'top_corners' });
  const plain = w.createBody([[0, 0, 0], [1, 0, 0], [0, 1, 0]], { triangles: [[0, 1, 2]], mass: 1.0 });
  w.step(5);
  const before = snapshot(w);
  refusedByC(() => w.createPanelMesh({ version: 99 }), embra.VersionError, 'embra_panel_mesh_create', /99/);
  refusedByC(() => w.createPanelMesh({ panelSize: NaN }), embra.InvalidArgumentError, 'embra_panel_mesh_create',
    /panel size must be finite/);
  refusedByC(() => w.createPanelMesh({ thickness: -1.0 }), embra.InvalidArgumentError, 'embra_panel_mesh_create',
    /thickness/);
  refusedByC(() => w.createPanelMesh({ positions: SQUARE, quads: [[0, 1, 2, 9]] }), embra.InvalidArgumentError,
    'embra_panel_mesh_create');
  refused(() => w.createPanelMesh({ positions: SQUARE, quads: [0, 1, 2] }), RangeError, /4-tuples/);
  refused(() => w.createPanelMesh({ pins: 'bottom' }), RangeError, /unknown name 'bottom'/);
  refused(() => w.createPanelMesh({ positions: SQUARE }), TypeError, /positions and quads go together/);
  const queries = {
    embra_panel_mesh_get_panel_count: (b) => w.panelCount(b),
    embra_panel_mesh_get_metrics: (b) => w.panelMetrics(b),
    embra_panel_mesh_get_vertex_errors: (b) => w.vertexErrors(b, 'miter'),
    embra_panel_mesh_export_cuts: (b) => w.exportCuts(b),
  };
  for (const [cFunction, call] of Object.entries(queries)) {
    refusedByC(() => call(new embra.BodyId(7, 1)), embra.StaleIdError, cFunction); // no such body
    refusedByC(() => call(plain), embra.InvalidArgumentError, cFunction, /not a panel mesh/);
  }
  refusedByC(() => w.vertexErrors(body, 9), embra.InvalidArgumentError, 'embra_panel_mesh_get_vertex_errors',
    /metric 9/);
  refusedByC(() => w.exportCuts(body, 7), embra.InvalidArgumentError, 'embra_panel_mesh_export_cuts', /format/);
  refused(() => w.exportCuts(body, 'xml'), RangeError, /unknown name 'xml'/);
  refusedByC(() => w.setTolerances({ miter: { target: 2.0, max: 1.0 } }), embra.InvalidArgumentError,
    'embra_world_set_tolerances', /miter.target is above/);
  refusedByC(() => { w.tolerances = { unitScale: NaN }; }, embra.InvalidArgumentError,
    'embra_world_set_tolerances', /unit_scale/);
  refusedByC(() => w.panelMetrics(body, { version: 2 }), embra.VersionError, 'embra_panel_mesh_get_metrics');
  const out = new Float64Array(31).fill(7.0); // 4 panels: 32 values needed
  refusedByC(() => w.vertexErrors(body, 'planarity', out), embra.BufferTooSmallError,
    'embra_panel_mesh_get_vertex_errors', /buffer holds 31/);
  assert.deepEqual(Array.from(out), new Array(31).fill(7.0));
  assert.deepEqual(snapshot(w), before);
  w.close();
  refused(() => w.panelMetrics(body), embra.InvalidArgumentError, /world is NULL.*closed/);
});
