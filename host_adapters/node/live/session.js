'use strict';
// One live scene: the world a page watches and edits (docs/live-protocol.md). The server owns the
// clock and the sockets; a Session owns the world, turns it into the protocol's messages, and
// applies the page's edits. Every edit is validated here or refused by the C library; either way a
// refused edit changes nothing and comes back as an `error` reply. Saves and exports go to one
// output folder under names made here (never from the scene), the oldest deleted beyond a bound.

const fs = require('fs');
const path = require('path');
const { World, EmbraError, NumericalError } = require('../lib');
const { fieldColors, toGltf, to3dm } = require('../lib/export');

const FIELDS = ['planarity', 'thickness', 'miter'];
/**
 * A drag is a soft pin in the default group, whose soft pins are projected before its welds and
 * panel constraints in every pass, so the panels correct last. Its compliance and its reach (the
 * drag pin's target is kept within DRAG_REACH times the scene's diagonal of the particle, however far
 * the cursor goes) bound its pull, and its speed (DRAG_SPEED) the momentum the mesh carries into its
 * panels when it is pulled taut. Those keep a drag's frames well inside the panels' tolerances on
 * the POQ drapes, but they are feedback and can overshoot; what guarantees the limit is the step
 * (#stepGuarded): while a drag is held, a frame that starts with every panel metric within DRAG_SAFE
 * of its max and ends above it is undone and stepped again without the drag's pull
 * (docs/live-protocol.md).
 */
const DRAG_COMPLIANCE = 2e-5; // m/N
const DRAG_REACH = 0.1; // of the scene's diagonal at load
const DRAG_BACK_OFF = 0.3; // of a tolerance's max: above it the drags' reach halves each frame
const DRAG_EASE = 0.2; // of a tolerance's max: below it the drags' reach grows back
const DRAG_GAIN_START = 0.05; // a new drag's reach, of DRAG_REACH: it grows from there
const DRAG_SPEED = 0.15; // of the scene's diagonal per second, times the reach's gain: the drag target's top speed
const DRAG_SAFE = 0.6; // of a tolerance's max: a drag frame that ends above it (from within it) is undone
const MAGIC = 0x464d4245; // 'EBMF' little-endian
/**
 * A page's coordinates (drag targets, collider positions) are places in the scene: within its
 * workspace, the box around everything the scene holds at load (particles, pin targets, collider
 * positions) grown on every side by WORKSPACE_REACH times its diagonal (at least 1 model unit).
 * The C library accepts any coordinate up to +-1e300, but a drag pin pulled to 1e200 makes the
 * next step fail and one pulled to 1e30 flings the mesh beyond what a frame's float32 can carry.
 */
const WORKSPACE_REACH = 1000;
const FIGHTS_LISTED = 10; // constraints listed in a `fights` message
const FIGHTS_COLOURED = 64; // constraints whose particles a `fights` message colours
/** Output files kept per scene in the output folder (the oldest deleted beyond it), by default. */
const KEEP_FILES = 100;
const OUTPUT_KINDS = ['json', 'gltf', '3dm'];

class RefusedMessage extends Error {}

function refuse(message) {
  throw new RefusedMessage(message);
}

function finite3(value, what, n = 3) {
  if (!Array.isArray(value) || value.length !== n || !value.every((v) => typeof v === 'number' && Number.isFinite(v)))
    refuse(`${what} must be ${n} finite numbers`);
  return value;
}

/**
 * The stem of output file names: the scene file's name as given on the command line (never the
 * scene's `name`), reduced to [A-Za-z0-9_-] and at most 64 characters; "scene" if nothing is left.
 */
function outputStem(scenePath) {
  const stem = path.basename(scenePath, path.extname(scenePath)).replace(/[^A-Za-z0-9_-]/g, '_').slice(0, 64);
  return /[A-Za-z0-9]/.test(stem) ? stem : 'scene';
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
   * @param {{saveDir?: string, keepFiles?: number}} options the output folder `save` and `export`
   *   write to (default: the current folder), and how many of this scene's files it keeps there
   */
  constructor(scenePath, options = {}) {
    this.scenePath = path.resolve(scenePath);
    this.sceneText = fs.readFileSync(this.scenePath, 'utf8');
    this.saveDir = path.resolve(options.saveDir || '.');
    this.keepFiles = options.keepFiles ?? KEEP_FILES;
    if (!Number.isInteger(this.keepFiles) || this.keepFiles < 1) throw new RangeError('keepFiles must be an integer >= 1');
    // Solver threads: the option (0: one per core), else the scene's own solver.threads. Not every
    // core by default: where the page renders on the same machine, the solver's barriers wait on
    // the browser (bench/README.md, the live page's frame rate).
    this.threads = options.threads;
    if (this.threads !== undefined && (!Number.isInteger(this.threads) || this.threads < 0))
      throw new RangeError('threads must be an integer >= 0');
    this.stem = outputStem(this.scenePath);
    this.outputPattern = new RegExp(`^${this.stem}-(\\d{6,})-f\\d+\\.(${OUTPUT_KINDS.join('|')})$`);
    this.seq = 0;
    this.world = null;
    this.#load();
  }

  /** Builds the world from the scene's text; a reset keeps the paused state. */
  #load(paused = false) {
    const world = World.loadJson(this.sceneText, path.dirname(this.scenePath));
    if (this.threads !== undefined) world.setSolver({ threads: this.threads });
    if (this.world) this.world.close();
    this.world = world;
    this.paused = paused;
    this.gravityOn = true;
    this.pinsOn = true;
    this.drags = new Map(); // page -> {pin, particle}: each page holds at most one drag
    this.lastMs = 0;
    this.dragGain = 1; // the drags' reach, as a fraction of dragReach (#adaptDrag)
    // What the drag's guard did (#stepGuarded), counted in frames since the load: stepped with a
    // drag held, kept as first stepped, undone and stepped again without the pull (`redone`), and
    // again at rest (`stilled`), held where they started (`held`), kept over DRAG_SAFE because the
    // frame started over it (`over_before`) or a collider moved in it (`collider_moved`); `steps`
    // counts every world step of those frames, `undone_worst` the worst metric (of its max) a frame
    // undone had reached.
    this.dragGuard = { frames: 0, kept: 0, redone: 0, stilled: 0, held: 0, over_before: 0, collider_moved: 0, steps: 0,
                       undone_worst: 0 };
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
               panels, restScale: [1, 1, 1], edges: [] };
    });
    this.#edgesOf(saved);
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
    this.colliderPoses = this.#colliderPoses();
    this.fieldValues = FIELDS.map(() => new Float64Array(this.particles).fill(NaN));
    this.#measure();
    this.workspace = this.#workspace();
  }

  /**
   * The edges a page draws of each body without triangles (a net, a cable): its mesh's `edges` and
   * the scene's distance constraints between two of its particles, as world particle indices.
   */
  #edgesOf(saved) {
    const byName = new Map(this.bodies.map((b) => [b.name, b]));
    const world = (ref) => (Number.isInteger(ref) ? ref : (byName.get(ref?.body)?.first ?? NaN) + ref?.vertex);
    (saved.bodies || []).forEach((entry, i) => {
      const b = this.bodies[i];
      if (!b || b.triangles.length > 0) return;
      for (const [u, v] of entry.mesh?.edges || []) b.edges.push(b.first + u, b.first + v);
    });
    const inside = (b, p) => Number.isInteger(p) && p >= b.first && p < b.first + b.count;
    for (const c of saved.constraints || []) {
      if (c.kind !== 'distance') continue;
      for (const pair of c.particles || []) {
        const [u, v] = pair.map(world);
        const b = this.bodies.find((x) => x.triangles.length === 0 && inside(x, u) && inside(x, v));
        if (b) b.edges.push(u, v);
      }
    }
  }

  /** The box a page's coordinates must lie in (WORKSPACE_REACH): {min, max}, 3 numbers each. */
  #workspace() {
    const lo = [Infinity, Infinity, Infinity];
    const hi = [-Infinity, -Infinity, -Infinity];
    const add = (p) => p.forEach((v, k) => {
      lo[k] = Math.min(lo[k], v);
      hi[k] = Math.max(hi[k], v);
    });
    for (let i = 0; i < this.particles; ++i) add(this.positions.subarray(3 * i, 3 * i + 3));
    for (const p of this.pins) add(this.world.pinTarget(p.id));
    for (const c of this.colliders) add(this.world.colliderTransform(c.id).position);
    if (lo[0] > hi[0]) { // an empty scene: the box around the origin
      lo.fill(0);
      hi.fill(0);
    }
    const diagonal = Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
    this.dragReach = DRAG_REACH * Math.max(diagonal, 1e-9);
    this.dragStep = DRAG_SPEED * Math.max(diagonal, 1e-9) * this.dt; // per frame
    const reach = WORKSPACE_REACH * Math.max(diagonal, 1);
    return { min: lo.map((v) => v - reach), max: hi.map((v) => v + reach) };
  }

  /** A point of the scene from a page: 3 finite numbers inside the workspace. */
  #point(value, what) {
    finite3(value, what);
    const { min, max } = this.workspace;
    if (!value.every((v, k) => v >= min[k] && v <= max[k]))
      refuse(`${what} ${JSON.stringify(value)} is outside the scene's workspace ` +
             `[${min.map((v) => v.toPrecision(6))}] .. [${max.map((v) => v.toPrecision(6))}]`);
    return value;
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

  /**
   * Moves a drag pin's target (its lead) toward the cursor: by at most dragStep times dragGain a
   * frame, and never farther than the reach (dragReach times dragGain) from its particle. The speed
   * limit is what keeps a fine mesh within tolerance: a mesh dragged fast until it is pulled taut
   * stops against its panel constraints with the momentum it had, and the impact, not the pull,
   * opens the panels (on the 32 x 32 drape, docs/live-protocol.md); a back-off (#adaptDrag) slows
   * the lead and shortens the reach at once.
   */
  #leadDrag(drag) {
    const at = this.positions.subarray(3 * drag.particle, 3 * drag.particle + 3);
    const within = (p, limit) => {
      const d = p.map((v, k) => v - at[k]);
      const length = Math.hypot(...d);
      return length > limit ? d.map((v, k) => at[k] + (limit / length) * v) : p;
    };
    const reach = this.dragReach * this.dragGain;
    const wanted = within(drag.target, reach);
    const move = wanted.map((v, k) => v - drag.lead[k]);
    const length = Math.hypot(...move);
    const step = this.dragStep * this.dragGain;
    const f = length > step ? step / length : 1;
    drag.lead = within(drag.lead.map((v, k) => v + f * move[k]), reach);
    this.world.setPinTarget(drag.pin, drag.lead);
  }

  /**
   * The drags' reach shrinks while a panel metric nears its tolerance's max (above DRAG_BACK_OFF of
   * it: halved each frame) and grows back (by a quarter a frame, up to DRAG_REACH) below DRAG_EASE.
   */
  #adaptDrag() {
    if (this.record.planarity_max === undefined) return;
    const worst = this.#worst();
    if (worst > DRAG_BACK_OFF) this.dragGain *= 0.5;
    else if (worst < DRAG_EASE) this.dragGain = Math.min(1, this.dragGain * 1.25);
  }

  /** The worst panel metric of the last #measure, as a fraction of its tolerance's max (0: no panels). */
  #worst() {
    const r = this.record;
    if (r.planarity_max === undefined) return 0;
    const t = this.tolerances;
    return Math.max(r.planarity_max / t.planarity.max, r.thickness_error_max / t.thickness.max,
                    r.miter_error_max / t.miter.max);
  }

  /** Every collider's pose now, as one array of numbers (position then rotation, per collider). */
  #colliderPoses() {
    return this.colliders.flatMap((c) => {
      const pose = this.world.colliderTransform(c.id);
      return [...pose.position, ...pose.rotation];
    });
  }

  /**
   * The drags' pull set to nothing: each lead at its particle's place (the positions last measured),
   * and the gain back to a new drag's.
   */
  #stopDrags() {
    for (const drag of this.drags.values()) {
      drag.lead = Array.from(this.positions.subarray(3 * drag.particle, 3 * drag.particle + 3));
      this.world.setPinTarget(drag.pin, drag.lead);
    }
    this.dragGain = Math.min(this.dragGain, DRAG_GAIN_START);
  }

  /** One world step: null, or the NumericalError it failed with (the world as before it). */
  #tryStep() {
    try {
      this.world.step();
      return null;
    } catch (e) {
      if (!(e instanceof NumericalError)) throw e;
      return e;
    }
  }

  /**
   * One frame while a drag is held, made transactional: the positions and velocities before the
   * step are kept (a step's outcome depends on nothing else the step changes but the clock and the
   * colliders' poses), and a frame that starts with every panel metric within DRAG_SAFE of its max
   * and ends above it is not kept. It is stepped again from the same state with the drags' leads at
   * their particles and the gain cut (`redone`); if that frame is over too, again with the dragged
   * bodies at rest (`stilled`); if that is over too, the state before the frame is kept with those
   * bodies at rest (`held`), whose metrics are the frame's start's. So a drag frame that starts
   * within DRAG_SAFE ends within it, by construction; a drag started on a scene within it stays
   * within it. Not undone: a frame that started over DRAG_SAFE (the scene's own motion: a drape
   * still falling) and a frame in which a collider moved (its move cannot be put back through the
   * C API); #adaptDrag brakes the drag there. Each re-step advances the world's clock by a frame
   * (the frame counter has no setter). Returns null, or the NumericalError of the frame's first
   * step (the world as before it); a re-step that fails counts as over.
   */
  #stepGuarded() {
    const w = this.world;
    const g = this.dragGuard;
    const x0 = w.positions();
    const v0 = w.velocities();
    ++g.frames;
    ++g.steps;
    for (const drag of this.drags.values()) this.#leadDrag(drag);
    const error = this.#tryStep();
    if (error) return error;
    this.#measure();
    if (this.#worst() <= DRAG_SAFE) {
      ++g.kept;
      return null;
    }
    const poses = this.#colliderPoses();
    if (poses.some((v, k) => v !== this.colliderPoses[k])) {
      ++g.collider_moved;
      return null;
    }
    const first = this.#worst();
    const x1 = w.positions();
    const v1 = w.velocities();
    w.setPositions(x0);
    w.setVelocities(v0);
    this.#measure(); // the frame's start
    if (this.#worst() > DRAG_SAFE) { // over before the step: the frame as first stepped
      ++g.over_before;
      w.setPositions(x1);
      w.setVelocities(v1);
      this.#measure();
      return null;
    }
    g.undone_worst = Math.max(g.undone_worst, first);
    // A re-step from (x0, velocities): kept (counted as `outcome`) when it ends within DRAG_SAFE,
    // else the state is put back.
    const retry = (velocities, outcome) => {
      ++g.steps;
      if (!this.#tryStep()) {
        this.#measure();
        if (this.#worst() <= DRAG_SAFE) {
          ++g[outcome];
          return true;
        }
      }
      w.setPositions(x0);
      w.setVelocities(velocities);
      return false;
    };
    this.#stopDrags();
    if (retry(v0, 'redone')) return null;
    const still = Float64Array.from(v0);
    for (const b of this.bodies)
      if ([...this.drags.values()].some((d) => d.particle >= b.first && d.particle < b.first + b.count))
        still.fill(0, 3 * b.first, 3 * (b.first + b.count));
    w.setVelocities(still);
    if (retry(still, 'stilled')) return null;
    ++g.held;
    this.#measure();
    return null;
  }

  /** Advances one frame. A numerical failure (the world restored to before the step) pauses. */
  step() {
    const t0 = process.hrtime.bigint();
    let error;
    if (this.drags.size > 0 && this.bodies.some((b) => b.panels > 0)) { // a guard for panel metrics only
      error = this.#stepGuarded();
    } else {
      error = this.#tryStep();
      if (!error) this.#measure();
    }
    this.lastMs = Number(process.hrtime.bigint() - t0) / 1e6;
    if (error) {
      this.paused = true;
      return { type: 'error', message: `${error.message} (paused)` };
    }
    this.colliderPoses = this.#colliderPoses();
    this.record.ms = this.lastMs;
    this.#adaptDrag();
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
                                         triangles: Array.from(b.triangles), edges: b.edges, panel_mesh: b.panels > 0,
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

  /**
   * What fights in the last step (docs/live-protocol.md, `fights`): the FIGHTS_LISTED worst
   * constraints and soft pins (embra_world_get_worst_constraints: ranked by violation x force) with
   * their group's and pin's names, the pairs of groups pulling against each other
   * (embra_world_get_group_conflicts), and per particle the largest energy (violation x force, J)
   * of the FIGHTS_COLOURED worst constraints it is in, as [particle, energy] pairs.
   */
  fightsMessage() {
    const w = this.world;
    const same = (a, b) => a && b && a.index === b.index && a.generation === b.generation;
    const groupName = (id) => (this.groups.find((g) => same(g.id, id)) || { name: `group ${id.index}` }).name;
    const pinName = (id) => {
      if (!id) return null;
      const scene = this.pins.find((p) => this.pinsOn && same(p.id, id));
      if (scene) return scene.name;
      return [...this.drags.values()].some((d) => same(d.pin, id)) ? 'drag' : `pin ${id.index}`;
    };
    const all = w.worstConstraints(FIGHTS_COLOURED);
    const energy = new Map();
    for (const c of all) {
      const e = Math.abs(c.violation * c.force);
      for (const p of c.particles) energy.set(p, Math.max(energy.get(p) || 0, e));
    }
    return {
      type: 'fights', frame: this.record.frame,
      worst: all.slice(0, FIGHTS_LISTED).map((c) => ({
        kind: c.kind, group: groupName(c.group), index: c.index, pin: pinName(c.pin), particles: c.particles,
        residual: c.residual, violation: c.violation, unit: c.unit, force: c.force,
      })),
      conflicts: w.groupConflicts().map((c) => ({ a: groupName(c.a), b: groupName(c.b), force: c.force, particles: c.particles })),
      energy: [...energy.entries()],
    };
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
   * after which nothing has changed. Synchronous, so a refusal is answered before the page's next
   * message is read (a next message that closes the connection cannot swallow the answer); only an
   * export returns a promise of its result.
   */
  handle(msg, page = 'page') {
    if (msg === null || typeof msg !== 'object' || Array.isArray(msg)) refuse('a message must be a JSON object');
    const w = this.world;
    switch (msg.type) {
      case 'drag_start': {
        if (!Number.isInteger(msg.particle) || msg.particle < 0 || msg.particle >= this.particles)
          refuse(`particle ${JSON.stringify(msg.particle)} is not in [0, ${this.particles})`);
        const target = this.#point(msg.target, 'target');
        const pin = w.createPin(msg.particle, target, { compliance: DRAG_COMPLIANCE });
        this.releaseDrag(page);
        this.drags.set(page, { pin, particle: msg.particle, target: [...target], lead: [...target] });
        this.dragGain = Math.min(this.dragGain, DRAG_GAIN_START);
        return {};
      }
      case 'drag': {
        const target = this.#point(msg.target, 'target');
        const drag = this.drags.get(page);
        if (!drag) refuse('drag without drag_start');
        drag.target = [...target]; // the pin's target follows it at the next step (#leadDrag)
        return {};
      }
      case 'drag_end': {
        const pinHere = msg.pin === undefined ? false : bool(msg.pin, 'pin');
        const drag = this.drags.get(page);
        if (!pinHere || !drag) {
          this.releaseDrag(page);
          return {};
        }
        // "Pin here": the drag's soft pin becomes a hard pin of the scene at the release point.
        const { target } = drag;
        this.releaseDrag(page);
        if (!this.pinsOn) refuse('the scene\'s pins are off: turn them on to pin here');
        const index = this.pins.length;
        const id = w.createPin(drag.particle, target);
        this.pins.push({ id, index, name: `pin_here_${index}`, particle: drag.particle, compliance: 0, group: undefined });
        return { scene: true };
      }
      case 'pin_target': {
        if (!this.pinsOn) refuse('the scene\'s pins are off');
        const p = indexIn(msg.index, this.pins, 'pin');
        w.setPinTarget(p.id, this.#point(msg.target, 'target'));
        return {}; // the dot follows its particle in the frames; the next scene message has the target
      }
      case 'collider_pose': {
        const c = indexIn(msg.index, this.colliders, 'collider');
        const position = this.#point(msg.position, 'position');
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
        const file = this.writeOutput('json', json, this.record.frame);
        return { replies: [{ type: 'saved', frame: this.record.frame, path: file, json }] };
      }
      case 'export': {
        if (msg.format !== 'gltf' && msg.format !== '3dm') refuse('format must be "gltf" or "3dm"');
        const metric = msg.metric ?? 'planarity';
        if (!FIELDS.includes(metric)) refuse(`metric must be one of ${FIELDS.join(', ')}`);
        const frame = this.record.frame;
        return this.exportBytes(msg.format, metric).then((bytes) => {
          const file = this.writeOutput(msg.format, bytes, frame);
          return { replies: [{ type: 'exported', format: msg.format, metric, frame, path: file, base64: bytes.toString('base64') }] };
        });
      }
      case 'export_all': {
        // The scene JSON, the glTF and the .3dm of one frame: each snapshot is taken here, before
        // the server's clock can step again.
        const metric = msg.metric ?? 'planarity';
        if (!FIELDS.includes(metric)) refuse(`metric must be one of ${FIELDS.join(', ')}`);
        const frame = this.record.frame;
        const json = this.#saveWithoutDrags();
        const gltf = this.exportBytes('gltf', metric);
        const rhino = this.exportBytes('3dm', metric);
        return Promise.all([gltf, rhino]).then(([g, r]) => {
          const saved = { type: 'saved', frame, path: this.writeOutput('json', json, frame), json };
          const files = [['gltf', g], ['3dm', r]].map(([format, bytes]) => ({
            type: 'exported', format, metric, frame, path: this.writeOutput(format, bytes, frame), base64: bytes.toString('base64'),
          }));
          return { replies: [saved, ...files] };
        });
      }
      default:
        refuse(`unknown message type ${JSON.stringify(msg.type)}`);
    }
    return {};
  }

  /** This scene's files in the output folder, oldest first: [{name, seq}]. */
  outputFiles() {
    let entries;
    try {
      entries = fs.readdirSync(this.saveDir, { withFileTypes: true });
    } catch (e) {
      if (e.code === 'ENOENT') return [];
      throw e;
    }
    return entries.filter((d) => d.isFile() || d.isSymbolicLink())
      .map((d) => ({ name: d.name, m: this.outputPattern.exec(d.name) })).filter((f) => f.m)
      .map((f) => ({ name: f.name, seq: Number(f.m[1]) })).sort((a, b) => a.seq - b.seq);
  }

  /**
   * Writes one output file as `<stem>-<seq>-f<frame>.<kind>` in the output folder and returns its
   * path. `seq` counts up past every file of this scene already there; the file is created, never
   * overwritten (nor a link followed); beyond keepFiles of this scene's files the oldest are deleted.
   */
  writeOutput(kind, data, frame) {
    if (!OUTPUT_KINDS.includes(kind)) throw new RangeError(`no output kind ${kind}`);
    try {
      fs.mkdirSync(this.saveDir, { recursive: true });
      const existing = this.outputFiles();
      for (let attempt = 0; ; ++attempt) {
        this.seq = Math.max(this.seq, existing.length ? existing[existing.length - 1].seq : 0) + 1;
        const name = `${this.stem}-${String(this.seq).padStart(6, '0')}-f${String(frame).padStart(5, '0')}.${kind}`;
        const file = path.resolve(this.saveDir, name);
        if (path.dirname(file) !== this.saveDir || !this.outputPattern.test(path.basename(file)))
          throw new Error(`${name} is not a file name of the output folder`); // unreachable: names are made here
        try {
          fs.writeFileSync(file, data, { flag: 'wx' });
        } catch (e) {
          if (e.code === 'EEXIST' && attempt < 10) continue;
          throw e;
        }
        const files = this.outputFiles();
        for (const old of files.slice(0, Math.max(0, files.length - this.keepFiles))) {
          try {
            fs.unlinkSync(path.join(this.saveDir, old.name));
          } catch (e) {
            if (e.code !== 'ENOENT') throw e;
          }
        }
        return file;
      }
    } catch (e) {
      refuse(`output folder ${this.saveDir}: ${e.message}`);
    }
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
    const held = [...this.drags.entries()].map(([page, d]) => [page, d, w.pinTarget(d.pin)]);
    for (const [page] of held) this.releaseDrag(page);
    try {
      return w.saveJson();
    } finally {
      for (const [page, d, at] of held)
        this.drags.set(page, { ...d, pin: w.createPin(d.particle, at, { compliance: DRAG_COMPLIANCE }) });
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

module.exports = { Session, RefusedMessage, FIELDS, MAGIC, DRAG_COMPLIANCE, DRAG_REACH, DRAG_SAFE, FIGHTS_LISTED, WORKSPACE_REACH, KEEP_FILES, outputStem };
