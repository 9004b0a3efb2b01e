'use strict';
// The Gaudi tent of `embra demo tent` (host_adapters/cli/embra_cli.c), built through the Node adapter
// with the same arithmetic in the same order, gives the bits the C host gives (100 frames); and so does
// examples/gaudi_tent.json loaded through it.

const assert = require('node:assert/strict');
const fs = require('node:fs');
const path = require('node:path');
const test = require('node:test');

const { embra, sourceDir, readObjVertices, runCli, assertSameBits } = require('./helpers');

/** An equilateral triangle of `side` (m) in z = 0, split into rows^2 triangles; its corners. */
function triangleMesh(rows, side) {
  const h = side * Math.sqrt(3.0) / 2.0;
  const xyz = [];
  for (let r = 0; r <= rows; r++) {
    for (let c = 0; c <= rows - r; c++) {
      xyz.push([side * (c + 0.5 * r) / rows - side / 2, h * r / rows - h / 3, 0.0]);
    }
  }
  const idx = (r, c) => r * (rows + 1) - Math.floor((r * (r - 1)) / 2) + c;
  const tri = [];
  for (let r = 0; r < rows; r++) {
    for (let c = 0; c < rows - r; c++) {
      tri.push([idx(r, c), idx(r, c + 1), idx(r + 1, c)]);
      if (c + 1 < rows - r) tri.push([idx(r, c + 1), idx(r + 1, c + 1), idx(r + 1, c)]);
    }
  }
  return { xyz, tri, corners: [idx(0, 0), idx(0, rows), idx(rows, 0)] };
}

/** Steps the tent `frames` frames through the World methods; its positions. */
function runTent(frames = 100, rows = 40) {
  const { xyz, tri, corners } = triangleMesh(rows, 1.0);
  const w = new embra.World({ gravity: [0.0, 0.0, 9.81], damping: 2.0, substeps: 20, iterations: 4,
    settleSpeed: 1e-3 });
  try {
    const stretch = w.createGroup({ order: 0, weight: 2 });
    const bend = w.createGroup({ order: 1, weight: 1 });
    const body = w.createBody(xyz, { triangles: tri, mass: 0.5, stretchCompliance: 1e-2, bend_compliance: 10.0,
      stretchGroup: stretch, bendGroup: bend });
    const pins = corners.map((k) => w.createPin(body.first + k, xyz[k]));
    for (let f = 1; f <= frames; f++) {
      const draw = f < 60 ? f / 60.0 : 1.0; // corners travel inwards over 1 s
      pins.forEach((pin, i) => w.setPinTarget(pin, xyz[corners[i]].map((x) => x * (1.0 - 0.1 * draw))));
      w.step();
    }
    return w.positions(body.first, body.count);
  } finally {
    w.close();
  }
}

const maxZ = (p) => Math.max(...p.filter((_, i) => i % 3 === 2));

test('the tent built in Node matches the C host bit for bit', () => {
  const c = readObjVertices(path.join(runCli(['demo', 'tent', '--frames', '100', '--every', '1000'], 'demo'),
    'final.obj'));
  const node = runTent(100);
  assert.equal(node.length, 3 * 861);
  assertSameBits(node, c, 'tent positions');
  assert.ok(maxZ(node) > 0.05, 'the membrane has risen under reversed gravity');
});

test('the tent scene loaded in Node matches the C host bit for bit', () => {
  const scene = path.join(sourceDir, 'examples', 'gaudi_tent.json');
  const c = readObjVertices(path.join(runCli(['run', scene, '--frames', '100'], 'scene'), 'final.obj'));
  const w = embra.World.loadFile(scene);
  try {
    assert.equal(w.sceneFrames(), 600);
    w.step(100);
    assert.equal(w.report().frame, 100);
    const node = w.positions();
    assertSameBits(node, c, 'scene positions');
    assert.ok(maxZ(node) > 0.05);
  } finally {
    w.close();
  }
});

test('a scene from JSON text steps as the scene from its file', () => {
  const file = path.join(sourceDir, 'examples', 'gaudi_tent.json');
  const a = embra.World.loadFile(file);
  const b = embra.World.loadJson(fs.readFileSync(file, 'utf8'));
  const c = embra.World.loadJson(fs.readFileSync(file)); // UTF-8 bytes
  for (const w of [a, b, c]) w.step(5);
  assertSameBits(b.positions(), a.positions(), 'from text');
  assertSameBits(c.positions(), a.positions(), 'from bytes');
  for (const w of [a, b, c]) w.close();
});

module.exports = { runTent };
