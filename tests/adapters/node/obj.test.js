'use strict';
// World.exportObj and World.writeObj (embra_world_export_obj), read back: the hanging net of
// examples/hanging_net.json (edges, no triangles) as 121 `v` lines, exactly its positions, and its
// 220 links as `l` lines, so an edge-only mesh renders.

const assert = require('node:assert/strict');
const fs = require('node:fs');
const path = require('node:path');
const test = require('node:test');

const { embra, sourceDir, tempDir } = require('./helpers');

test('a hanging net is written with its links as OBJ l lines', () => {
  const scene = path.join(sourceDir, 'examples', 'hanging_net.json');
  const edges = JSON.parse(fs.readFileSync(scene, 'utf8')).bodies[0].mesh.edges;
  const world = embra.World.loadFile(scene);
  world.step(20);
  const file = path.join(tempDir('obj'), 'net.obj');
  world.writeObj(file);
  const text = fs.readFileSync(file, 'utf8');
  assert.equal(text, world.exportObj());
  const lines = text.split('\n');
  const v = lines.filter((l) => l.startsWith('v ')).flatMap((l) => l.split(' ').slice(1).map(Number));
  assert.deepEqual(v, Array.from(world.positions()).flat(Infinity).map(Number)); // %.17g: exact
  assert.ok(Math.min(...v.filter((_, k) => k % 3 === 2)) < -0.01); // stepped: the net has sagged
  assert.equal(lines.filter((l) => l.startsWith('f ')).length, 0);
  const { first } = world.bodyParticles(world.bodies()[0]);
  const got = lines.filter((l) => l.startsWith('l ')).sort();
  const expected = edges.map(([a, b]) => `l ${first + a + 1} ${first + b + 1}`).sort();
  assert.equal(got.length, 220);
  assert.deepEqual(got, expected);
  const before = world.saveJson();
  assert.throws(() => world.writeObj(path.join(tempDir('obj'), 'missing', 'net.obj')), /missing/);
  assert.equal(world.saveJson(), before);
  world.close();
});
