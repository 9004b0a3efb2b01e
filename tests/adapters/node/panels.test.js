'use strict';
// Planar Offset Quad panel meshes through Node: the paper's 4 x 4 drape of examples/poq_drape.json,
// built with the World methods from the scene's own numbers, gives the bits the C host gives for the
// scene after 150 frames (positions bit-identical, cut lists byte-identical, metrics equal); the
// scene loaded through the adapter steps as the one built; vertex errors are bounded by the metrics.

const assert = require('node:assert/strict');
const fs = require('node:fs');
const path = require('node:path');
const test = require('node:test');

const { embra, sourceDir, readObjVertices, runCli, assertSameBits } = require('./helpers');

const FRAMES = 150; // the posts drawn in (frames 0-30), the drape settled, and the sphere on its way (120-180)
const scenePath = path.join(sourceDir, 'examples', 'poq_drape.json');
const scene = JSON.parse(fs.readFileSync(scenePath, 'utf8'));

/** A scene action's value at `frame`: linear between the keys around it, held outside them (the
 * arithmetic of the scene player, in the same order). */
function keyed(keys, frame) {
  let hi = 0;
  while (hi < keys.length && keys[hi].frame < frame) hi++;
  if (hi === 0) return keys[0].value.map(Number);
  if (hi === keys.length) return keys[keys.length - 1].value.map(Number);
  const a = keys[hi - 1];
  const b = keys[hi];
  const t = (frame - a.frame) / (b.frame - a.frame);
  return a.value.map((x, i) => (1.0 - t) * x + t * b.value[i]);
}

/** The drape rebuilt through World methods from the scene file's numbers, stepped with its actions
 * applied before each frame, as the scene player does. */
class Drape {
  constructor() {
    const s = scene.solver;
    const p = scene.panel_meshes[0];
    const ball = scene.colliders[0];
    this.world = new embra.World({ dt: s.dt, substeps: s.substeps, iterations: s.iterations, gravity: s.gravity,
      settle_speed: s.settle_speed });
    assert.equal(p.generator, 'grid');
    this.body = this.world.createPanelMesh({ gridColumns: p.columns, gridRows: p.rows, panelSize: p.panel_size,
      origin: p.origin, thickness: p.thickness, mass: p.mass, damping: p.damping,
      slideCompliance: p.slide_compliance, pins: p.pins });
    this.ball = this.world.createCollider(ball.shape, { position: ball.position, radius: ball.radius });
    const { format, version, ...tolerances } = scene.tolerances;
    assert.deepEqual([format, version], ['embra-tolerances', 1]);
    this.world.tolerances = tolerances;
    // The corner pins createPanelMesh made are the world's first four: ids {k, 1} in creation order,
    // the order the scene names them poq.pin0..3 (checked against the actions' first keys).
    this.pins = new Map([0, 1, 2, 3].map((k) => [`${p.name}.pin${k}`, new embra.PinId(k, 1)]));
    assert.deepEqual(this.world.pins().map(String), [...this.pins.values()].map(String));
    assert.deepEqual([0, 1, 2, 3].map((k) => this.world.pinParticle(this.pins.get(`${p.name}.pin${k}`))),
      [0, 8 * (p.columns - 1) + 1, 8 * p.columns * (p.rows - 1) + 3, 8 * (p.columns * p.rows - 1) + 2]);
    for (const a of scene.actions) {
      if (a.type === 'pin_target') assert.deepEqual(this.world.pinTarget(this.pins.get(a.pin)), keyed(a.keys, 0));
    }
  }

  step(frames) {
    for (let i = 0; i < frames; i++) {
      const frame = this.world.report().frame + 1;
      for (const a of scene.actions) {
        const v = keyed(a.keys, frame);
        if (a.type === 'pin_target') {
          this.world.setPinTarget(this.pins.get(a.pin), v);
        } else {
          assert.equal(a.type, 'collider_pose');
          this.world.setColliderTransform(this.ball, v);
        }
      }
      this.world.step();
    }
  }
}

/** 1 - n1.n2 of a quad's two triangles, the larger over both diagonals (the paper's measure). */
function planarity(q) {
  const sub = (a, b) => a.map((x, i) => x - b[i]);
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const unit = (v) => { const n = Math.hypot(...v); return v.map((c) => c / n); };
  const split = (a, b, c, d) => {
    const n1 = unit(cross(sub(b, a), sub(c, a)));
    const n2 = unit(cross(sub(c, a), sub(d, a)));
    return 1.0 - (n1[0] * n2[0] + n1[1] * n2[1] + n1[2] * n2[2]);
  };
  return Math.max(split(q[0], q[1], q[2], q[3]), split(q[1], q[2], q[3], q[0]));
}

test('the drape built in Node matches the C host bit for bit: positions, metrics, cut lists', () => {
  const out = runCli(['run', scenePath, '--frames', String(FRAMES)], 'poq');
  const records = fs.readFileSync(path.join(out, 'metrics.jsonl'), 'utf8').trim().split('\n').map(JSON.parse);
  const c = records[records.length - 1];
  const drape = new Drape();
  const w = drape.world;
  try {
    assert.equal(drape.body.count, 8 * 16);
    assert.equal(w.panelCount(drape.body), 16);
    drape.step(FRAMES);
    const node = w.positions(drape.body.first, drape.body.count);
    assertSameBits(node, readObjVertices(path.join(out, 'final.obj')), 'drape positions');
    assert.ok(Math.min(...node.filter((_, i) => i % 3 === 2)) < -0.5, 'folded down over the sphere');
    const m = w.panelMetrics(drape.body);
    assert.equal(c.frame, FRAMES);
    assert.equal(m.planarity_top.max, c.planarity_top_max);
    assert.equal(m.planarity_bottom.max, c.planarity_bottom_max);
    assert.equal(Math.max(m.corner_distance_top.max, m.corner_distance_bottom.max), c.corner_distance_max);
    assert.equal(Math.max(m.diagonal_top.max, m.diagonal_bottom.max), c.diagonal_max);
    assert.equal(m.thickness.max, c.thickness_error_max);
    assert.equal(m.miter.max, c.miter_error_max);
    assert.equal(m.conical.max, c.conical_defect_max);
    assert.equal(w.cornerGap(drape.body).max, c.corner_gap_max);
    assert.equal(m.within_tolerance === 1, c.within_tolerance);
    assert.ok(m.miter.max > 0, 'folding: the metrics are not all zero');
    assert.equal(w.exportCuts(drape.body), fs.readFileSync(path.join(out, 'panels_0.json'), 'utf8'));
    assert.equal(w.exportCuts(drape.body, 'csv'), fs.readFileSync(path.join(out, 'panels_0.csv'), 'utf8'));
    assert.equal(JSON.parse(w.exportCuts(drape.body, embra.CUTS_FORMATS.json)).format, 'embra-panel-cuts');
    const pose = scene.actions.find((a) => a.type === 'collider_pose');
    assert.deepEqual(w.colliderTransform(drape.ball).position, keyed(pose.keys, FRAMES)); // on its way
  } finally {
    w.close();
  }
});

test('the drape scene loaded in Node steps as the one built, and meets the paper\'s bars at frame 100', () => {
  const drape = new Drape();
  const built = drape.world;
  const loaded = embra.World.loadFile(scenePath);
  try {
    const body = new embra.BodyId(0, 1);
    assert.equal(loaded.panelCount(body), 16);
    assert.deepEqual(loaded.bodyParticles(body), { first: 0, count: 128 });
    assert.deepEqual(loaded.tolerances, built.tolerances);
    assert.equal(loaded.tolerances.unit_scale, 1250.0);
    assert.deepEqual(loaded.pins().map(String), built.pins().map(String));
    assert.deepEqual(loaded.colliders().map((c) => loaded.colliderTransform(c)),
      built.colliders().map((c) => built.colliderTransform(c)));
    drape.step(100);
    loaded.step(100);
    const p = loaded.positions();
    assertSameBits(built.positions(), p, 'built vs loaded');
    const m = loaded.panelMetrics(body);
    assert.deepEqual(m, built.panelMetrics(drape.body));
    assert.equal(m.version, embra.capi.PANEL_METRICS_VERSION);
    assert.ok(m.thickness.max <= 5e-5 && m.miter.max <= 1e-3, `thickness ${m.thickness.max}, miter ${m.miter.max}`);
    assert.ok(m.planarity_top.max <= 1e-6 && m.planarity_bottom.max <= 1e-6);
    assert.equal(m.planarity_top.count, 16);
    assert.equal(m.thickness.count, 16);
    assert.equal(m.miter.count, 2 * 4 * 5);
    assert.equal(m.conical.count, 9); // interior vertices of valence 4
    let own = 0;
    for (let k = 0; k < 16; k++) {
      for (let layer = 0; layer < 2; layer++) {
        const at = (c) => 3 * (8 * k + 4 * layer + c);
        const q = [0, 1, 2, 3].map((c) => Array.from(p.subarray(at(c), at(c) + 3)));
        own = Math.max(own, planarity(q));
      }
    }
    assert.ok(Math.abs(own - Math.max(m.planarity_top.max, m.planarity_bottom.max)) <= 1e-15);
  } finally {
    built.close();
    loaded.close();
  }
});

test('vertex errors are one value per particle, their maximum the metric', () => {
  const drape = new Drape();
  const w = drape.world;
  try {
    drape.step(40);
    const m = w.panelMetrics(drape.body);
    const expected = {
      planarity: Math.max(m.planarity_top.max, m.planarity_bottom.max), thickness: m.thickness.max,
      miter: m.miter.max, corner_distance: Math.max(m.corner_distance_top.max, m.corner_distance_bottom.max),
      conical: m.conical.max,
    };
    for (const [name, top] of Object.entries(expected)) {
      const field = w.vertexErrors(drape.body, name);
      assert.ok(field instanceof Float64Array);
      assert.equal(field.length, 128);
      assert.equal(Math.max(...field), top, name);
      assert.deepEqual(w.vertexErrors(drape.body, embra.PANEL_METRICS[name]), field);
    }
    assert.ok(expected.miter > 0);
    const out = new Float64Array(130).fill(7.0); // the caller's buffer, larger than needed: written in place
    assert.equal(w.vertexErrors(drape.body, 'miter', out), out);
    assert.equal(Math.max(...out.subarray(0, 128)), m.miter.max);
    assert.deepEqual(Array.from(out.subarray(128)), [7.0, 7.0]);
  } finally {
    w.close();
  }
});

test('grid builder, pins, tolerances and a mesh of quads', () => {
  const w = new embra.World();
  try {
    const d = embra.defaultPanelMeshDef();
    assert.deepEqual([d.version, d.grid_columns, d.grid_rows], [embra.capi.PANEL_MESH_DEF_VERSION, 4, 4]);
    assert.deepEqual([d.pins, d.corners], [embra.PANEL_PINS.none, embra.PANEL_CORNERS.welded]);
    assert.deepEqual([d.panel_size, d.thickness, d.density, d.slide_compliance], [0.8, 0.01, 1.0, 1e-3]);
    assert.deepEqual([d.friction_static, d.friction_dynamic], [0.5, 0.3]);
    assert.ok(d.group.equals(new embra.GroupId()));
    // Corners shared: one top and one bottom particle per vertex of the 3 x 4 vertex grid, the panels
    // on a vertex on the same particles (panel 0's corner 1 is panel 1's corner 0).
    const ws = new embra.World();
    try {
      const shared = ws.createPanelMesh({ grid_columns: 2, grid_rows: 3, corners: 'shared' });
      assert.deepEqual([shared.first, shared.count, ws.panelCount(shared)], [0, 24, 6]);
      const c = ws.panelCornerParticles(shared);
      assert.equal(c.length, 48);
      assert.deepEqual([c[1], c[2], Math.max(...c)], [c[8 + 0], c[8 + 3], 23]);
      assert.equal(ws.panelMetrics(shared).within_tolerance, 1);
    } finally {
      ws.close();
    }
    const body = w.createPanelMesh({ grid_columns: 2, grid_rows: 3, pins: 'top_and_bottom_corners' });
    assert.deepEqual([body.first, body.count, w.panelCount(body)], [0, 48, 6]);
    assert.deepEqual(Array.from(w.panelCornerParticles(body)), Array.from({ length: 48 }, (_, i) => i));
    assert.equal(w.counts().particles, 48);
    assert.equal(w.counts().pins, 8);
    let m = w.panelMetrics(body);
    assert.equal(m.within_tolerance, 1);
    assert.equal(m.miter.count, 2 * 4 + 3 * 3);
    assert.equal(m.thickness.within_target, 6);
    assert.equal(m.thickness.above_max, 0);

    const t = embra.defaultTolerances();
    assert.deepEqual([t.version, t.unit_scale], [1, 1000.0]);
    assert.deepEqual(t.thickness, { target: 5e-5, max: 1e-3 });
    assert.equal(w.tolerances.miter.target, 1e-3); // a world's tolerances start as the defaults
    w.setTolerances({ miter: { target: 0.5, max: 1.0 } });
    assert.deepEqual([w.tolerances.miter.target, w.tolerances.miter.max, w.tolerances.unit_scale], [0.5, 1.0, 1000.0]);
    w.tolerances = t;
    assert.deepEqual(w.tolerances, t);

    // Bent by hand out of tolerance: one corner 2 cm off its panel's plane. The world's tolerances count
    // it above the max; looser ones passed to the call count it within.
    const p = w.positions(0, 1);
    w.setPositions([p[0], p[1], p[2] + 0.02], 0);
    const strict = w.panelMetrics(body);
    assert.equal(strict.within_tolerance, 0);
    assert.ok(strict.planarity_top.above_max >= 1);
    const one = { target: 1.0, max: 1.0 };
    const loose = w.panelMetrics(body, { planarity: one, planarityDistance: one, thickness: one, miter: one });
    assert.equal(loose.within_tolerance, 1);
    assert.equal(loose.planarity_top.within_target, 6);
    assert.equal(loose.planarity_top.max, strict.planarity_top.max);

    // A mesh of two quads sharing an edge, given as vertices and quads.
    const xyz = [[0, 0, 1], [1, 0, 1], [2, 0, 1], [0, 1, 1], [1, 1, 1], [2, 1, 1]];
    const two = w.createPanelMesh({ positions: xyz, quads: [[0, 1, 4, 3], [1, 2, 5, 4]], thickness: 0.05,
      group: w.defaultGroup() });
    assert.deepEqual([two.first, two.count, w.panelCount(two)], [48, 16, 2]);
    m = w.panelMetrics(two);
    assert.equal(m.miter.count, 7);
    assert.ok(m.thickness.max < 1e-12);
    assert.equal(m.within_tolerance, 1);
    const z = Array.from(w.positions(two.first, two.count)).filter((_, i) => i % 3 === 2);
    assert.deepEqual(z.slice(0, 4), [1, 1, 1, 1]);
    assert.ok(z.slice(4, 8).every((v) => Math.abs(v - 0.95) < 1e-12), 'bottom 0.05 below');
    assert.equal(w.exportCuts(two, 'csv').trim().split('\n').length, 3); // a header and one row per panel
  } finally {
    w.close();
  }
});
