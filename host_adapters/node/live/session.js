'use strict';
// One live scene: the world a page watches and edits (docs/live-protocol.md). The server owns the
// clock and the sockets; a Session owns the world, turns it into the protocol's messages, and
// applies the page's edits. Every edit is validated here or refused by the C library; either way a
// refused edit changes nothing and comes back as an `error` reply.

const fs = require('fs');
const path = require('path');
const { World, EmbraError, NumericalError } = require('../lib');
const { fieldColors, toGltf, to3dm } = require('../lib/export');

const FIELDS = ['planarity', 'thickness', 'miter'];
const DRAG_COMPLIANCE = 1e-6; // m/N: a soft pin firm enough to lead, soft enough not to tear
const MAGIC = 0x464d4245; // 'EBMF' little-endian

class RefusedMessage extends Error {}

function refuse(message) {
  throw new RefusedMessage(message);
}

function finite3(value, what, n = 3) {
  if (!Array.isArray(value) || value.length !== n || !value.every((v) => typeof v === 'number' && Number.isFinite(v)))
    refuse(`${what} must be ${n} finite numbers`);
  return value;
}

function indexIn(value, list, what) {
  if (!Number.isInteger(value) || value < 0 || value >= list.length)
    refuse(`${what} ${JSON.stringify(value)} is not an index in [0, ${list.length})`);
  return list[value];
}

function bool(value, what) {
  if (typeof value !== 'boolean') refuse(`${what} must be true or false`);
  return value;
}

class Session {
  /**
   * @param {string} scenePath a scene JSON file (schemas/scene.schema.json)
   * @param {{saveDir?: string}} options where `save` and `export` write their files
   */
  constructor(scenePath, options = {}) {
    this.scenePath = path.resolve(scenePath);
    this.sceneText = fs.readFileSync(this.scenePath, 'utf8');
    this.saveDir = path.resolve(options.saveDir || '.');
    this.world = null;
    this.#load();
  }

  /** Builds the world from the scene's text; a reset keeps the paused state. */
  #load(paused = false) {
    const world = World.loadJson(this.sceneText, path.dirname(this.scenePath));
    if (this.world) this.world.close();
    this.world = world;
    this.paused = paused;
    this.gravityOn = true;
    this.pinsOn = true;
    this.drags = new Map(); // page -> {pin, particle}: each page holds at most one drag
    this.lastMs = 0;
    const saved = JSON.parse(world.saveJson());
    this.name = saved.name || path.basename(this.scenePath, '.json');
    this.description = saved.description || '';
    const solver = world.solver;
    this.dt = solver.dt;
    this.gravity = Array.from(solver.gravity);
    this.frames = Number(world.sceneFrames());
    this.particles = world.particleCount;
    this.tolerances = world.tolerances;

    this.bodies = world.bodies().map((id, i) => {
      const { first, count } = world.bodyParticles(id);
      let panels = 0;
      try {
        panels = world.panelCount(id);
      } catch (e) {
        if (!(e instanceof EmbraError)) throw e; // not a panel mesh
      }
      const entry = (saved.bodies || [])[i] || {};
      return { id, index: i, name: entry.name || `body_${i}`, first, count, triangles: world.bodyTriangles(id),
               panels, restScale: [1, 1, 1] };
    });
    const groupIds = world.groups();
    const savedGroups = saved.groups || [];
    this.groups = groupIds.map((id, i) => {
      const entry = savedGroups.length === groupIds.length ? savedGroups[i] : {};
      return { id, index: i, name: entry.name || `group_${i}`, order: entry.order ?? 0, weight: entry.weight ?? 1 };
    });
    const groupByName = new Map(this.groups.map((g) => [g.name, g.id]));
    const savedPins = saved.pins || [];
    const pinIds = world.pins();
    this.pins = pinIds.map((id, i) => {
      const entry = savedPins.length === pinIds.length ? savedPins[i] : {};
      const compliance = entry.compliance || 0;
      return { id, index: i, name: entry.name || `pin_${i}`, particle: world.pinParticle(id), compliance,
               group: compliance > 0 && entry.group ? groupByName.get(entry.group) : undefined };
    });
    const savedColliders = saved.colliders || [];
    const colliderIds = world.colliders();
    this.colliders = colliderIds.map((id, i) => {
      const entry = savedColliders.length === colliderIds.length ? savedColliders[i] : {};
      return { id, index: i, name: entry.name || `collider_${i}`, shape: entry.shape || 'sphere',
               radius: entry.radius ?? 1, half_extents: entry.half_extents || [0.5, 0.5, 0.5],
               half_length: entry.half_length ?? 0.5, vertices: entry.vertices || [], triangles: entry.triangles || [] };
    });
    this.positions = new Float64Array(3 * this.particles);
    this.fieldValues = FIELDS.map(() => new Float64Array(this.particles).fill(NaN));
    this.#measure();
  }

  /** Reads the state the messages report: positions, error fields and the frame's numbers. */
  #measure() {
    const w = this.world;
    w.positions(0, this.particles, this.positions);
    for (const f of this.fieldValues) f.fill(NaN);
    const r = w.report();
    const record = { type: 'frame', frame: Number(r.frame), ms: this.lastMs, residual_max: r.residual_max,
                     kinetic_energy: r.kinetic_energy, settled: !!r.settled };
    const panelBodies = this.bodies.filter((b) => b.panels > 0);
    if (panelBodies.length > 0) {
      let planarity = 0;
      let thickness = 0;
      let miter = 0;
      let within = true;
      for (const b of panelBodies) {
        const m = w.panelMetrics(b.id);
        planarity = Math.max(planarity, m.planarity_top.max, m.planarity_bottom.max);
        thickness = Math.max(thickness, m.thickness.max);
        miter = Math.max(miter, m.miter.max);
        within = within && !!m.within_tolerance;
        FIELDS.forEach((name, k) => w.vertexErrors(b.id, name, this.fieldValues[k].subarray(b.first, b.first + b.count)));
      }
      Object.assign(record, { planarity_max: planarity, thickness_error_max: thickness, miter_error_max: miter,
                              within_tolerance: within });
    }
    this.record = record;
  }

  /** Advances one frame. A numerical failure (the world restored to before the step) pauses. */
  step() {
    const t0 = process.hrtime.bigint();
    try {
      this.world.step();
    } catch (e) {
      if (!(e instanceof NumericalError)) throw e;
      this.paused = true;
      this.lastMs = Number(process.hrtime.bigint() - t0) / 1e6;
      return { type: 'error', message: `${e.message} (paused)` };
    }
    this.lastMs = Number(process.hrtime.bigint() - t0) / 1e6;
    this.#measure();
    return null;
  }

  sceneMessage() {
    const t = this.tolerances;
    const tol = (x) => ({ target: x.target, max: x.max });
    return {
      type: 'scene', name: this.name, description: this.description, dt: this.dt, frames: this.frames,
      particles: this.particles, paused: this.paused, gravity: this.gravity, gravity_on: this.gravityOn,
      pins_on: this.pinsOn,
      bodies: this.bodies.map((b) => ({ index: b.index, name: b.name, first: b.first, count: b.count,
                                         triangles: Array.from(b.triangles), panel_mesh: b.panels > 0,
                                         panels: b.panels, rest_scale: b.restScale })),
      colliders: this.colliders.map((c) => {
        const pose = this.world.colliderTransform(c.id);
        return { index: c.index, name: c.name, shape: c.shape, radius: c.radius, position: pose.position,
                 rotation: pose.rotation, half_extents: c.half_extents, half_length: c.half_length,
                 vertices: c.vertices, triangles: c.triangles };
      }),
      pins: this.pinsOn ? this.pins.map((p) => ({ index: p.index, name: p.name, particle: p.particle,
                                                   target: this.world.pinTarget(p.id) })) : [],
      groups: this.groups.map((g) => ({ index: g.index, name: g.name, order: g.order, weight: g.weight })),
      fields: FIELDS,
      tolerances: { unit_scale: t.unit_scale, planarity: tol(t.planarity), thickness: tol(t.thickness),
                    miter: tol(t.miter) },
    };
  }

  frameMessage() {
    return this.record;
  }

  statusMessage() {
    return { type: 'status', paused: this.paused, gravity_on: this.gravityOn, pins_on: this.pinsOn };
  }

  /** The frame's geometry in the protocol's binary layout (an ArrayBuffer). */
  geometryMessage() {
    const n = this.particles;
    const c = this.colliders.length;
    const f = FIELDS.length;
    const buffer = new ArrayBuffer(24 + 4 * (3 * n + 7 * c + f * n));
    const head = new DataView(buffer, 0, 24);
    [MAGIC, 1, this.record.frame, n, c, f].forEach((v, k) => head.setUint32(4 * k, v, true));
    const body = new Float32Array(buffer, 24);
    body.set(this.positions, 0);
    this.colliders.forEach((col, k) => {
      const pose = this.world.colliderTransform(col.id);
      body.set(pose.position, 3 * n + 7 * k);
      body.set(pose.rotation, 3 * n + 7 * k + 3);
    });
    this.fieldValues.forEach((values, k) => body.set(values, 3 * n + 7 * c + k * n));
    return buffer;
  }

  /**
   * Applies one page message (already parsed JSON). Returns the replies to send to the sender
   * (objects) and whether everyone needs a new `scene`. Refusals throw RefusedMessage or EmbraError,
   * after which nothing has changed.
   */
  async handle(msg, page = 'page') {
    if (msg === null || typeof msg !== 'object' || Array.isArray(msg)) refuse('a message must be a JSON object');
    const w = this.world;
    switch (msg.type) {
      case 'drag_start': {
        if (!Number.isInteger(msg.particle) || msg.particle < 0 || msg.particle >= this.particles)
          refuse(`particle ${JSON.stringify(msg.particle)} is not in [0, ${this.particles})`);
        const target = finite3(msg.target, 'target');
        const pin = w.createPin(msg.particle, target, { compliance: DRAG_COMPLIANCE });
        this.releaseDrag(page);
        this.drags.set(page, { pin, particle: msg.particle });
        return {};
      }
      case 'drag': {
        const target = finite3(msg.target, 'target');
        const drag = this.drags.get(page);
        if (!drag) refuse('drag without drag_start');
        w.setPinTarget(drag.pin, target);
        return {};
      }
      case 'drag_end':
        this.releaseDrag(page);
        return {};
      case 'collider_pose': {
        const c = indexIn(msg.index, this.colliders, 'collider');
        const position = finite3(msg.position, 'position');
        const rotation = msg.rotation === undefined ? w.colliderTransform(c.id).rotation : finite3(msg.rotation, 'rotation', 4);
        w.setColliderTransform(c.id, position, rotation);
        return {};
      }
      case 'gravity': {
        const on = bool(msg.on, 'on');
        w.setGravity(on ? this.gravity : [0, 0, 0]);
        this.gravityOn = on;
        return { replies: [this.statusMessage()], broadcast: true };
      }
      case 'pins': {
        const on = bool(msg.on, 'on');
        if (on !== this.pinsOn) {
          if (on) {
            for (const p of this.pins) {
              const opts = p.compliance > 0 ? { compliance: p.compliance, ...(p.group ? { group: p.group } : {}) } : {};
              p.id = w.createPin(p.particle, p.target, opts);
            }
          } else {
            for (const p of this.pins) {
              p.target = w.pinTarget(p.id);
              w.destroyPin(p.id);
            }
          }
          this.pinsOn = on;
        }
        return { replies: [this.statusMessage()], broadcast: true, scene: true };
      }
      case 'group_weight': {
        const g = indexIn(msg.index, this.groups, 'group');
        if (!Number.isInteger(msg.weight)) refuse('weight must be an integer');
        w.setGroupWeight(g.id, msg.weight);
        g.weight = msg.weight;
        return { scene: true };
      }
      case 'rest_scale': {
        const b = indexIn(msg.body, this.bodies, 'body');
        const s = [msg.scale, msg.scale_u ?? 1, msg.scale_v ?? 1];
        finite3(s, 'scale, scale_u, scale_v');
        w.setRestScale(b.id, s[0], s[1], s[2]);
        b.restScale = s;
        return {};
      }
      case 'pause':
        this.paused = bool(msg.paused, 'paused');
        return { replies: [this.statusMessage()], broadcast: true };
      case 'step':
        if (!this.paused) refuse('step is for a paused scene');
        return { stepped: true };
      case 'reset':
        this.#load(this.paused);
        return { scene: true };
      case 'save': {
        const json = this.#saveWithoutDrags();
        fs.mkdirSync(this.saveDir, { recursive: true });
        const file = path.join(this.saveDir, `${this.name}-${String(this.record.frame).padStart(5, '0')}.json`);
        fs.writeFileSync(file, json);
        return { replies: [{ type: 'saved', path: file, json }] };
      }
      case 'export': {
        if (msg.format !== 'gltf' && msg.format !== '3dm') refuse('format must be "gltf" or "3dm"');
        const metric = msg.metric ?? 'planarity';
        if (!FIELDS.includes(metric)) refuse(`metric must be one of ${FIELDS.join(', ')}`);
        const file = path.join(this.saveDir, `${this.name}-${String(this.record.frame).padStart(5, '0')}.${msg.format}`);
        const bytes = await this.exportBytes(msg.format, metric);
        fs.mkdirSync(this.saveDir, { recursive: true });
        fs.writeFileSync(file, bytes);
        return { replies: [{ type: 'exported', format: msg.format, metric, path: file, base64: bytes.toString('base64') }] };
      }
      default:
        refuse(`unknown message type ${JSON.stringify(msg.type)}`);
    }
    return {};
  }

  /** Ends a page's drag (its pin destroyed); nothing when it holds none. Also when a page closes. */
  releaseDrag(page) {
    const drag = this.drags.get(page);
    if (!drag) return;
    this.drags.delete(page);
    if (this.world) this.world.destroyPin(drag.pin);
  }

  /** The scene JSON of the current state without the pages' drag pins (a design, not a gesture). */
  #saveWithoutDrags() {
    const w = this.world;
    const held = [...this.drags.entries()].map(([page, d]) => [page, d.particle, w.pinTarget(d.pin)]);
    for (const [page] of held) this.releaseDrag(page);
    try {
      return w.saveJson();
    } finally {
      for (const [page, particle, target] of held)
        this.drags.set(page, { pin: w.createPin(particle, target, { compliance: DRAG_COMPLIANCE }), particle });
    }
  }

  /** The current state as .gltf (JSON text) or .3dm bytes, coloured by `metric`'s error field. */
  async exportBytes(format, metric) {
    const k = FIELDS.indexOf(metric);
    const meshes = this.bodies.filter((b) => b.triangles.length > 0);
    if (meshes.length === 0) refuse('nothing to export: no body of this scene has triangles (export writes meshes)');
    const snapshot = {
      name: this.name,
      positions: Float64Array.from(this.positions),
      meshes: meshes.map((b) => ({ name: b.name, triangles: b.triangles })),
      colors: fieldColors(metric, this.fieldValues[k], this.tolerances[metric]),
    };
    if (format === 'gltf') return Buffer.from(JSON.stringify(toGltf(snapshot)));
    return to3dm(snapshot);
  }

  close() {
    if (this.world) this.world.close();
    this.world = null;
  }
}

module.exports = { Session, RefusedMessage, FIELDS, MAGIC, DRAG_COMPLIANCE };
