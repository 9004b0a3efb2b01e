'use strict';
// The .3dm export returns everything it takes from rhino3dm's WebAssembly heap. Before every
// rhino3dm object was deleted (doc.settings(), doc.objects(), each mesh's vertex, face, colour and
// normal lists), each export of the POQ drape kept about 1.2 MB: the heap reached its 2 GB maximum
// and rhino3dm aborted at export 1,647 (and every later one failed until the server restarted).
// 1,700 exports of that same mesh now leave the heap as it was after the first, in about 5 s.

const assert = require('node:assert/strict');
const path = require('node:path');
const { test } = require('node:test');
const { sourceDir, packageDir, embra } = require('./helpers');

const { fieldColors, to3dm, read3dm, rhinoHeapBytes } = require(path.join(packageDir, 'lib', 'export'));

const EXPORTS = 1700; // beyond the 1,647th, where the leaking export failed
const MB = 1024 * 1024;

function poqSnapshot() {
  const w = embra.World.loadFile(path.join(sourceDir, 'examples', 'poq_drape.json'));
  try {
    w.step(10);
    const body = w.bodies()[0];
    return {
      name: 'poq_drape',
      positions: w.positions(),
      meshes: [{ name: 'poq', triangles: w.bodyTriangles(body) }],
      colors: fieldColors('planarity', w.vertexErrors(body, 'planarity'), w.tolerances.planarity),
    };
  } finally {
    w.close();
  }
}

test(`${EXPORTS} .3dm exports and as many reads leave rhino3dm's heap where the first left it`, async () => {
  const snapshot = poqSnapshot();
  assert.equal(rhinoHeapBytes(), 0, 'rhino3dm is not loaded yet');
  const first = await to3dm(snapshot);
  await read3dm(first);
  const warm = rhinoHeapBytes();
  assert.ok(warm > MB, `rhino3dm's heap is ${warm} bytes after one export`);
  let last = first;
  for (let k = 1; k < EXPORTS; ++k) last = await to3dm(snapshot);
  const afterExports = rhinoHeapBytes();
  // The heap only ever grows, in 64 KiB pages: 1 MB of growth would be 0.6 KB kept per export.
  assert.ok(afterExports - warm <= MB, `the heap grew by ${(afterExports - warm) / MB} MB over ${EXPORTS} exports`);
  for (let k = 0; k < 300; ++k) await read3dm(last);
  assert.ok(rhinoHeapBytes() - warm <= MB, `the heap grew by ${(rhinoHeapBytes() - warm) / MB} MB with the reads`);
  // The last export is as whole as the first.
  const [mesh] = await read3dm(last);
  assert.equal(mesh.name, 'poq');
  assert.equal(mesh.faces, snapshot.meshes[0].triangles.length / 3);
  assert.deepEqual(mesh.positions, (await read3dm(first))[0].positions);
});

test('an export that fails part way deletes what it made, and the next one works', async () => {
  const snapshot = poqSnapshot();
  await to3dm(snapshot);
  const warm = rhinoHeapBytes();
  // A colour that is no number fails part way: after the document, the mesh and its lists exist.
  const bad = { ...snapshot, colors: new Proxy(snapshot.colors, { get: (t, k) => (k === '3' ? Symbol('x') : Reflect.get(t, k)) }) };
  for (let k = 0; k < 200; ++k) await assert.rejects(to3dm(bad));
  assert.ok(rhinoHeapBytes() - warm <= MB, `the heap grew by ${(rhinoHeapBytes() - warm) / MB} MB over 200 failed exports`);
  const [mesh] = await read3dm(await to3dm(snapshot));
  assert.equal(mesh.faces, snapshot.meshes[0].triangles.length / 3);
});
