// Replay of an `embra run SCENE --out DIR --every K` folder (docs/live-protocol.md, "The replay
// folder"): final.json gives names, colliders, pins and tolerances, metrics.jsonl the plot,
// frame_NNNNN.obj (+ frame_NNNNN.errors.json) the geometry and colour map of every K-th frame, and
// final.obj (+ final.errors.json) the last state. The folder comes from a directory picker, from
// dropped files, or over http: `?replay=URL` reads URL/index.json, which `embra run` writes (the
// files of the run, and each OBJ frame's collider poses); without one only final.* and
// metrics.jsonl are read.

import { parseObj, parseObjPositions } from './obj.js';

export const DEFAULT_TOLERANCES = {
  unit_scale: 1,
  planarity: { target: 1e-6, max: 1e-4 },
  thickness: { target: 5e-5, max: 1e-3 },
  miter: { target: 1e-3, max: 1e-2 },
};

const FRAME_OBJ = /^frame_(\d+)\.obj$/;

/** A folder as a map from file name to a function reading it as text. */
export function folderFromFiles(fileList) {
  const files = new Map();
  for (const file of fileList) files.set(file.name, () => file.text());
  return files;
}

/** A folder served over http; `base` is its URL (with or without a trailing slash). */
export async function folderFromUrl(base) {
  const root = new URL(base.endsWith('/') ? base : `${base}/`, window.location.href);
  const read = (name) => async () => {
    const response = await fetch(new URL(name, root));
    if (!response.ok) throw new Error(`HTTP ${response.status}`);
    return response.text();
  };
  let names;
  try {
    const listing = JSON.parse(await read('index.json')());
    names = Array.isArray(listing) ? listing : listing.files;
    if (!Array.isArray(names)) throw new Error('index.json lists no files');
  } catch (err) {
    console.warn(`replay: index.json: ${err.message}; reading final.* and metrics.jsonl only`);
    const guesses = ['final.json', 'final.obj', 'final.errors.json', 'metrics.jsonl'];
    const found = await Promise.all(guesses.map((name) => fetch(new URL(name, root), { method: 'HEAD' })
      .then((r) => r.ok, () => false)));
    names = guesses.filter((_, k) => found[k]);
  }
  const files = new Map();
  for (const name of names) files.set(String(name).split('/').pop(), read(name));
  return files;
}

async function readJson(files, name) {
  if (!files.has(name)) return null;
  try {
    return JSON.parse(await files.get(name)());
  } catch (err) {
    throw new Error(`${name}: ${err.message}`);
  }
}

function parseMetrics(text) {
  const rows = [];
  for (const line of text.split('\n')) {
    if (line.trim()) rows.push(JSON.parse(line));
  }
  return rows;
}

function colliderOf(def, index) {
  return {
    index,
    name: def.name || `collider${index}`,
    shape: def.shape,
    radius: def.radius ?? 1,
    position: def.position || [0, 0, 0],
    rotation: def.rotation || [1, 0, 0, 0],
    half_extents: def.half_extents || [0.5, 0.5, 0.5],
    half_length: def.half_length ?? 0.5,
    vertices: (def.vertices || []).flat(),
    triangles: (def.triangles || []).flat(),
  };
}

/** The scene message's shape, made from final.json, the first OBJ and an errors file. */
function sceneOf(final, obj, errors, metrics) {
  const particles = obj.positions.length / 3;
  const defs = final?.bodies || [];
  const panelBodies = new Set((final?.panel_meshes || []).map((p) => p.body));
  const firsts = [];
  let first = 0;
  for (const def of defs) {
    firsts.push(first);
    first += def.mesh?.vertices?.length || 0;
  }
  const bodies = [];
  const indices = [...new Set([...obj.bodies.keys(), ...obj.edges.keys()])].sort((a, b) => a - b);
  for (const index of indices) {
    const triangles = obj.bodies.get(index) || [];
    const edges = obj.edges.get(index) || [];
    const def = defs[index] || {};
    let lo = Infinity;
    let hi = -1;
    for (const p of [...triangles, ...edges]) {
      lo = Math.min(lo, p);
      hi = Math.max(hi, p);
    }
    bodies.push({
      index,
      name: def.name || `body_${index}`,
      first: firsts[index] ?? (hi >= 0 ? lo : 0),
      count: def.mesh?.vertices?.length ?? (hi >= 0 ? hi - lo + 1 : 0),
      triangles,
      edges,
      panel_mesh: panelBodies.has(def.name),
      rest_scale: def.rest_scale || [1, 1, 1],
    });
  }
  const bodyFirst = new Map(defs.map((d, k) => [d.name, firsts[k]]));
  const pins = [];
  (final?.pins || []).forEach((pin, index) => {
    let particle = pin.particle;
    if (particle && typeof particle === 'object') particle = (bodyFirst.get(particle.body) ?? NaN) + particle.vertex;
    if (Number.isInteger(particle) && particle >= 0 && particle < particles) {
      pins.push({ index, name: pin.name || `pin${index}`, particle, target: pin.target || null });
    }
  });
  const colliders = (final?.colliders || []).map(colliderOf);
  const fields = errors ? Object.keys(errors.fields || {}) : [];
  const tolerances = errors?.tolerances || final?.tolerances || DEFAULT_TOLERANCES;
  const solver = final?.solver || {};
  return {
    type: 'scene',
    name: final?.name || 'replay',
    description: final?.description || '',
    dt: solver.dt || 0,
    frames: final?.frames || (metrics.length ? metrics[metrics.length - 1].frame : 0),
    particles,
    paused: true,
    gravity: solver.gravity || [0, 0, -9.81],
    gravity_on: true,
    pins_on: true,
    bodies,
    colliders,
    pins,
    groups: final?.groups || [],
    fields,
    tolerances,
  };
}

/** A loaded replay folder: scene, metrics rows, the frames with geometry, and frameData(i). */
export async function openReplay(files) {
  const final = await readJson(files, 'final.json');
  const metrics = files.has('metrics.jsonl') ? parseMetrics(await files.get('metrics.jsonl')()) : [];
  const finalErrors = files.has('final.errors.json') ? await readJson(files, 'final.errors.json') : null;
  const frames = [];
  for (const name of files.keys()) {
    const match = FRAME_OBJ.exec(name);
    if (!match) continue;
    const errors = name.replace(/\.obj$/, '.errors.json');
    frames.push({ frame: Number(match[1]), obj: name, errors: files.has(errors) ? errors : null });
  }
  frames.sort((a, b) => a.frame - b.frame);
  if (files.has('final.obj')) {
    const frame = finalErrors?.frame ?? final?.state?.frame ?? (metrics.length ? metrics[metrics.length - 1].frame : null);
    if (frame === null || !frames.some((f) => f.frame === frame)) {
      frames.push({ frame: frame ?? (frames.length ? frames[frames.length - 1].frame + 1 : 0), obj: 'final.obj',
        errors: files.has('final.errors.json') ? 'final.errors.json' : null, final: true });
    }
  }
  if (frames.length === 0) throw new Error('no frame_NNNNN.obj or final.obj in the folder');

  const firstObj = parseObj(await files.get(frames[0].obj)());
  const errorsName = frames.find((f) => f.errors)?.errors;
  const sampleErrors = errorsName === 'final.errors.json' ? finalErrors : errorsName ? await readJson(files, errorsName) : null;
  const scene = sceneOf(final, firstObj, sampleErrors, metrics);
  // Collider poses per frame from the run's index.json (written by `embra run`); a folder without
  // one shows the colliders where final.json has them.
  const index = files.has('index.json') ? await readJson(files, 'index.json') : null;
  const indexed = new Map((index?.frames || []).map((f) => [f.obj, f.colliders]));

  const cache = new Map();
  const posesAt = (entry) => {
    const poses = new Float32Array(7 * scene.colliders.length);
    const recorded = indexed.get(entry.obj);
    for (const c of scene.colliders) {
      const pose = recorded?.[c.index];
      poses.set(pose && pose.length === 7 ? pose : [...c.position, ...c.rotation], 7 * c.index);
    }
    return poses;
  };

  async function load(entry) {
    const positions = entry === frames[0] ? firstObj.positions : parseObjPositions(await files.get(entry.obj)(), scene.particles);
    let errors = null;
    if (entry.errors) errors = entry.errors === 'final.errors.json' ? finalErrors : await readJson(files, entry.errors);
    const fields = scene.fields.map((name) => {
      const values = errors?.fields?.[name];
      const out = new Float64Array(scene.particles).fill(NaN); // doubles: colours exactly as from the file
      if (values) values.forEach((v, k) => { if (v !== null && k < out.length) out[k] = v; });
      return out;
    });
    return { frame: entry.frame, positions, poses: posesAt(entry), fields, hasErrors: !!errors };
  }

  return {
    scene,
    metrics,
    frames,
    /** Geometry, collider poses and error fields of frames[i] (cached). */
    frameData(i) {
      if (!cache.has(i)) cache.set(i, load(frames[i]).catch((err) => { cache.delete(i); throw err; }));
      return cache.get(i);
    },
  };
}
