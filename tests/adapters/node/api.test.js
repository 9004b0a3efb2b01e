'use strict';
// The Node adapter covers the C ABI, and each part of it does what the header says.

const assert = require('node:assert/strict');
const { spawnSync } = require('node:child_process');
const fs = require('node:fs');
const path = require('node:path');
const test = require('node:test');

const { embra, packageDir, tempDir, assertSameBits } = require('./helpers');

const dist = (p, a, b) => Math.hypot(p[3 * a] - p[3 * b], p[3 * a + 1] - p[3 * b + 1], p[3 * a + 2] - p[3 * b + 2]);

test('versions and status names', () => {
  const v = embra.version();
  const [major, minor, patch] = embra.versionString().split('.').map(Number);
  assert.equal(v, major * 10000 + minor * 100 + patch);
  assert.equal(embra.abiVersion(), embra.ABI_VERSION);
  embra.checkAbi();
  assert.throws(() => embra.checkAbi(embra.ABI_VERSION + 1), (e) => e instanceof embra.VersionError &&
    /embra_check_abi/.test(e.message));
  assert.equal(embra.statusName(-2), 'EMBRA_ERROR_STALE_ID');
  assert.equal(embra.statusName(0), 'EMBRA_OK');
});

test('defaults are the documented ones', () => {
  const s = embra.defaultSolverDef();
  assert.deepEqual([s.version, s.substeps, s.iterations, s.tethers, s.realign_passes, s.chain_solve, s.threads],
    [2, 16, 1, 2, 0, 1, 1]);
  assert.equal(s.dt, 1.0 / 60.0);
  assert.deepEqual(s.gravity, [0, 0, -9.81]);
  assert.equal(s.settle_speed, 1e-3);
  const m = embra.defaultMaterial();
  assert.deepEqual([m.mass, m.density, m.stretch_compliance, m.bend_compliance], [0, 1, 0, 1]);
  assert.deepEqual([m.friction_static, m.friction_dynamic], [0.5, 0.3]);
  assert.deepEqual(['distance', 'edge_angle', 'dihedral', 'tet_volume', 'weld', 'tether', 'planarity',
    'plane_offset', 'equal_length', 'conical', 'length_min', 'angle_min', 'angle_max', 'colinear', 'direction',
    'cocircular', 'cospherical'].map(embra.constraintArity), [2, 3, 4, 4, 2, 2, 4, 4, 4, 5, 2, 3, 3, 3, 4, 4, 5]);
  const b = embra.defaultBodyDef();
  assert.equal(b.generate, embra.GENERATE.stretch | embra.GENERATE.bend | embra.GENERATE.volume);
  assert.ok(b.stretch_group instanceof embra.GroupId && b.stretch_group.equals(new embra.GroupId()));
  const c = embra.defaultColliderDef();
  assert.deepEqual([c.version, c.rotation, c.radius, c.half_extents, c.half_length],
    [embra.capi.COLLIDER_DEF_VERSION, [1, 0, 0, 0], 1, [0.5, 0.5, 0.5], 0.5]);
  assert.deepEqual([embra.defaultGroupDef().weight, embra.defaultPinDef().compliance,
    embra.defaultConstraintDef().rest_from_current, embra.defaultConstraintBatchDef().compliance], [1, 0, 1, 0]);
});

test('free fall is symplectic Euler in closed form', () => {
  // one free particle: after N substeps of h, z = z0 - h^2 g N (N + 1) / 2 exactly (v0 = 0)
  const w = new embra.World({ gravity: [0.0, 0.0, -9.81], substeps: 10 });
  const body = w.createBody([[0.0, 0.0, 5.0]], { mass: 2.0 });
  w.step(30);
  const n = 300;
  const h = (1.0 / 60.0) / 10;
  const z = w.positions(body.first, 1)[2];
  assert.ok(Math.abs(z - (5.0 - 9.81 * h * h * n * (n + 1) / 2)) < 1e-10);
  const vz = w.velocities(body.first, 1)[2];
  assert.ok(Math.abs(vz - (-9.81 * n * h)) < 1e-9);
  const r = w.report();
  assert.equal(r.frame, 30);
  assert.ok(Math.abs(r.time - 0.5) < 1e-12);
  assert.ok(Math.abs(r.kinetic_energy - 0.5 * 2.0 * vz * vz) < 1e-9);
  w.close();
});

test('groups, bulk constraints and reports: a hard chain hangs at its rest lengths', () => {
  const xyz = [0, 1, 2, 3, 4, 5].map((i) => [0.1 * i, 0.0, 0.0]);
  const w = new embra.World({ iterations: 20 });
  const def = w.defaultGroup();
  const contact = w.contactGroup();
  assert.ok(!def.equals(contact));
  const links = w.createGroup({ order: 5, weight: 3 });
  w.setGroupOrder(links, 4);
  w.setGroupWeight(links, 2);
  const body = w.createBody(xyz, { generate: 0, mass: 0.6 });
  assert.deepEqual(w.bodyParticles(body), { first: body.first, count: 6 });
  assert.equal(w.addConstraints('distance', [0, 1, 2, 3, 4].map((i) => [i, i + 1]), { group: links }), 5);
  assert.equal(w.counts().constraints, 5);
  w.addConstraint('tether', [0, 5], { rest: 0.6, compliance: 1e-3, group: links }); // slack: never pulls
  w.createPin(0, xyz[0]);
  w.step(120);
  assert.equal(w.counts().constraints, 6);
  assert.equal(w.counts().groups, 3);
  const p = w.positions();
  for (let i = 0; i < 5; i++) assert.ok(Math.abs(dist(p, i, i + 1) - 0.1) < 1e-6, `link ${i}`);
  const g = w.groupReport(links);
  assert.equal(g.count, 6);
  assert.ok(g.residual_max < 1e-6);
  w.destroyGroup(links);
  assert.equal(w.counts().constraints, 0);
  assert.equal(w.counts().groups, 2);
  assert.equal(w.warning().frame, -1);
  w.close();
});

test('equal length: four links between fixed ends, neighbours held equal, end a quarter each', () => {
  const xyz = [[0, 0, 0], [0.1, 0, 0], [0.5, 0, 0], [0.6, 0, 0], [1, 0, 0]];
  const w = new embra.World({ gravity: [0, 0, 0], substeps: 4, iterations: 4, damping: 20, tethers: 0 });
  w.createBody(xyz, { generate: 0, masses: [0, 1, 2, 0.5, 0] });
  assert.equal(w.addConstraints('equal_length', [[0, 1, 1, 2], [1, 2, 2, 3], [2, 3, 3, 4]], { rest: [0, 0, 0] }), 3);
  w.step(200);
  const p = w.positions();
  for (let i = 0; i < 4; i++) assert.ok(Math.abs(dist(p, i, i + 1) - 0.25) < 1e-9, `link ${i}`);
  w.close();
});

test('polygon planarity: a hexagon with its corners up and down in turn ends on one plane', () => {
  const xyz = [];
  for (let k = 0; k < 6; k++) xyz.push([Math.cos(k * Math.PI / 3), Math.sin(k * Math.PI / 3), k % 2 ? -0.2 : 0.2]);
  const w = new embra.World({ gravity: [0, 0, 0], substeps: 4, iterations: 10 });
  w.createBody(xyz, { generate: 0, masses: [1, 1, 1, 1, 1, 1] });
  assert.equal(w.addPolygonPlanarity([0, 1, 2, 3, 4, 5]), 6);
  w.step(200);
  const p = w.positions();
  const v = (k) => [0, 1, 2].map((i) => p[3 * k + i] - p[i]);  // corner k from corner 0
  const a = v(2), b = v(4);
  const n = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const len = Math.hypot(...n);
  for (let k = 0; k < 6; k++) {
    const d = v(k);
    const off = (d[0] * n[0] + d[1] * n[1] + d[2] * n[2]) / len;  // from the plane through 0, 2, 4
    assert.ok(Math.abs(off) < 1e-9, `corner ${k}: ${off}`);
  }
  assert.throws(() => w.addPolygonPlanarity([0, 1, 2, 1]), /twice/);
  w.close();
});

test('shape match: six points, one pinned, hard, swing with every distance kept; remove; refusals', () => {
  const xyz = [[0, 0, 1], [0.4, 0, 1], [0, 0.4, 1], [0, 0, 1.4], [0.3, 0.3, 1.3], [-0.2, 0.1, 1.2]];
  const w = new embra.World({ gravity: [0, 0, -9.81], substeps: 4, iterations: 40, tethers: 0 });
  w.createBody(xyz, { generate: 0, masses: [1, 2, 1, 1, 0.5, 1] });
  assert.equal(w.addShapeMatch([0, 1, 2, 3, 4, 5]), 0);
  w.createPin(0, xyz[0]);
  w.step(60);
  const p = w.positions();
  const d0 = (i, j) => Math.hypot(...[0, 1, 2].map((k) => xyz[i][k] - xyz[j][k]));
  for (let i = 0; i < 6; i++) {
    for (let j = i + 1; j < 6; j++) assert.ok(Math.abs(dist(p, i, j) - d0(i, j)) < 1e-6, `${i}-${j}`);
  }
  assert.equal(w.shapeMatchCount(), 1);
  w.removeShapeMatch(0);
  assert.equal(w.shapeMatchCount(), 0);
  assert.throws(() => w.addShapeMatch([0, 1, 1]), /twice/);
  w.close();
});

test('rigid set: six points braced (4 n - 9 constraints) fall and turn with every distance kept', () => {
  const xyz = [[0, 0, 1], [0.4, 0, 1], [0, 0.4, 1], [0, 0, 1.4], [0.3, 0.3, 1.3], [-0.2, 0.1, 1.2]];
  const w = new embra.World({ gravity: [0, 0, -9.81], substeps: 4, iterations: 40, tethers: 0 });
  w.createBody(xyz, { generate: 0, masses: [1, 1, 1, 1, 1, 1] });
  assert.equal(w.addRigidSet([0, 1, 2, 3, 4, 5]), 15);
  w.createPin(0, xyz[0]);
  w.step(60);
  const p = w.positions();
  const d0 = (i, j) => Math.hypot(...[0, 1, 2].map((k) => xyz[i][k] - xyz[j][k]));
  for (let i = 0; i < 6; i++) {
    for (let j = i + 1; j < 6; j++) assert.ok(Math.abs(dist(p, i, j) - d0(i, j)) < 1e-6, `${i}-${j}`);
  }
  assert.throws(() => w.addRigidSet([0, 1, 1]), /twice/);
  w.close();
});

test('statics: two hard bars at 45 degrees carry a load, the pins react with every weight and load', () => {
  const xyz = [[-1, 0, 0], [1, 0, 0], [0, 0, -1]];
  const w = new embra.World({ gravity: [0, 0, -9.81], substeps: 4, iterations: 20, damping: 5, tethers: 0,
    realign_passes: 2 });
  w.createBody(xyz, { generate: 0, masses: [1, 1.5, 2] });
  w.addConstraints('distance', [[0, 2], [1, 2]]);
  const pins = [w.createPin(0, xyz[0]), w.createPin(1, xyz[1])];
  w.setLoads([0, 0, -10], 2);
  assert.deepEqual(Array.from(w.loads()), [0, 0, 0, 0, 0, 0, 0, 0, -10]);
  w.step(200);
  const down = 2 * 9.81 + 10;
  for (const t of w.constraintForces(w.defaultGroup(), 'distance')) assert.ok(Math.abs(t - down / Math.SQRT2) < 1e-9 * down);
  const r = w.reactions();
  assert.ok(r[0].pin.equals(pins[0]) && r[1].pin.equals(pins[1]));
  assert.deepEqual(r.map((x) => x.particle), [0, 1]);
  const total = [0, 1, 2].map((k) => r[0].force[k] + r[1].force[k]);
  assert.ok(Math.abs(total[0]) < 1e-9 * down && Math.abs(total[1]) < 1e-9 * down);
  assert.ok(Math.abs(total[2] - (4.5 * 9.81 + 10)) < 1e-9 * down);
  assert.throws(() => w.constraintForces(w.defaultGroup(), 'weld'), embra.EmbraError);
  assert.throws(() => w.setLoads([0, NaN, 0], 0));
  assert.deepEqual(Array.from(w.loads(0, 1)), [0, 0, 0]);
  w.close();
});

test('collider reactions: a ground plane carries the weights and loads resting on it', () => {
  // Three loose particles (1, 1.5, 2 kg) on the plane z = 0, one with a point load whose horizontal
  // part friction holds: the plane's force is minus every weight and load, its moment about its
  // origin minus the loads' moment (N, N m, to 1e-9 relative).
  const xyz = [[0, 0, 0], [1, 0, 0], [0, 1, 0]];
  const masses = [1, 1.5, 2];
  const w = new embra.World({ gravity: [0, 0, -9.81], substeps: 4, iterations: 20, damping: 5, tethers: 0,
    realign_passes: 2 });
  const floor = w.createCollider('plane', { position: [0, 0, 0] });
  w.createBody(xyz, { generate: 0, masses });
  w.setLoads([0.5, 0, -2], 2);
  w.step(50);
  const loads = masses.map((m) => [0, 0, -9.81 * m]);
  loads[2] = [0.5, 0, -9.81 * 2 - 2];
  const total = [0, 1, 2].map((k) => loads.reduce((a, f) => a + f[k], 0));
  const p = Array.from(w.positions());
  const moment = [0, 0, 0];
  loads.forEach((f, i) => {
    const x = p.slice(3 * i, 3 * i + 3);
    moment[0] += x[1] * f[2] - x[2] * f[1];
    moment[1] += x[2] * f[0] - x[0] * f[2];
    moment[2] += x[0] * f[1] - x[1] * f[0];
  });
  const r = w.colliderReactions();
  assert.equal(r.length, 1);
  assert.ok(r[0].collider.equals(floor));
  assert.equal(r[0].contacts, 3);
  const scale = Math.hypot(...total);
  for (let k = 0; k < 3; k++) {
    assert.ok(Math.abs(r[0].force[k] + total[k]) < 1e-9 * scale, `force ${k}`);
    assert.ok(Math.abs(r[0].moment[k] + moment[k]) < 1e-9 * Math.hypot(...moment), `moment ${k}`);
  }
  assert.equal(w.reactions().length, 0);
  w.close();
});

test('area and line loads push free particles by p A / 3 and q L / 2, and read back', () => {
  // A free triangle of three 0.5 kg particles (0.5 m^2) under 12 Pa per true area along (0, 3, -4):
  // 2 N, 4 m/s^2 on each corner; a free edge of length 2 under (1, 0, 0) N/m: 1 N on each end.
  const tri = [[0, 0, 0], [1, 0, 0], [0, 1, 0]];
  const edge = [[0, 0, 5], [2, 0, 5]];
  const w = new embra.World({ gravity: [0, 0, 0], substeps: 4, iterations: 1, tethers: 0 });
  w.createBody([...tri, ...edge], { generate: 0, masses: [0.5, 0.5, 0.5, 0.5, 0.5] });
  w.setAreaLoads([{ particles: [0, 1, 2], mode: 'true_area', pressure: 12, direction: [0, 3, -4] }]);
  w.setLineLoads([{ particles: [3, 4], load: [1, 0, 0] }]);
  assert.deepEqual(w.areaLoads(), [{ particles: [0, 1, 2], mode: 'true_area', pressure: 12, direction: [0, 3, -4] }]);
  assert.deepEqual(w.lineLoads(), [{ particles: [3, 4], load: [1, 0, 0] }]);
  w.step(3);
  const n = 12;
  const h = 1 / 60 / 4;
  const s = h * h * n * (n + 1) / 2;
  const p = w.positions();
  for (let i = 0; i < 3; i++) {
    [0, 0.6, -0.8].forEach((u, k) => assert.ok(Math.abs(p[3 * i + k] - tri[i][k] - 4 * u * s) < 1e-12));
  }
  for (let i = 0; i < 2; i++) assert.ok(Math.abs(p[9 + 3 * i] - edge[i][0] - 2 * s) < 1e-12);
  assert.throws(() => w.setAreaLoads([{ particles: [0, 1, 1], pressure: 1 }]), embra.EmbraError);
  assert.throws(() => w.setLineLoads([{ particles: [3, 5], load: [1, 0, 0] }]), embra.EmbraError);
  assert.throws(() => w.setAreaLoads([{ particles: [0, 1, 2], mode: 'plan', pressure: 1 }]), RangeError);
  assert.equal(w.areaLoads()[0].pressure, 12);
  w.setAreaLoads([]);
  w.setLineLoads([]);
  assert.deepEqual([w.areaLoads(), w.lineLoads()], [[], []]);
  w.close();
});

test('a polyline support holds a bead on a circle while it swings', () => {
  const pts = [];
  for (let k = 0; k < 48; k++) {
    const a = -Math.PI / 2 + Math.PI / 48 + 2 * Math.PI * k / 48;
    pts.push([0.6 * Math.cos(a), 0, 0.6 * Math.sin(a)]);
  }
  const distance = (q) => {
    let best = Infinity;
    for (let s = 0; s < pts.length; s++) {
      const a = pts[s];
      const b = pts[(s + 1) % pts.length];
      const e = [0, 1, 2].map((k) => b[k] - a[k]);
      const t = Math.min(1, Math.max(0, [0, 1, 2].reduce((acc, k) => acc + (q[k] - a[k]) * e[k], 0) /
        e.reduce((acc, c) => acc + c * c, 0)));
      best = Math.min(best, Math.hypot(...[0, 1, 2].map((k) => q[k] - a[k] - t * e[k])));
    }
    return best;
  };
  const w = new embra.World({ gravity: [0, 0, -9.81], substeps: 8, iterations: 2, tethers: 0 });
  w.createBody([[0.6, 0, 0.1]], { generate: 0, masses: [0.3] });
  const pin = w.createPolylineSupport(0, pts, { closed: true });
  let low = Infinity;
  for (let f = 0; f < 60; f++) {
    w.step();
    const q = Array.from(w.positions());
    assert.ok(distance(q) < 1e-9);
    low = Math.min(low, q[2]);
  }
  assert.ok(low < -0.5);
  assert.ok(w.reactions()[0].pin.equals(pin));
  assert.throws(() => w.createPolylineSupport(0, [pts[0], pts[0], pts[1]]),
    embra.EmbraError);
  w.close();
});

test('polylineSupportPoints reads the points as created; setPinTarget moves the curve', () => {
  const pts = [[0, 0, 0], [1 / 3, 0.1, -0.2], [0.7, -0.4, 0.05]];
  const w = new embra.World({ gravity: [0, 0, 0], substeps: 4, iterations: 2, tethers: 0 });
  w.createBody([[0, 0, 0], [1, 0, 0]], { generate: 0, masses: [1, 1] });
  const pin = w.createPolylineSupport(0, pts);
  const plane = w.createSupport(1, [0, 0, 0], { compliance: 1 });
  assert.deepStrictEqual(w.polylineSupportPoints(pin), pts);
  const shift = [0.25, -1.5, 2];
  w.setPinTarget(pin, shift);
  w.step(2);
  assert.deepStrictEqual(w.polylineSupportPoints(pin), pts);
  const q = Array.from(w.positions()).slice(0, 3);
  // On the moved curve: the distance to its nearest segment.
  let best = Infinity;
  for (let s = 0; s + 1 < pts.length; s++) {
    const a = pts[s].map((c, k) => c + shift[k]);
    const b = pts[s + 1].map((c, k) => c + shift[k]);
    const e = [0, 1, 2].map((k) => b[k] - a[k]);
    const t = Math.min(1, Math.max(0, [0, 1, 2].reduce((acc, k) => acc + (q[k] - a[k]) * e[k], 0) /
      e.reduce((acc, c) => acc + c * c, 0)));
    best = Math.min(best, Math.hypot(...[0, 1, 2].map((k) => q[k] - a[k] - t * e[k])));
  }
  assert.ok(best < 1e-9);
  assert.throws(() => w.polylineSupportPoints(plane), embra.EmbraError);
  w.close();
});

test('a mesh support: a particle slides down an inclined face at g sin(theta)', () => {
  const th = Math.PI / 6;
  const n = [-Math.sin(th), 0, Math.cos(th)];
  const down = [-Math.cos(th), 0, -Math.sin(th)];
  const verts = [[1, 1], [-1, 1], [-1, -1], [1, -1]].map(([a, b]) => [0, 1, 2].map((k) => 10 * (a * down[k] + b * [0, 1, 0][k])));
  const w = new embra.World({ gravity: [0, 0, -9.81], substeps: 10, iterations: 1, tethers: 0 });
  w.createBody([[0, 0.3, 0]], { generate: 0, masses: [2] });
  const pin = w.createMeshSupport(0, verts, [[0, 3, 2], [0, 2, 1]]);
  w.step(30);
  const steps = 300;
  const h = 1 / 60 / 10;
  const p = w.positions();
  const along = p[0] * down[0] + p[2] * down[2];
  const exact = 9.81 * Math.sin(th) * h * h * steps * (steps + 1) / 2;
  // rounding of the closest point (vertices of size 10) carried on by the velocity: steps^2 eps 10
  assert.ok(Math.abs(along - exact) < steps * steps * 2.2e-16 * 10);
  assert.ok(Math.abs(p[0] * n[0] + p[2] * n[2]) < 1e-12);
  const r = w.reactions();
  assert.ok(r[0].pin.equals(pin));
  for (let k = 0; k < 3; k++) assert.ok(Math.abs(r[0].force[k] - 2 * 9.81 * Math.cos(th) * n[k]) < 1e-9 * 9.81);
  assert.throws(() => w.createMeshSupport(0, [[0, 0, 0], [1, 0, 0], [2, 0, 0]], [[0, 1, 2]]), embra.EmbraError);
  assert.throws(() => w.createMeshSupport(0, verts, [[0, 1, 4]]), embra.EmbraError);
  w.close();
});

test('a plane support: slides at g sin(theta), pushes with m g cos(theta) along its normal', () => {
  const th = Math.PI / 6;
  const n = [-Math.sin(th), 0, Math.cos(th)];
  const w = new embra.World({ gravity: [0, 0, -9.81], substeps: 10, iterations: 1, tethers: 0 });
  w.createBody([[0, 0, 0]], { generate: 0, masses: [2] });
  const pin = w.createSupport(0, [0, 0, 0], { support: 'plane', axis: n.map((c) => 2 * c) });
  w.step(30);
  const steps = 300;
  const h = 1 / 60 / 10;
  const p = w.positions();
  const along = -(p[0] * Math.cos(th) + p[2] * Math.sin(th));
  const exact = 9.81 * Math.sin(th) * h * h * steps * (steps + 1) / 2;
  assert.ok(Math.abs(along - exact) < 1e-12 * exact);
  const r = w.reactions();
  assert.ok(r[0].pin.equals(pin));
  for (let k = 0; k < 3; k++) assert.ok(Math.abs(r[0].force[k] - 2 * 9.81 * Math.cos(th) * n[k]) < 1e-9 * 9.81);
  assert.throws(() => w.createSupport(0, [0, 0, 0], { support: 'line', axis: [0, 0, 0] }), embra.EmbraError);
  assert.throws(() => w.createSupport(0, [0, 0, 0], { support: 'curve' }));
  w.close();
});

test('an axes support (roller) holds z and lets x and y accelerate at F / m', () => {
  const w = new embra.World({ gravity: [0, 0, -9.81], substeps: 10, iterations: 1, tethers: 0 });
  w.createBody([[0.3, -0.4, 1.2]], { generate: 0, masses: [2] });
  const pin = w.createSupport(0, [0.3, -0.4, 1.2], { support: 'axes', axis: [0, 0, 1] });
  w.setLoads([[1.5, 0.5, 0]]);
  for (let f = 0; f < 30; f++) {
    w.step();
    assert.ok(Math.abs(w.positions()[2] - 1.2) < 1e-12);
  }
  const steps = 300;
  const h = 1 / 60 / 10;
  const p = w.positions();
  assert.ok(Math.abs(p[0] - 0.3 - 0.75 * h * h * steps * (steps + 1) / 2) < 1e-12);
  assert.ok(Math.abs(p[1] + 0.4 - 0.25 * h * h * steps * (steps + 1) / 2) < 1e-12);
  const r = w.reactions();
  assert.ok(r[0].pin.equals(pin));
  assert.strictEqual(r[0].force[0], 0);
  assert.strictEqual(r[0].force[1], 0);
  assert.ok(Math.abs(r[0].force[2] - 2 * 9.81) < 1e-9 * 9.81);
  assert.throws(() => w.createSupport(0, [0, 0, 0], { support: 'axes', axis: [0, 0.5, 1] }), embra.EmbraError);
  assert.throws(() => w.createSupport(0, [0, 0, 0], { support: 'axes', axis: [0, 0, 0] }), embra.EmbraError);
  w.close();
});

test('bulk rest and compliance arrays', () => {
  const w = new embra.World({ gravity: [0, 0, 0], iterations: 50 });
  w.createBody([[0, 0, 0], [1, 0, 0], [2, 0, 0]], { generate: 0, mass: 3.0 });
  w.addConstraints(embra.KINDS.distance, new Int32Array([0, 1, 1, 2]), { rest: [0.5, 0.25],
    compliances: new Float64Array([0, 0]) });
  w.step(60);
  const p = w.positions();
  assert.ok(Math.abs(dist(p, 0, 1) - 0.5) < 1e-9);
  assert.ok(Math.abs(dist(p, 1, 2) - 0.25) < 1e-9);
  w.close();
});

test('pin targets move particles', () => {
  const w = new embra.World();
  w.createBody([[0, 0, 0]], { mass: 1.0 });
  const pin = w.createPin(0, [0, 0, 0]);
  w.setPinTarget(pin, [0.25, -0.5, 1.0]);
  assert.deepEqual(w.pinTarget(pin), [0.25, -0.5, 1.0]);
  w.step();
  assert.deepEqual(Array.from(w.positions()), [0.25, -0.5, 1.0]);
  w.close();
});

test('colliders hold a falling particle and carry it when moved', () => {
  const w = new embra.World();
  w.createBody([[0, 0, 2]], { mass: 1.0 });
  const sphere = w.createCollider('sphere', { position: [0, 0, 0], radius: 1.0 });
  const floor = w.createCollider('plane', { position: [0, 0, -5] });
  w.step(120);
  assert.ok(Math.abs(w.positions()[2] - 1.0) < 1e-6, 'resting on top of the sphere');
  w.setColliderTransform(sphere, [0, 0, -1]);
  w.destroyCollider(floor);
  w.step(60);
  assert.ok(Math.abs(w.positions()[2]) < 1e-6, 'followed the sphere down');
  const hull = [[-1, -1, -1], [1, -1, -1], [0, 1, -1], [0, 0, 1]];
  w.createCollider('convex', { position: [5, 0, 0], vertices: hull });
  w.createCollider(embra.SHAPES.mesh, { position: [9, 0, 0], vertices: hull,
    triangles: [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]] });
  w.createCollider('box', { position: [-5, 0, 0], halfExtents: [1, 2, 3] });
  w.createCollider('capsule', { position: [-9, 0, 0], radius: 0.5, half_length: 1.0 });
  assert.equal(w.counts().colliders, 5);
  w.close();
});

test('live ids in creation order, a pin\'s particle, a collider\'s pose', () => {
  const w = new embra.World({ gravity: [0, 0, 0] });
  const ids = (list) => list.map(String);
  assert.deepEqual(ids(w.groups()), ids([w.defaultGroup(), w.contactGroup()]));
  assert.deepEqual(w.bodies(), []);
  const a = w.createBody([[0, 0, 0], [1, 0, 0]], { edges: [[0, 1]], mass: 1.0 });
  const b = w.createBody([[0, 0, 1]], { mass: 1.0 });
  const g = w.createGroup({ order: 3 });
  assert.deepEqual(ids(w.bodies()), ids([a.id, b.id]));
  assert.ok(w.bodies()[1] instanceof embra.BodyId);
  assert.deepEqual(ids(w.groups()), ids([w.defaultGroup(), w.contactGroup(), g]));
  const pins = [w.createPin(1, [1, 0, 0]), w.createPin(2, [0, 0, 1]), w.createPin(0, [0, 0, 0])];
  assert.deepEqual(pins.map((p) => w.pinParticle(p)), [1, 2, 0]);
  w.destroyPin(pins[1]);
  assert.deepEqual(ids(w.pins()), ids([pins[0], pins[2]]));
  const ball = w.createCollider('sphere', { position: [0, 0, -3], radius: 0.5 });
  const box = w.createCollider('box', { position: [4, 0, 0], rotation: [0, 0, 0, 1] });
  assert.deepEqual(ids(w.colliders()), ids([ball, box]));
  assert.deepEqual(w.colliderTransform(ball), { position: [0, 0, -3], rotation: [1, 0, 0, 0] });
  assert.deepEqual(w.colliderTransform(box), { position: [4, 0, 0], rotation: [0, 0, 0, 1] });
  w.setColliderTransform(ball, [0, 1, -3]); // the pose it reaches at the end of the next step
  assert.deepEqual(w.colliderTransform(ball).position, [0, 1, -3]);
  w.step();
  assert.deepEqual(w.colliderTransform(ball), { position: [0, 1, -3], rotation: [1, 0, 0, 0] });
  w.destroyCollider(ball);
  assert.deepEqual(ids(w.colliders()), ids([box]));
  w.destroyGroup(g);
  assert.equal(w.groups().length, 2);
  w.close();
});

test('rest scale shrinks edges', () => {
  const w = new embra.World({ gravity: [0, 0, 0], iterations: 10 });
  const body = w.createBody([[0, 0, 0], [1, 0, 0]], { edges: [[0, 1]], mass: 1.0 });
  w.setRestScale(body, 0.5, 1.0, 1.0);
  w.step(120);
  assert.ok(Math.abs(dist(w.positions(), 0, 1) - 0.5) < 1e-9);
  w.close();
});

test('positions, velocities and triangles round trip; typed arrays are used in place', () => {
  const w = new embra.World();
  const xyz = new Float64Array([0, 0, 0, 1, 0, 0, 0, 1, 0]);
  const body = w.createBody(xyz, { triangles: new Int32Array([0, 1, 2]), mass: 1.0 });
  w.setPositions([[0.5, 0.25, 2.0]], 2);
  w.setVelocities(new Float64Array([1, 2, 3, 4, 5, 6]), 0);
  assert.deepEqual(Array.from(w.positions(2, 1)), [0.5, 0.25, 2.0]);
  assert.deepEqual(Array.from(w.velocities()), [1, 2, 3, 4, 5, 6, 0, 0, 0]);
  const tri = w.bodyTriangles(new embra.BodyId(0, 1));
  assert.ok(tri instanceof Int32Array);
  assert.deepEqual(Array.from(tri), [0, 1, 2]);
  const out = new Float64Array(9);
  assert.equal(w.positions(body.first, 3, out), out); // C wrote into the caller's array
  assert.deepEqual(Array.from(out), [0, 0, 0, 1, 0, 0, 0.5, 0.25, 2.0]);
  const part = new Float64Array(12).fill(-1);
  w.positions(1, 2, part.subarray(3, 9)); // a view into a larger buffer: written at its offset
  assert.deepEqual(Array.from(part), [-1, -1, -1, 1, 0, 0, 0.5, 0.25, 2.0, -1, -1, -1]);
  assert.equal(w.particleCount, 3);
  w.close();
});

test('a saved scene steps on bit-identically', () => {
  const dir = tempDir('saved');
  const xyz = [];
  for (let i = 0; i < 4; i++) for (let j = 0; j < 4; j++) xyz.push([0.1 * j, 0.1 * i, 0.0]);
  const tri = [];
  for (const v of [0, 1, 2, 4, 5, 6, 8, 9, 10]) tri.push([v, v + 1, v + 5]);
  for (const v of [0, 1, 2, 4, 5, 6, 8, 9, 10]) tri.push([v, v + 5, v + 4]);
  const a = new embra.World();
  a.createBody(xyz, { triangles: tri, mass: 0.2 });
  a.createPin(0, xyz[0]);
  a.step(10);
  const text = a.saveJson();
  a.saveFile(path.join(dir, 'mid.json'));
  const b = embra.World.loadJson(text);
  const c = embra.World.loadFile(path.join(dir, 'mid.json'));
  for (const w of [a, b, c]) w.step(20);
  assertSameBits(b.positions(), a.positions(), 'from text');
  assertSameBits(c.positions(), a.positions(), 'from file');
  assert.equal(b.saveJson(), a.saveJson());
  for (const w of [a, b, c]) w.close();
});

test('solver settings round trip', () => {
  const w = new embra.World({ substeps: 7, damping: 0.5 });
  assert.deepEqual([w.solver.substeps, w.solver.damping], [7, 0.5]);
  w.setSolver({ iterations: 3 });
  w.setGravity([0.0, 0.0, 9.81]);
  const s = w.solver;
  assert.deepEqual([s.substeps, s.iterations, s.gravity], [7, 3, [0, 0, 9.81]]);
  assert.equal(w.sceneFrames(), 600);
  w.close();
});

function whichLibrary(env) {
  const code = `const e = require(${JSON.stringify(path.join(packageDir, 'lib'))}); console.log(e.libraryPath);`;
  return spawnSync(process.execPath, ['-e', code], { env, encoding: 'utf8' });
}

test('the library is found from EMBRA_LIBRARY, else by SONAME through the loader\'s search', () => {
  const lib = fs.realpathSync(process.env.EMBRA_LIBRARY);
  const env = { ...process.env };
  delete env.EMBRA_LIBRARY;
  delete env.LD_LIBRARY_PATH;
  let run = whichLibrary({ ...env, EMBRA_LIBRARY: lib });
  assert.equal(run.status, 0, run.stderr);
  assert.equal(run.stdout.trim(), lib);
  run = whichLibrary({ ...env, LD_LIBRARY_PATH: path.dirname(lib) });
  assert.equal(run.status, 0, run.stderr);
  assert.equal(run.stdout.trim(), `libembra.so.${embra.ABI_VERSION}`);
  run = whichLibrary({ ...env, EMBRA_LIBRARY: path.join(tempDir('nolib'), 'libembra.so.0') });
  assert.notEqual(run.status, 0);
  assert.match(run.stderr, /cannot load libembra/);
  assert.match(run.stderr, /EMBRA_LIBRARY/);
});
