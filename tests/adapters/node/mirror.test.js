'use strict';
// The generated mirror (lib/capi_generated.js, from embra.h by scripts/gen_bindings.py, kept fresh by
// the test bindings.fresh) as the package uses it: every prototype is loaded from the library, every
// status code has its error class, and the World methods take each enum's generated names.

const assert = require('node:assert/strict');
const test = require('node:test');

const { embra } = require('./helpers');

const { capi } = embra;

test('every prototype is loaded from the library', () => {
  const names = Object.keys(capi.PROTOTYPES);
  assert.ok(names.length > 40, `only ${names.length} prototypes`);
  for (const name of names) assert.equal(typeof capi.lib[name], 'function', `${name} is not loaded from the library`);
  assert.equal(capi.ABI_VERSION, embra.abiVersion());
});

test('every status code has its own error class, which names it', () => {
  const statuses = Object.entries(capi).filter(([k]) => k.startsWith('ERROR_'));
  assert.ok(statuses.some(([k]) => k === 'ERROR_LOCKED') && statuses.some(([k]) => k === 'ERROR_CANCELLED'));
  const classes = new Set();
  for (const [name, status] of statuses) {
    const e = embra.errorFor(status, 'message');
    assert.ok(e instanceof embra.EmbraError && e.constructor !== embra.EmbraError, name);
    assert.equal(e.status, status);
    assert.equal(e.statusName, `EMBRA_${name}`);
    assert.equal(e.message, 'message');
    assert.equal(e.constructor.STATUS, status);
    classes.add(e.constructor);
  }
  assert.equal(classes.size, statuses.length);
  assert.ok(embra.errorFor(capi.ERROR_LOCKED, '') instanceof embra.LockedError);
  assert.ok(embra.errorFor(capi.ERROR_CANCELLED, '') instanceof embra.CancelledError);
});

test('the World methods take the generated names of each enum', () => {
  assert.deepEqual(embra.KINDS, capi.CONSTRAINT_NAMES);
  assert.deepEqual(embra.SHAPES, capi.COLLIDER_NAMES);
  assert.deepEqual(embra.GENERATE, capi.GENERATE_NAMES);
  assert.deepEqual(embra.PANEL_PINS, capi.PANEL_PINS_NAMES);
  assert.deepEqual(embra.PANEL_METRICS, capi.PANEL_METRIC_NAMES);
  assert.deepEqual(embra.CUTS_FORMATS, capi.CUTS_NAMES);
});
