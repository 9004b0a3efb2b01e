'use strict';
// The current form as files a designer opens elsewhere: glTF 2.0 (one .gltf, its buffer embedded)
// and Rhino .3dm (rhino3dm, openNURBS), with a fabrication error field as vertex colours in the
// paper's convention (colors.js).
//
// A "snapshot" is {name, positions: Float64Array (xyz per particle), meshes: [{name, triangles:
// Int32Array of world particle indices}], colors: Float32Array (rgb in [0, 1] per particle) or
// null}. Each mesh is written with its own vertices (the particles its triangles use, in
// increasing particle order), so a panel mesh's top and bottom layers stay separate objects'
// geometry exactly as the solver holds them.

const fs = require('fs');
const path = require('path');
const { errorColor } = require('./colors');

/** Per-particle RGB for one error field against its tolerance; NaN/null values are "not measured". */
function fieldColors(metric, values, tolerance) {
  const out = new Float32Array(values.length * 3);
  for (let i = 0; i < values.length; ++i) out.set(errorColor(metric, values[i], tolerance), 3 * i);
  return out;
}

/** The particles a mesh uses, ascending, and its triangles re-indexed onto them. */
function compact(triangles) {
  const used = Array.from(new Set(triangles)).sort((a, b) => a - b);
  const local = new Map(used.map((p, i) => [p, i]));
  const indices = new Uint32Array(triangles.length);
  for (let k = 0; k < triangles.length; ++k) indices[k] = local.get(triangles[k]);
  return { used, indices };
}

function checkSnapshot(s) {
  if (!s || !(s.positions instanceof Float64Array) || s.positions.length % 3 !== 0)
    throw new TypeError('snapshot.positions must be a Float64Array of xyz triples');
  const n = s.positions.length / 3;
  if (!Array.isArray(s.meshes) || s.meshes.length === 0) throw new TypeError('snapshot.meshes must be a non-empty array');
  for (const m of s.meshes) {
    if (!m.triangles || m.triangles.length === 0 || m.triangles.length % 3 !== 0)
      throw new TypeError(`mesh ${m.name}: triangles must be a non-empty list of index triples`);
    for (const i of m.triangles)
      if (!Number.isInteger(i) || i < 0 || i >= n) throw new RangeError(`mesh ${m.name}: particle ${i} is outside [0, ${n})`);
  }
  if (s.colors && s.colors.length !== 3 * n) throw new TypeError('snapshot.colors must hold 3 numbers per particle');
  for (const v of s.positions) if (!Number.isFinite(v)) throw new RangeError('snapshot.positions holds a non-finite number');
}

/**
 * glTF 2.0 as one JSON document (the binary buffer as a base64 data URI): a node and mesh per
 * body, POSITION (float32) and COLOR_0 (float32 rgb, linear) per vertex, uint32 indices. glTF is
 * y-up; embra and Rhino are z-up, so the root node turns z-up into y-up (a -90 degree turn about x).
 */
function toGltf(snapshot) {
  checkSnapshot(snapshot);
  const chunks = [];
  let length = 0;
  const views = [];
  const accessors = [];
  const meshes = [];
  const push = (typed, target) => {
    const bytes = Buffer.from(typed.buffer, typed.byteOffset, typed.byteLength);
    views.push({ buffer: 0, byteOffset: length, byteLength: bytes.length, target });
    chunks.push(bytes);
    length += bytes.length;
    const pad = (4 - (length % 4)) % 4;
    if (pad) {
      chunks.push(Buffer.alloc(pad));
      length += pad;
    }
    return views.length - 1;
  };
  for (const m of snapshot.meshes) {
    const { used, indices } = compact(m.triangles);
    const pos = new Float32Array(used.length * 3);
    const lo = [Infinity, Infinity, Infinity];
    const hi = [-Infinity, -Infinity, -Infinity];
    used.forEach((p, i) => {
      for (let k = 0; k < 3; ++k) {
        const v = Math.fround(snapshot.positions[3 * p + k]);
        pos[3 * i + k] = v;
        lo[k] = Math.min(lo[k], v);
        hi[k] = Math.max(hi[k], v);
      }
    });
    const attributes = {};
    accessors.push({ bufferView: push(pos, 34962), componentType: 5126, count: used.length, type: 'VEC3', min: lo, max: hi });
    attributes.POSITION = accessors.length - 1;
    if (snapshot.colors) {
      const col = new Float32Array(used.length * 3);
      used.forEach((p, i) => col.set(snapshot.colors.subarray(3 * p, 3 * p + 3), 3 * i));
      accessors.push({ bufferView: push(col, 34962), componentType: 5126, count: used.length, type: 'VEC3' });
      attributes.COLOR_0 = accessors.length - 1;
    }
    accessors.push({ bufferView: push(indices, 34963), componentType: 5125, count: indices.length, type: 'SCALAR' });
    meshes.push({ name: m.name, primitives: [{ attributes, indices: accessors.length - 1, mode: 4, material: 0 }] });
  }
  const data = Buffer.concat(chunks);
  return {
    asset: { version: '2.0', generator: 'embra' },
    scene: 0,
    scenes: [{ name: snapshot.name, nodes: [0] }],
    nodes: [
      { name: snapshot.name, rotation: [-Math.SQRT1_2, 0, 0, Math.SQRT1_2], children: meshes.map((_, i) => i + 1) },
      ...meshes.map((m, i) => ({ name: m.name, mesh: i })),
    ],
    meshes,
    materials: [{ name: 'embra-error-colours', doubleSided: true,
                  pbrMetallicRoughness: { baseColorFactor: [1, 1, 1, 1], metallicFactor: 0, roughnessFactor: 0.8 } }],
    accessors,
    bufferViews: views,
    buffers: [{ byteLength: data.length, uri: `data:application/octet-stream;base64,${data.toString('base64')}` }],
  };
}

let rhinoModule = null;
let rhinoMemory = null;

/**
 * rhino3dm's WebAssembly module, loaded once (concurrent first calls share the load). The module is
 * instantiated here (Emscripten's instantiateWasm hook) only to keep its memory in view for
 * rhinoHeapBytes; the bytes and imports are rhino3dm's own.
 */
function rhino() {
  if (!rhinoModule) {
    rhinoModule = new Promise((resolve, reject) => {
      const wasm = path.join(path.dirname(require.resolve('rhino3dm')), 'rhino3dm.wasm');
      require('rhino3dm')({
        instantiateWasm(imports, done) {
          WebAssembly.instantiate(fs.readFileSync(wasm), imports).then(({ instance, module }) => {
            rhinoMemory = Object.values(instance.exports).find((e) => e instanceof WebAssembly.Memory) ||
              (imports.env && imports.env.memory) || null;
            done(instance, module);
          }, reject);
          return {};
        },
      }).then(resolve, reject);
    });
    rhinoModule.catch(() => { rhinoModule = null; }); // a failed load is retried by the next call
  }
  return rhinoModule;
}

/**
 * The size in bytes of rhino3dm's WebAssembly heap (its linear memory, which only ever grows), or
 * 0 before the module is loaded. Every export returns what it allocated, so after the first export
 * this stays the same however many follow.
 */
function rhinoHeapBytes() {
  return rhinoMemory ? rhinoMemory.buffer.byteLength : 0;
}

/**
 * Runs `body(own)` and deletes, whatever happens, every rhino3dm object passed through `own` (which
 * returns its argument). rhino3dm's objects live in the WebAssembly heap until deleted, and every
 * accessor (doc.settings(), doc.objects(), mesh.vertices(), ...) returns a new one.
 */
async function withOwned(body) {
  const owned = [];
  const own = (object) => {
    if (object) owned.push(object);
    return object;
  };
  try {
    return await body(own);
  } finally {
    for (const object of owned.reverse()) release(object);
  }
}

/**
 * Deletes one rhino3dm object through Embind's own `delete` (found on the prototype that defines
 * `isDeleted`): some classes shadow it with a method of their own, File3dmObjectTable.delete(id).
 */
function release(object) {
  let handle = Object.getPrototypeOf(object);
  while (handle && !Object.prototype.hasOwnProperty.call(handle, 'isDeleted')) handle = Object.getPrototypeOf(handle);
  if (!handle) throw new TypeError('not a rhino3dm object');
  if (!handle.isDeleted.call(object)) handle.delete.call(object);
}

/**
 * Rhino .3dm bytes (openNURBS through rhino3dm): a mesh object per body, named after it, with 8-bit
 * vertex colours. Units: metres. Mesh vertices are single precision, as Rhino stores them (a .3dm
 * written by rhino3dm with double-precision vertices reads back rounded to float all the same): a
 * position is the solver's rounded to the nearest float, about 0.1 micrometre at 1 m. Every
 * rhino3dm object it makes is deleted before it returns or throws.
 */
async function to3dm(snapshot) {
  checkSnapshot(snapshot);
  const r = await rhino();
  return withOwned((own) => {
    const doc = own(new r.File3dm());
    own(doc.settings()).modelUnitSystem = r.UnitSystem.Meters;
    const objects = own(doc.objects());
    for (const m of snapshot.meshes) {
      const { used, indices } = compact(m.triangles);
      const mesh = own(new r.Mesh());
      const vertices = own(mesh.vertices());
      for (const p of used) vertices.add(snapshot.positions[3 * p], snapshot.positions[3 * p + 1], snapshot.positions[3 * p + 2]);
      const faces = own(mesh.faces());
      for (let k = 0; k < indices.length; k += 3) faces.addTriFace(indices[k], indices[k + 1], indices[k + 2]);
      if (snapshot.colors) {
        const colors = own(mesh.vertexColors());
        const byte = (v) => Math.max(0, Math.min(255, Math.round(v * 255)));
        for (const p of used)
          colors.add(byte(snapshot.colors[3 * p]), byte(snapshot.colors[3 * p + 1]), byte(snapshot.colors[3 * p + 2]));
      }
      own(mesh.normals()).computeNormals();
      const attributes = own(new r.ObjectAttributes());
      attributes.name = m.name;
      objects.add(mesh, attributes);
    }
    return Buffer.from(doc.toByteArray());
  });
}

/**
 * A .3dm read back: per mesh object its name, vertex positions (xyz doubles), colours and face
 * count. Like to3dm, it deletes every rhino3dm object it makes.
 */
async function read3dm(bytes) {
  const r = await rhino();
  return withOwned((own) => {
    const doc = own(r.File3dm.fromByteArray(new Uint8Array(bytes)));
    if (!doc) throw new Error('not a readable .3dm file');
    const out = [];
    const objects = own(doc.objects());
    for (let i = 0; i < objects.count; ++i) {
      const o = own(objects.get(i));
      const g = own(o.geometry());
      if (!(g instanceof r.Mesh)) continue;
      const v = own(g.vertices());
      const positions = new Float64Array(v.count * 3);
      for (let k = 0; k < v.count; ++k) positions.set(v.get(k), 3 * k);
      const c = own(g.vertexColors());
      const colors = [];
      for (let k = 0; k < c.count; ++k) {
        const { r: red, g: green, b: blue } = c.get(k);
        colors.push([red, green, blue]);
      }
      out.push({ name: own(o.attributes()).name, positions, colors, faces: own(g.faces()).count });
    }
    return out;
  });
}

module.exports = { fieldColors, toGltf, to3dm, read3dm, rhinoHeapBytes, compact };
