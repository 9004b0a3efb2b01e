'use strict';
// A scene's OBJ paths resolve against its folder (the file's folder for World.loadFile, baseDir for
// World.loadJson) and may not leave it unless the host allows it ({ allowPathsOutsideBase: true }).

const assert = require('node:assert/strict');
const fs = require('node:fs');
const path = require('node:path');
const test = require('node:test');

const { embra, tempDir } = require('./helpers');

const OBJ = 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n'; // one quad: 4 vertices

function scene(obj) {
  return JSON.stringify({
    format: 'embra-scene', version: 1, name: 'obj_scene',
    bodies: [{ name: 'sheet', mesh: { obj }, material: { mass: 0.5 } }],
  });
}

/** root/outside.obj, root/scenes/inside.obj and scenes in root/scenes naming each. */
function folders() {
  const root = tempDir('load');
  const scenes = path.join(root, 'scenes');
  fs.mkdirSync(scenes);
  fs.writeFileSync(path.join(root, 'outside.obj'), OBJ);
  fs.writeFileSync(path.join(scenes, 'inside.obj'), OBJ);
  fs.writeFileSync(path.join(scenes, 'inside.json'), scene('inside.obj'));
  fs.writeFileSync(path.join(scenes, 'outside.json'), scene('../outside.obj'));
  fs.writeFileSync(path.join(scenes, 'absolute.json'), scene(path.join(root, 'outside.obj')));
  return { root, scenes };
}

function loaded(world) {
  const n = world.particleCount;
  world.close();
  return n;
}

test('OBJ paths resolve against the scene\'s folder, not the process\'s', () => {
  const { root, scenes } = folders();
  const cwd = process.cwd();
  process.chdir(root);
  try {
    assert.equal(loaded(embra.World.loadFile(path.join(scenes, 'inside.json'))), 4);
    const text = fs.readFileSync(path.join(scenes, 'inside.json'), 'utf8');
    assert.equal(loaded(embra.World.loadJson(text, scenes)), 4);
    assert.equal(loaded(embra.World.loadFile(path.join('scenes', 'inside.json'), { allowPathsOutsideBase: true })), 4);
  } finally {
    process.chdir(cwd);
  }
});

for (const name of ['outside.json', 'absolute.json']) {
  test(`OBJ paths out of the scene's folder are refused unless allowed (${name})`, () => {
    const { scenes } = folders();
    const file = path.join(scenes, name);
    const text = fs.readFileSync(file, 'utf8');
    const obj = JSON.parse(text).bodies[0].mesh.obj;
    assert.throws(() => embra.World.loadFile(file), (e) => e instanceof embra.EmbraError &&
      e.message.startsWith('embra_world_load_file: ') && e.message.includes(obj));
    assert.throws(() => embra.World.loadJson(text, scenes), (e) => e instanceof embra.EmbraError &&
      e.message.startsWith('embra_world_load_json_with_options: ') && e.message.includes(obj));
    // the host that trusts the scene says so
    assert.equal(loaded(embra.World.loadFile(file, { allowPathsOutsideBase: true })), 4);
    assert.equal(loaded(embra.World.loadJson(text, scenes, { allow_paths_outside_base: true })), 4);
  });
}

test('the option is true or false, and nothing else is taken', () => {
  const { scenes } = folders();
  const file = path.join(scenes, 'outside.json');
  const text = fs.readFileSync(file, 'utf8');
  for (const value of ['yes', 1, null]) {
    assert.throws(() => embra.World.loadFile(file, { allowPathsOutsideBase: value }), TypeError);
    assert.throws(() => embra.World.loadJson(text, scenes, { allowPathsOutsideBase: value }), TypeError);
  }
  assert.throws(() => embra.World.loadJson(text, scenes, { allowOutside: true }), /unknown option 'allow_outside'/);
  assert.throws(() => embra.World.loadFile(path.join(scenes, 'missing.json'), { allowPathsOutsideBase: true }),
    /ENOENT/);
  const o = embra.defaultLoadOptions();
  assert.deepEqual([o.version, o.allow_paths_outside_base, o.base_dir], [embra.capi.LOAD_OPTIONS_VERSION, 0, null]);
});
