'use strict';
// lib/capi.js mirrors embra.h: every EMBRA_API function is bound (and nothing else), every status
// code, enum value and struct version has the header's value, and the names the World methods
// accept cover each enum.

const assert = require('node:assert/strict');
const fs = require('node:fs');
const path = require('node:path');
const test = require('node:test');

const { embra, sourceDir } = require('./helpers');

const { capi } = embra;
const header = fs.readFileSync(path.join(sourceDir, 'capi', 'include', 'embra', 'embra.h'), 'utf8');

test('every header function is bound, and nothing else', () => {
  const declared = new Set([...header.matchAll(/EMBRA_API[^;(]*?\b(embra_\w+)\s*\(/g)].map((m) => m[1]));
  assert.ok(declared.size > 40, `only ${declared.size} functions found in embra.h`);
  const bound = new Set(Object.keys(capi.PROTOTYPES));
  const missing = [...declared].filter((n) => !bound.has(n));
  const extra = [...bound].filter((n) => !declared.has(n));
  assert.deepEqual(missing, [], `EMBRA_API functions not in lib/capi.js PROTOTYPES: ${missing.join(', ')}`);
  assert.deepEqual(extra, [], `PROTOTYPES names functions embra.h does not declare: ${extra.join(', ')}`);
  for (const name of declared) {
    assert.equal(typeof capi.lib[name], 'function', `${name} is not loaded from the library`);
    // the declaration's name is the C name (koffi binds by it)
    assert.match(capi.PROTOTYPES[name], new RegExp(`\\b${name}\\s*\\(`), name);
  }
});

test('every status code, enum value, def version, range and limit is mirrored with its value', () => {
  const constants = new Map([...header.matchAll(/\bEMBRA_([A-Z0-9_]+)\s*=\s*(-?\d+)/g)].map((m) => [m[1], m[2]]));
  // every numeric #define: def versions and the ranges and limits (1e300, 1e-300, 2097152, ...)
  for (const m of header.matchAll(/^#define\s+EMBRA_([A-Z0-9_]+)\s+([-+0-9.eE]+)\s*$/gm)) constants.set(m[1], m[2]);
  assert.ok(constants.size > 40, `only ${constants.size} constants found in embra.h`);
  assert.ok([...constants.keys()].some((k) => k.endsWith('_DEF_VERSION')), 'no *_DEF_VERSION found');
  for (const name of ['ERROR_CANCELLED', 'LOAD_OPTIONS_VERSION', 'MAX_ABS_VALUE', 'MIN_POSITIVE', 'MAX_DT',
    'MAX_PASSES_PER_STEP', 'MAX_OBJ_BYTES']) assert.ok(constants.has(name), `EMBRA_${name} not found in embra.h`);
  const missing = [];
  for (const [name, value] of constants) {
    if (capi[name] !== Number(value)) missing.push(`EMBRA_${name} = ${value} (capi.${name} is ${capi[name]})`);
  }
  assert.deepEqual(missing, [], `not mirrored in lib/capi.js:\n  ${missing.join('\n  ')}`);
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

test('the names the World methods accept cover each enum', () => {
  const values = (prefix) => Object.entries(capi).filter(([k, v]) => k.startsWith(prefix) &&
    !k.endsWith('_VERSION') && typeof v === 'number').map(([, v]) => v).sort();
  const sorted = (table) => Object.values(table).sort();
  assert.deepEqual(sorted(embra.KINDS), values('CONSTRAINT_'));
  assert.deepEqual(sorted(embra.SHAPES), values('COLLIDER_'));
  assert.deepEqual(sorted(embra.GENERATE), values('GENERATE_'));
  assert.deepEqual(sorted(embra.PANEL_PINS), values('PANEL_PINS_'));
  assert.deepEqual(sorted(embra.PANEL_METRICS), values('PANEL_METRIC_'));
  assert.deepEqual(sorted(embra.CUTS_FORMATS), values('CUTS_'));
});

test('every struct of the header is declared', () => {
  const declared = new Set([...header.matchAll(/typedef struct (embra_\w+) \{/g)].map((m) => m[1]));
  assert.ok(declared.size > 20);
  assert.deepEqual([...declared].sort(), Object.keys(capi.STRUCTS).sort());
});
