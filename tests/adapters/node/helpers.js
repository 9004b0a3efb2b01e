'use strict';
// Shared setup of the Node adapter tests.
//
// Environment (set by tests/adapters/CMakeLists.txt): EMBRA_LIBRARY (libembra.so), EMBRA_CLI (the
// `embra` command, the C reference), EMBRA_SOURCE_DIR (the repository).

const assert = require('node:assert/strict');
const { execFileSync } = require('node:child_process');
const fs = require('node:fs');
const os = require('node:os');
const path = require('node:path');

function env(name) {
  const value = process.env[name];
  if (!value) throw new Error(`${name} is not set (run these tests through ctest: tests/adapters/CMakeLists.txt)`);
  return value;
}

const sourceDir = env('EMBRA_SOURCE_DIR');
const cli = env('EMBRA_CLI');
const packageDir = path.join(sourceDir, 'host_adapters', 'node');
const embra = require(path.join(packageDir, 'lib'));

/** A fresh temporary folder, removed when the process exits. */
function tempDir(prefix) {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), `embra-node-${prefix}-`));
  process.on('exit', () => fs.rmSync(dir, { recursive: true, force: true }));
  return dir;
}

/** The 'v' lines of an OBJ written by the `embra` command (%.17g: every double exactly). */
function readObjVertices(file) {
  const out = [];
  for (const line of fs.readFileSync(file, 'utf8').split('\n')) {
    if (line.startsWith('v ')) out.push(...line.trim().split(/\s+/).slice(1, 4).map(Number));
  }
  return Float64Array.from(out);
}

/** Runs the C host (`embra ARGS --out DIR`) and returns DIR. */
function runCli(args, prefix) {
  const out = tempDir(prefix);
  execFileSync(cli, [...args, '--out', out], { stdio: ['ignore', 'ignore', 'inherit'] });
  return out;
}

function bytes(values) {
  const a = values instanceof Float64Array ? values : Float64Array.from(values);
  return Buffer.from(a.buffer, a.byteOffset, a.byteLength);
}

/** The two arrays of doubles hold the same bits (the first difference is named when not). */
function assertSameBits(actual, expected, what) {
  assert.equal(actual.length, expected.length, `${what}: ${actual.length} values, expected ${expected.length}`);
  if (!bytes(actual).equals(bytes(expected))) {
    const i = actual.findIndex((v, k) => !Object.is(v, expected[k]));
    assert.fail(`${what}: value ${i} is ${actual[i]}, the C host's ${expected[i]} (bits differ)`);
  }
}

/** Everything a refused call must leave as it was: positions, velocities, counts, the saved scene. */
function snapshot(world) {
  return {
    positions: bytes(world.positions()).toString('hex'), velocities: bytes(world.velocities()).toString('hex'),
    counts: world.counts(), tolerances: world.tolerances, scene: world.saveJson(),
  };
}

module.exports = {
  embra, sourceDir, cli, packageDir, tempDir, readObjVertices, runCli, bytes, assertSameBits, snapshot,
};
