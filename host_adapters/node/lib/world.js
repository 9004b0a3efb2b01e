'use strict';
// The World: a JS view of one embra_world *, covering the whole C ABI.
//
// Arguments are checked in JS first (TypeError for a wrong type or an unknown field, RangeError for a
// wrong length, an integer out of int32 or an unknown name); then C checks the values. A refused call
// throws the EmbraError of its status with the C library's message and leaves the world unchanged,
// exactly as the C function does. Def fields keep their C names (snake_case, as in the scene JSON and
// in every object read back); camelCase spellings are accepted as well (settleSpeed = settle_speed).
// close() is idempotent; a closed World refuses every call (InvalidArgumentError "world is NULL ...
// (this World was closed)"). A World not closed is destroyed when garbage-collected.
//
// Every method runs on the calling (JS) thread and returns when C returns, except stepAsync, whose
// frames run on koffi's worker threads: while one runs, the JS thread stays free, cancel() stops it,
// and any other call on that World is refused by C with LockedError (one call at a time per world)
// and changes nothing.

const fs = require('node:fs');
const nodePath = require('node:path');

const capi = require('./capi');
const buf = require('./buffers');
const { EmbraError, errorFor, check } = require('./errors');

const { lib } = capi;

// The names each enum's values go by here and in scenes: generated from embra.h with the enums.
const SHAPES = capi.COLLIDER_NAMES;
const KINDS = capi.CONSTRAINT_NAMES;
const GENERATE = capi.GENERATE_NAMES;
const PANEL_PINS = capi.PANEL_PINS_NAMES;
const PANEL_CORNERS = capi.PANEL_CORNERS_NAMES;
const PANEL_PRECISION = capi.PANEL_PRECISION_NAMES;
const PIN_SUPPORTS = capi.PIN_SUPPORT_NAMES;
const AREA_LOAD_MODES = capi.AREA_LOAD_NAMES;
const AREA_LOAD_MODE_NAMES = Object.fromEntries(Object.entries(AREA_LOAD_MODES).map(([k, v]) => [v, k]));
const PANEL_METRICS = capi.PANEL_METRIC_NAMES;
const SOLVE_UNTIL = capi.SOLVE_UNTIL_NAMES;
const SOLVE_OUTCOMES = Object.freeze(Object.fromEntries(Object.entries(capi.SOLVE_NAMES).map(([k, v]) => [v, k])));
const METRIC_NAMES = Object.freeze(Object.fromEntries(Object.entries(capi.PANEL_METRIC_NAMES).map(([k, v]) => [v, k])));
const CUTS_FORMATS = capi.CUTS_NAMES;

// --- ids ------------------------------------------------------------------------------------------

/** A value id {index, generation} of an object in a world; {0, 0} means "none" or "the default". */
class Id {
  constructor(index = 0, generation = 0) {
    this.index = buf.uint32(index, `${new.target.name}.index`);
    this.generation = buf.uint32(generation, `${new.target.name}.generation`);
    Object.freeze(this);
  }

  equals(other) {
    return other instanceof Id && other.constructor === this.constructor && other.index === this.index &&
      other.generation === this.generation;
  }

  toString() {
    return `${this.constructor.name}(index=${this.index}, generation=${this.generation})`;
  }
}

/** embra_group_id: a constraint group ({0, 0} = the default group where a field says so). */
class GroupId extends Id {}
/** embra_body_id. */
class BodyId extends Id {}
/** embra_pin_id. */
class PinId extends Id {}
/** embra_collider_id. */
class ColliderId extends Id {}
/** embra_field_id: a wind, pressure, surface tension or vortex field. */
class FieldId extends Id {}

const ID_CLASSES = new Map([['embra_group_id', GroupId], ['embra_body_id', BodyId], ['embra_pin_id', PinId],
  ['embra_collider_id', ColliderId], ['embra_field_id', FieldId]]);

/** A body's id and its particle range [first, first + count). */
class Body {
  constructor(id, first, count) {
    if (!(id instanceof BodyId)) throw new TypeError(`Body: expected a BodyId, got ${buf.describe(id)}`);
    this.id = id;
    this.first = buf.int32(first, 'Body.first');
    this.count = buf.int32(count, 'Body.count');
    Object.freeze(this);
  }

  toString() {
    return `Body(index=${this.id.index}, first=${this.first}, count=${this.count})`;
  }
}

function toId(value, cls, name) {
  if (value === null || value === undefined) return new cls();
  if (value instanceof Body && cls === BodyId) return value.id;
  if (!(value instanceof cls)) throw new TypeError(`${name}: expected a ${cls.name}, got ${buf.describe(value)}`);
  return value;
}

/** A struct read from C with its ids as Id objects (recursively). */
function wrapIds(value, type) {
  for (const [key, member] of Object.entries(type.members)) {
    const cls = ID_CLASSES.get(member.type.name);
    if (cls) value[key] = new cls(value[key].index, value[key].generation);
    else if (member.type.primitive === 'Record') wrapIds(value[key], member.type);
  }
  return value;
}

// --- defs -----------------------------------------------------------------------------------------

/** settleSpeed -> settle_speed: the C name of a field given in camelCase. */
function cName(key) {
  return key.replace(/[A-Z]/g, (c) => `_${c.toLowerCase()}`);
}

/** The options of a call as a Map from C names, each given once; unknown keys are left to the caller. */
function options(value, what) {
  if (value === null || value === undefined) return new Map();
  if (typeof value !== 'object' || Array.isArray(value) || ArrayBuffer.isView(value)) {
    throw new TypeError(`${what}: expected an object of named settings, got ${buf.describe(value)}`);
  }
  const out = new Map();
  for (const [key, v] of Object.entries(value)) {
    const name = cName(key);
    if (out.has(name)) throw new TypeError(`${what}: '${name}' is given twice (as '${key}' too)`);
    out.set(name, v);
  }
  return out;
}

/** Sets fields of a def (a JS object of koffi struct `type`) from a Map or object of values. */
function fill(def, type, fields, what) {
  const given = fields instanceof Map ? fields : options(fields, what);
  for (const [key, value] of given) {
    const member = type.members[key];
    if (member === undefined) {
      throw new TypeError(`${what} has no field '${key}' (fields: ${Object.keys(type.members).join(', ')})`);
    }
    const t = member.type;
    const name = `${what}.${key}`;
    const cls = ID_CLASSES.get(t.name);
    if (cls) {
      def[key] = toId(value, cls, name);
    } else if (t.primitive === 'Record') {
      fill(def[key], t, value, name);
    } else if (t.primitive === 'Array') {
      const v = buf.fixed(value, t.length, name);
      def[key] = t.ref.primitive === 'Int32' ? v.map((x, i) => buf.int32(x, `${name}[${i}]`)) : v;
    } else if (t.primitive === 'Int32') {
      def[key] = buf.int32(value, name);
    } else if (t.primitive === 'Int64') {
      def[key] = buf.int64(value, name);
    } else if (t.primitive === 'Float64') {
      def[key] = buf.number(value, name);
    } else {
      throw new TypeError(`${name} is an array pointer: give the data as the call's own argument`);
    }
  }
  return def;
}

/** options.allowPathsOutsideBase of a load: true or false only (a security choice is not guessed). */
function allowOutside(value, what) {
  const opts = options(value, what);
  const allow = take(opts, 'allow_paths_outside_base');
  if (opts.size) throw new TypeError(`${what}: unknown option '${[...opts.keys()][0]}' (known: allowPathsOutsideBase)`);
  if (allow === undefined) return false;
  if (typeof allow !== 'boolean') {
    throw new TypeError(`${what}.allowPathsOutsideBase: expected true or false, got ${buf.describe(allow)}`);
  }
  return allow;
}

function enumValue(value, table, name) {
  if (typeof value === 'string') {
    if (!Object.prototype.hasOwnProperty.call(table, value)) {
      throw new RangeError(`${name}: unknown name '${value}' (known: ${Object.keys(table).join(', ')})`);
    }
    return table[value];
  }
  return buf.int32(value, name);
}

function take(opts, key) {
  const v = opts.get(key);
  opts.delete(key);
  return v;
}

function wholeTuples(array, width, name, what) {
  if (array.length % width) {
    throw new RangeError(`${name}: ${array.length} ${what} is not a whole number of ${width}-tuples`);
  }
  return array.length / width;
}

function xyzCount(array, name) {
  if (array.length % 3) throw new RangeError(`${name}: ${array.length} numbers is not a whole number of xyz triples`);
  return buf.int32(array.length / 3, `${name} count`);
}

// --- the world ------------------------------------------------------------------------------------

const registry = new FinalizationRegistry((ptr) => lib.embra_world_destroy(ptr));
const ADOPT = Symbol('adopt');

/** An embra world. Call close() when done (or let it be garbage-collected); a closed World refuses calls. */
class World {
  #ptr = null;
  /** A stepAsync frame is inside C on a worker thread. */
  #inFlight = false;
  /** close() during that frame: the pointer to destroy when it returns. */
  #destroyWhenReturned = null;
  /** stepAsync calls run one after another. */
  #queue = Promise.resolve();

  /**
   * A world from embra_default_solver_def() and `settings`: any embra_solver_def field (dt, substeps,
   * iterations, chebyshev_rho_milli, gravity, damping, settle_speed, tethers, realign_passes, self_collision, chain_solve).
   */
  constructor(settings, ptr) {
    if (settings === ADOPT) {
      this.#adopt(ptr);
      return;
    }
    const def = fill(lib.embra_default_solver_def(), capi.SolverDef, settings, 'SolverDef');
    const out = [null];
    check(lib.embra_world_create(out, def));
    this.#adopt(out[0]);
  }

  #adopt(ptr) {
    this.#ptr = ptr;
    registry.register(this, ptr, this);
  }

  /**
   * A world from scene JSON text (a string or UTF-8 bytes). The scene's OBJ paths are relative to
   * `baseDir` (null: the current folder) and must stay inside it, unless
   * `loadOptions.allowPathsOutsideBase` is true (for scenes the host trusts: absolute paths and '..' allowed).
   */
  static loadJson(text, baseDir = null, loadOptions = undefined) {
    let data;
    if (typeof text === 'string') data = Buffer.from(text, 'utf8');
    else if (text instanceof Uint8Array) data = text;
    else throw new TypeError(`text: expected a string or a Uint8Array, got ${buf.describe(text)}`);
    const def = lib.embra_default_load_options();
    def.allow_paths_outside_base = allowOutside(loadOptions, 'loadJson options') ? 1 : 0;
    def.base_dir = baseDir === null || baseDir === undefined ? null : buf.cString(baseDir, 'baseDir');
    const out = [null];
    check(lib.embra_world_load_json_with_options(out, data, data.length, def));
    return new World(ADOPT, out[0]);
  }

  /**
   * A world from a scene file. Its OBJ paths are relative to the file's folder and must stay inside it,
   * unless `loadOptions.allowPathsOutsideBase` is true (as for loadJson).
   */
  static loadFile(path, loadOptions = undefined) {
    const file = buf.cString(path, 'path');
    if (allowOutside(loadOptions, 'loadFile options')) {
      // embra_world_load_file has no options: the file is read here, its folder the base
      return World.loadJson(fs.readFileSync(file), nodePath.dirname(file), { allowPathsOutsideBase: true });
    }
    const out = [null];
    check(lib.embra_world_load_file(out, file));
    return new World(ADOPT, out[0]);
  }

  // --- lifetime -----------------------------------------------------------------------------------

  /**
   * Destroys the world (embra_world_destroy). Idempotent. During a stepAsync frame it cancels that frame
   * and the world is destroyed when the worker returns; the stepAsync promise rejects.
   */
  close() {
    const ptr = this.#ptr;
    this.#ptr = null;
    if (ptr === null) return;
    registry.unregister(this);
    if (this.#inFlight) {
      lib.embra_world_cancel(ptr);
      this.#destroyWhenReturned = ptr;
    } else {
      lib.embra_world_destroy(ptr);
    }
  }

  get closed() {
    return this.#ptr === null;
  }

  /**
   * Asks the step in progress (a stepAsync frame on a worker thread) to stop: that frame rejects with
   * CancelledError and the world is as before it. A request made while no step runs stops the next frame
   * stepped, before its first iteration. The one call C accepts while another is in progress.
   */
  cancel() {
    this.#call('embra_world_cancel');
  }

  /** Calls a C function with this world first; a closed World passes NULL, which C refuses. */
  #call(name, ...args) {
    const ptr = this.#ptr;
    const status = lib[name](ptr, ...args);
    if (status !== capi.OK) {
      const err = errorFor(status);
      if (ptr === null) throw new err.constructor(`${err.message} (this World was closed)`, status);
      throw err;
    }
  }

  // --- solver settings ----------------------------------------------------------------------------

  /** The solver settings (a copy: change them with setSolver). */
  get solver() {
    const d = {};
    this.#call('embra_world_get_solver', d);
    return d;
  }

  /** Replaces the settings: the current ones with the given fields changed. */
  setSolver(settings) {
    const d = fill(this.solver, capi.SolverDef, settings, 'SolverDef');
    this.#call('embra_world_set_solver', d);
  }

  /** Gravity in m/s^2 from the next step on (reverse it for the Gaudi paradigm). */
  setGravity(gravity) {
    this.#call('embra_world_set_gravity', Float64Array.from(buf.fixed(gravity, 3, 'gravity')));
  }

  /** {particles, bodies, groups, pins, colliders, constraints}. */
  counts() {
    const c = {};
    this.#call('embra_world_get_counts', c);
    return c;
  }

  get particleCount() {
    return this.counts().particles;
  }

  /** Ids of the live objects of one kind, in creation order (two calls: count, then ids). */
  #ids(name, cls) {
    const n = [0];
    this.#call(name, null, 0, n);
    const out = new Uint32Array(2 * n[0]);
    this.#call(name, out, n[0], n);
    const ids = [];
    for (let k = 0; k < n[0]; k++) ids.push(new cls(out[2 * k], out[2 * k + 1]));
    return ids;
  }

  /** The BodyIds of the live bodies, in creation order (a loaded scene's: in the scene's order). */
  bodies() {
    return this.#ids('embra_world_get_bodies', BodyId);
  }

  /** The GroupIds of the live groups, the default and contact groups first. */
  groups() {
    return this.#ids('embra_world_get_groups', GroupId);
  }

  /** The PinIds of the live pins, in creation order. */
  pins() {
    return this.#ids('embra_world_get_pins', PinId);
  }

  /** The ColliderIds of the live colliders, in creation order. */
  colliders() {
    return this.#ids('embra_world_get_colliders', ColliderId);
  }

  // --- groups -------------------------------------------------------------------------------------

  /** A constraint group: {order (lower first; default 0), weight (projections per pass; default 1)}. */
  createGroup(settings) {
    const d = fill(lib.embra_default_group_def(), capi.GroupDef, settings, 'GroupDef');
    const g = {};
    this.#call('embra_group_create', d, g);
    return new GroupId(g.index, g.generation);
  }

  destroyGroup(group) {
    this.#call('embra_group_destroy', toId(group, GroupId, 'group'));
  }

  setGroupOrder(group, order) {
    this.#call('embra_group_set_order', toId(group, GroupId, 'group'), buf.int32(order, 'order'));
  }

  setGroupWeight(group, weight) {
    this.#call('embra_group_set_weight', toId(group, GroupId, 'group'), buf.int32(weight, 'weight'));
  }

  defaultGroup() {
    const g = {};
    this.#call('embra_world_default_group', g);
    return new GroupId(g.index, g.generation);
  }

  contactGroup() {
    const g = {};
    this.#call('embra_world_contact_group', g);
    return new GroupId(g.index, g.generation);
  }

  /** {count, residual_max, residual_rms} of a group's last step. */
  groupReport(group) {
    const r = {};
    this.#call('embra_group_get_report', toId(group, GroupId, 'group'), r);
    return r;
  }

  /**
   * Enables or disables a group (embra_group_set_enabled): a disabled group keeps its constraints and
   * soft pins but is not projected, measured or diagnosed. Not the contact group.
   */
  setGroupEnabled(group, enabled) {
    if (typeof enabled !== 'boolean') throw new TypeError(`enabled: expected true or false, got ${buf.describe(enabled)}`);
    this.#call('embra_group_set_enabled', toId(group, GroupId, 'group'), enabled ? 1 : 0);
  }

  groupEnabled(group) {
    const e = [0];
    this.#call('embra_group_get_enabled', toId(group, GroupId, 'group'), e);
    return e[0] === 1;
  }

  // --- bodies -------------------------------------------------------------------------------------

  /**
   * Adds a body (embra_body_create) and returns its Body (id, first particle, count).
   *
   * positions: xyz per vertex (a Float64Array is used in place; flat or nested arrays are packed).
   * options: triangles, edges, tets (body-local vertex indices, flat or nested); masses (kg per
   * vertex); uvs (2 per vertex); generate (flags, a name or a list of names of GENERATE); material
   * (embra_material fields) and/or material fields directly (mass, stretch_compliance, ...);
   * stretch_group, shear_group, bend_group, volume_group (GroupId).
   */
  createBody(positions, opts) {
    const o = options(opts, 'createBody options');
    const d = lib.embra_default_body_def();
    const xyz = buf.doublesIn(positions, 'positions');
    if (xyz === null) throw new TypeError('positions: required');
    const n = xyzCount(xyz, 'positions');
    d.positions = xyz;
    d.vertex_count = n;
    const masses = buf.doublesIn(take(o, 'masses'), 'masses');
    if (masses !== null) {
      if (masses.length !== n) throw new RangeError(`masses: ${masses.length} values for ${n} vertices`);
      d.masses = masses;
    }
    const uvs = buf.doublesIn(take(o, 'uvs'), 'uvs');
    if (uvs !== null) {
      if (uvs.length !== 2 * n) throw new RangeError(`uvs: ${uvs.length} numbers for ${n} vertices (2 per vertex)`);
      d.uvs = uvs;
    }
    for (const [key, width, count] of [['triangles', 3, 'triangle_count'], ['edges', 2, 'edge_count'],
      ['tets', 4, 'tet_count']]) {
      const idx = buf.intsIn(take(o, key), key);
      if (idx !== null) {
        d[count] = buf.int32(wholeTuples(idx, width, key, 'indices'), `${key} count`);
        d[key] = idx;
      }
    }
    if (o.has('generate')) {
      const g = take(o, 'generate');
      d.generate = Array.isArray(g) ? g.reduce((flags, x, i) => flags | enumValue(x, GENERATE, `generate[${i}]`), 0)
        : enumValue(g, GENERATE, 'generate');
    }
    if (o.has('material')) fill(d.material, capi.Material, take(o, 'material'), 'Material');
    for (const key of ['stretch_group', 'shear_group', 'bend_group', 'volume_group']) {
      if (o.has(key)) d[key] = toId(take(o, key), GroupId, key);
    }
    fill(d.material, capi.Material, o, 'Material');
    const body = {};
    const first = [0];
    this.#call('embra_body_create', d, body, first);
    return new Body(new BodyId(body.index, body.generation), first[0], n);
  }

  /** {first, count} of a body's particles. */
  bodyParticles(body) {
    const first = [0];
    const count = [0];
    this.#call('embra_body_get_particles', toId(body, BodyId, 'body'), first, count);
    return { first: first[0], count: count[0] };
  }

  /** Scales the rest lengths of a body's generated stretch constraints (and volumes by scale^3). */
  /** The body's embra_material (embra_body_get_material). */
  material(body) {
    const m = {};
    this.#call('embra_body_get_material', toId(body, BodyId, 'body'), m);
    return m;
  }

  /**
   * Changes a body's material from the next step on, without a rebuild (embra_body_set_material): the
   * compliances of what it generated, its damping, thickness and friction. Starts from the body's material;
   * the given fields override it. Mass and density must stay the body's own.
   */
  setMaterial(body, fields) {
    const m = fill(this.material(body), capi.Material, fields, 'Material');
    this.#call('embra_body_set_material', toId(body, BodyId, 'body'), m);
  }

  /** The masses (kg) of a body's particles, one each, 0 = immovable (embra_body_get_masses): a Float64Array. */
  bodyMasses(body) {
    const b = toId(body, BodyId, 'body');
    const n = [0];
    this.#call('embra_body_get_masses', b, null, 0, n);
    const out = new Float64Array(n[0]);
    this.#call('embra_body_get_masses', b, out, out.length, n);
    return out;
  }

  /**
   * Sets the masses (kg) of a body's particles from the next step on, without a rebuild
   * (embra_body_set_masses): one per particle of the body, each 0 (immovable) or positive. A
   * hard-pinned particle keeps following its pin. Refused, changing nothing, for a wrong count or a
   * negative or non-finite mass.
   */
  setBodyMasses(body, masses) {
    const data = buf.doublesIn(masses, 'masses');
    if (data === null) throw new TypeError('masses: required');
    this.#call('embra_body_set_masses', toId(body, BodyId, 'body'), data, data.length);
  }

  setRestScale(body, scale = 1.0, scaleU = 1.0, scaleV = 1.0) {
    this.#call('embra_body_set_rest_scale', toId(body, BodyId, 'body'), buf.number(scale, 'scale'),
      buf.number(scaleU, 'scaleU'), buf.number(scaleV, 'scaleV'));
  }

  /** A body's triangles as world particle indices, 3 per triangle (an Int32Array). */
  bodyTriangles(body) {
    return this.#bodyInt32s('embra_body_get_triangles', body);
  }

  /** A body's int32 list read by `fn` (asked for its count first), as an Int32Array. */
  #bodyInt32s(fn, body) {
    const b = toId(body, BodyId, 'body');
    const n = [0];
    this.#call(fn, b, null, 0, n);
    const out = new Int32Array(n[0]);
    this.#call(fn, b, out, out.length, n);
    return out;
  }

  // --- panel meshes -------------------------------------------------------------------------------

  /**
   * Builds a Planar Offset Quad panel mesh (embra_panel_mesh_create) and returns its Body (8 particles
   * per panel welded, 2 per vertex shared). settings: positions and quads (the top quad mesh: xyz per
   * vertex, 4 indices per quad) or, without them, a grid of grid_columns x grid_rows panels of
   * panel_size at origin; pins (a PANEL_PINS name or number); corners (a PANEL_CORNERS name or
   * number); precision (a PANEL_PRECISION name, 'full' or 'single', or number); group; any other
   * embra_panel_mesh_def field (thickness, mass, ...).
   */
  createPanelMesh(settings) {
    const o = options(settings, 'createPanelMesh settings');
    const d = lib.embra_default_panel_mesh_def();
    const positions = take(o, 'positions');
    const quads = take(o, 'quads');
    if (o.has('pins')) d.pins = enumValue(take(o, 'pins'), PANEL_PINS, 'pins');
    if (o.has('corners')) d.corners = enumValue(take(o, 'corners'), PANEL_CORNERS, 'corners');
    if (o.has('precision')) d.precision = enumValue(take(o, 'precision'), PANEL_PRECISION, 'precision');
    for (const key of ['vertex_count', 'quad_count']) {
      if (o.has(key)) throw new TypeError(`createPanelMesh: ${key} is taken from positions and quads`);
    }
    fill(d, capi.PanelMeshDef, o, 'PanelMeshDef');
    if ((positions === undefined || positions === null) !== (quads === undefined || quads === null)) {
      throw new TypeError('createPanelMesh: positions and quads go together (neither: a grid)');
    }
    if (positions !== undefined && positions !== null) {
      const xyz = buf.doublesIn(positions, 'positions');
      const q = buf.intsIn(quads, 'quads');
      d.positions = xyz;
      d.vertex_count = xyzCount(xyz, 'positions');
      d.quads = q;
      d.quad_count = buf.int32(wholeTuples(q, 4, 'quads', 'indices'), 'quad count');
    }
    const body = {};
    const first = [0];
    this.#call('embra_panel_mesh_create', d, body, first);
    const id = new BodyId(body.index, body.generation);
    return new Body(id, first[0], this.bodyParticles(id).count);
  }

  /**
   * The world particle of each panel corner (embra_panel_mesh_get_corner_particles): an Int32Array of
   * 8 a panel, its top corners 0-3 then its bottom corners 0-3.
   */
  panelCornerParticles(body) {
    return this.#bodyInt32s('embra_panel_mesh_get_corner_particles', body);
  }

  /** The number of panels of a panel-mesh body. */
  panelCount(body) {
    const n = [0];
    this.#call('embra_panel_mesh_get_panel_count', toId(body, BodyId, 'body'), n);
    return n[0];
  }

  /** The fabrication tolerances the metrics are judged against (a copy). */
  get tolerances() {
    const t = {};
    this.#call('embra_world_get_tolerances', t);
    return t;
  }

  set tolerances(tolerances) {
    this.setTolerances(tolerances);
  }

  /** Replaces the tolerances: the current ones with the given fields changed ({miter: {target, max}}). */
  setTolerances(tolerances) {
    const t = fill(this.tolerances, capi.Tolerances, tolerances, 'Tolerances');
    this.#call('embra_world_set_tolerances', t);
  }

  /**
   * The section 4.1 metrics of a panel-mesh body at the current positions, judged against
   * `tolerances` (fields over the defaults) or, when omitted, the world's.
   */
  panelMetrics(body, tolerances = null) {
    const b = toId(body, BodyId, 'body');
    const t = tolerances === null || tolerances === undefined ? null
      : fill(lib.embra_default_tolerances(), capi.Tolerances, tolerances, 'Tolerances');
    const m = {};
    this.#call('embra_panel_mesh_get_metrics', b, t, m);
    return m;
  }

  /**
   * The welds' error of a panel-mesh body (a summary in model units): per mesh vertex of two or more
   * panels, the largest distance between two of its corner copies in one layer.
   */
  cornerGap(body) {
    const s = {};
    this.#call('embra_panel_mesh_get_corner_gap', toId(body, BodyId, 'body'), s);
    return s;
  }

  /**
   * One error value per particle of a panel-mesh body (8 per panel, in body order) for a colour map:
   * metric a PANEL_METRICS name or number. A new Float64Array, or `out` written in place (too small:
   * BufferTooSmallError, nothing written).
   */
  vertexErrors(body, metric, out = null) {
    const b = toId(body, BodyId, 'body');
    const m = enumValue(metric, PANEL_METRICS, 'metric');
    const n = [0];
    let result = out;
    if (out === null || out === undefined) {
      this.#call('embra_panel_mesh_get_vertex_errors', b, m, null, 0, n);
      result = new Float64Array(n[0]);
    } else {
      buf.doublesOut(0, out, 'out');
    }
    this.#call('embra_panel_mesh_get_vertex_errors', b, m, result, result.length, n);
    return result;
  }

  /** The cut list of a panel-mesh body at the current positions as text: format "json" or "csv". */
  exportCuts(body, format = 'json') {
    const b = toId(body, BodyId, 'body');
    const f = enumValue(format, CUTS_FORMATS, 'format');
    const n = [0];
    this.#call('embra_panel_mesh_export_cuts', b, f, null, 0, n);
    const out = Buffer.alloc(n[0]);
    this.#call('embra_panel_mesh_export_cuts', b, f, out, out.length, n);
    return out.toString('utf8', 0, n[0] - 1);
  }

  // --- constraints --------------------------------------------------------------------------------

  /**
   * One constraint (embra_constraint_add): kind a KINDS name or number, its particles (world indices),
   * options {rest (omitted: measured from the current positions), compliance (default 0), group}.
   */
  addConstraint(kind, particles, opts) {
    const o = options(opts, 'addConstraint options');
    const d = lib.embra_default_constraint_def();
    d.kind = enumValue(kind, KINDS, 'kind');
    const ids = Array.from(buf.intsIn(particles, 'particles') || []);
    const arity = lib.embra_constraint_arity(d.kind);
    if (arity && ids.length !== arity) {
      throw new RangeError(`particles: kind ${kind} takes ${arity} particles, got ${ids.length}`);
    }
    if (ids.length > 4) throw new RangeError(`particles: at most 4, got ${ids.length}`);
    while (ids.length < 4) ids.push(0);
    d.particles = ids;
    const rest = take(o, 'rest');
    if (rest !== undefined && rest !== null) {
      d.rest_from_current = 0;
      d.rest = buf.number(rest, 'rest');
    }
    if (o.has('compliance')) d.compliance = buf.number(take(o, 'compliance'), 'compliance');
    if (o.has('group')) d.group = toId(take(o, 'group'), GroupId, 'group');
    if (o.size) throw new TypeError(`addConstraint: unknown option '${o.keys().next().value}'`);
    this.#call('embra_constraint_add', d);
  }

  /**
   * Many constraints of one kind at once (embra_constraints_add), all or none; returns their count.
   * particles: arity indices per constraint (flat or nested); options {rest, compliances (one value
   * per constraint each), compliance (for all; default 0), group}.
   */
  addConstraints(kind, particles, opts) {
    const o = options(opts, 'addConstraints options');
    const d = lib.embra_default_constraint_batch_def();
    d.kind = enumValue(kind, KINDS, 'kind');
    const arity = lib.embra_constraint_arity(d.kind);
    const p = buf.intsIn(particles, 'particles');
    if (p === null) throw new TypeError('particles: required');
    const count = arity ? wholeTuples(p, arity, 'particles', 'indices') : p.length;
    d.count = buf.int32(count, 'count');
    d.particles = p;
    for (const key of ['rest', 'compliances']) {
      const values = buf.doublesIn(take(o, key), key);
      if (values !== null) {
        if (values.length !== count) throw new RangeError(`${key}: ${values.length} values for ${count} constraints`);
        d[key] = values;
      }
    }
    if (o.has('compliance')) d.compliance = buf.number(take(o, 'compliance'), 'compliance');
    if (o.has('group')) d.group = toId(take(o, 'group'), GroupId, 'group');
    if (o.size) throw new TypeError(`addConstraints: unknown option '${o.keys().next().value}'`);
    this.#call('embra_constraints_add', d);
    return count;
  }

  /**
   * Holds a polygon of four or more corners (particle indices in order round it) in one plane
   * (embra_polygon_planarity_add): planarity constraints of rest 0 on its windows of four consecutive
   * corners, all of them cyclically for more than four. options {compliance (default 0), group};
   * returns how many were added.
   */
  addPolygonPlanarity(particles, opts) {
    const o = options(opts, 'addPolygonPlanarity options');
    const p = buf.intsIn(particles, 'particles');
    if (p === null) throw new TypeError('particles: required');
    const compliance = o.has('compliance') ? buf.number(take(o, 'compliance'), 'compliance') : 0;
    const group = toId(o.has('group') ? take(o, 'group') : null, GroupId, 'group');
    if (o.size) throw new TypeError(`addPolygonPlanarity: unknown option '${o.keys().next().value}'`);
    const added = [0];
    this.#call('embra_polygon_planarity_add', group, p, buf.int32(p.length, 'count'), compliance, added);
    return added[0];
  }

  /**
   * Keeps three or more points (particle indices) in their current shape, moving as one rigid body
   * (embra_rigid_set_add): bracing by distance constraints to a base of three or four of them, with the
   * base's volume (solid) or each point's offset from its plane (flat). options {compliance (default
   * 0), group}; returns how many constraints were added (4 n - 9).
   */
  addRigidSet(particles, opts) {
    const o = options(opts, 'addRigidSet options');
    const p = buf.intsIn(particles, 'particles');
    if (p === null) throw new TypeError('particles: required');
    const compliance = o.has('compliance') ? buf.number(take(o, 'compliance'), 'compliance') : 0;
    const group = toId(o.has('group') ? take(o, 'group') : null, GroupId, 'group');
    if (o.size) throw new TypeError(`addRigidSet: unknown option '${o.keys().next().value}'`);
    const added = [0];
    this.#call('embra_rigid_set_add', group, p, buf.int32(p.length, 'count'), compliance, added);
    return added[0];
  }

  /**
   * Shape matching (embra_shape_match_add): three or more points (particle indices), not on one line,
   * pulled every projection toward the best-fit rigid placement (mass-weighted, proper rotation) of their
   * current shape. options {compliance (m/N, default 0 = hard), group}; returns its index among the
   * group's shape matches.
   */
  addShapeMatch(particles, opts) {
    const o = options(opts, 'addShapeMatch options');
    const p = buf.intsIn(particles, 'particles');
    if (p === null) throw new TypeError('particles: required');
    const compliance = o.has('compliance') ? buf.number(take(o, 'compliance'), 'compliance') : 0;
    const group = toId(o.has('group') ? take(o, 'group') : null, GroupId, 'group');
    if (o.size) throw new TypeError(`addShapeMatch: unknown option '${o.keys().next().value}'`);
    const index = [0];
    this.#call('embra_shape_match_add', group, p, buf.int32(p.length, 'count'), compliance, index);
    return index[0];
  }

  /** Removes shape match `index` of `group` (null: the default group); later ones move down. */
  removeShapeMatch(index, group = null) {
    this.#call('embra_shape_match_remove', toId(group, GroupId, 'group'), buf.int32(index, 'index'));
  }

  /** How many shape matches `group` (null: the default group) holds. */
  shapeMatchCount(group = null) {
    const count = [0];
    this.#call('embra_group_get_shape_match_count', toId(group, GroupId, 'group'), count);
    return count[0];
  }

  // Edits of one constraint, named as the diagnostics name it: group (null: the default group), kind and
  // index among the group's constraints of that kind (those bodies generated first, then the added ones in
  // the order added). Only added constraints are edited; a body's follow its material (setMaterial).

  /** {count, generated}: the group's constraints of `kind` and how many of them bodies generated. */
  constraintCount(group, kind) {
    const n = [0];
    const g = [0];
    this.#call('embra_group_get_constraint_count', toId(group, GroupId, 'group'), enumValue(kind, KINDS, 'kind'), n, g);
    return { count: n[0], generated: g[0] };
  }

  /** One constraint: {kind, group, particles (its arity), rest, compliance}. */
  constraint(group, kind, index) {
    const d = {};
    this.#call('embra_constraint_get', toId(group, GroupId, 'group'), enumValue(kind, KINDS, 'kind'),
      buf.int32(index, 'index'), d);
    return {
      kind: d.kind,
      group: new GroupId(d.group.index, d.group.generation),
      particles: d.particles.slice(0, lib.embra_constraint_arity(d.kind)),
      rest: d.rest,
      compliance: d.compliance,
    };
  }

  setConstraintCompliance(group, kind, index, compliance) {
    this.#call('embra_constraint_set_compliance', toId(group, GroupId, 'group'), enumValue(kind, KINDS, 'kind'),
      buf.int32(index, 'index'), buf.number(compliance, 'compliance'));
  }

  setConstraintRest(group, kind, index, rest) {
    this.#call('embra_constraint_set_rest', toId(group, GroupId, 'group'), enumValue(kind, KINDS, 'kind'),
      buf.int32(index, 'index'), buf.number(rest, 'rest'));
  }

  /**
   * Plasticity and rupture of an added distance or dihedral (embra_constraint_set_plasticity): past
   * `yieldStrain` its rest follows it, past `rupture` it breaks (see broken()); 0: never.
   */
  setConstraintPlasticity(group, kind, index, yieldStrain, rupture) {
    this.#call('embra_constraint_set_plasticity', toId(group, GroupId, 'group'), enumValue(kind, KINDS, 'kind'),
      buf.int32(index, 'index'), buf.number(yieldStrain, 'yield'), buf.number(rupture, 'rupture'));
  }

  /** {yield, rupture} of a constraint (embra_constraint_get_plasticity); 0 is none. */
  constraintPlasticity(group, kind, index) {
    const y = [0];
    const r = [0];
    this.#call('embra_constraint_get_plasticity', toId(group, GroupId, 'group'), enumValue(kind, KINDS, 'kind'),
      buf.int32(index, 'index'), y, r);
    return { yield: y[0], rupture: r[0] };
  }

  /**
   * The constraints broken since the last call (embra_world_get_broken), in the order they broke:
   * [{group (GroupId), kind (name), index, particles, frame, strain}]; the world's list is emptied.
   */
  broken() {
    const { koffi } = capi;
    const n = [0];
    this.#call('embra_world_get_broken', null, 0, n);
    const size = koffi.sizeof(capi.BrokenConstraint);
    const capacity = Math.max(n[0], 1);
    const out = Buffer.alloc(capacity * size);
    this.#call('embra_world_get_broken', out, capacity, n);
    const names = Object.fromEntries(Object.entries(KINDS).map(([k, v]) => [v, k]));
    const result = [];
    for (let k = 0; k < n[0]; k++) {
      const b = koffi.decode(out, k * size, capi.BrokenConstraint);
      result.push({
        group: new GroupId(b.group.index, b.group.generation), kind: names[b.kind] ?? b.kind, index: b.index,
        particles: Array.from(b.particles).filter((p) => p >= 0), frame: Number(b.frame), strain: b.strain,
      });
    }
    return result;
  }

  /** Moves the constraint to the end of group `to`'s; returns its index there. */
  setConstraintGroup(group, kind, index, to) {
    const at = [0];
    this.#call('embra_constraint_set_group', toId(group, GroupId, 'group'), enumValue(kind, KINDS, 'kind'),
      buf.int32(index, 'index'), toId(to, GroupId, 'to'), at);
    return at[0];
  }

  /** Removes the constraint; those after it in its group move down by one. */
  removeConstraint(group, kind, index) {
    this.#call('embra_constraint_remove', toId(group, GroupId, 'group'), enumValue(kind, KINDS, 'kind'),
      buf.int32(index, 'index'));
  }

  // --- pins ---------------------------------------------------------------------------------------

  /** Holds `particle` at `target` (m); options {compliance: 0 = hard, > 0 (m/N) a soft pin in `group`}. */
  createPin(particle, target, opts) {
    const o = options(opts, 'createPin options');
    const d = lib.embra_default_pin_def();
    d.particle = buf.int32(particle, 'particle');
    d.target = buf.fixed(target, 3, 'target');
    if (o.has('compliance')) d.compliance = buf.number(take(o, 'compliance'), 'compliance');
    if (o.has('group')) d.group = toId(take(o, 'group'), GroupId, 'group');
    if (o.size) throw new TypeError(`createPin: unknown option '${o.keys().next().value}'`);
    const pin = {};
    this.#call('embra_pin_create', d, pin);
    return new PinId(pin.index, pin.generation);
  }

  /**
   * A frictionless sliding support (embra_support_create): `particle` held on the plane through
   * `target` (m) normal to `axis` (support 'plane', the default) or on the line through it along
   * `axis` ('line'); or a per-axis anchor ('axes', a roller): the world coordinates whose `axis`
   * component is 1 held at the target's, those with 0 free ([0, 0, 1]: z held). Options: support,
   * axis (default [0, 0, 1]), compliance (0 hard, else m/N), group.
   * Returns its PinId.
   */
  createSupport(particle, target, opts) {
    const o = options(opts, 'createSupport options');
    const d = lib.embra_default_support_def();
    d.particle = buf.int32(particle, 'particle');
    d.target = buf.fixed(target, 3, 'target');
    if (o.has('support')) d.support = enumValue(take(o, 'support'), PIN_SUPPORTS, 'support');
    if (o.has('axis')) d.axis = buf.fixed(take(o, 'axis'), 3, 'axis');
    if (o.has('compliance')) d.compliance = buf.number(take(o, 'compliance'), 'compliance');
    if (o.has('group')) d.group = toId(take(o, 'group'), GroupId, 'group');
    if (o.size) throw new TypeError(`createSupport: unknown option '${o.keys().next().value}'`);
    const pin = {};
    this.#call('embra_support_create', d, pin);
    return new PinId(pin.index, pin.generation);
  }

  /**
   * A frictionless support on a polyline (embra_polyline_support_create): `particle` held on the
   * closest point of the polyline through `points` (xyz per point, m, offsets from the target, so
   * setPinTarget moves the curve). Options: target (default [0, 0, 0]), closed (true joins its ends),
   * compliance (0 hard, else m/N), group. Returns its PinId.
   */
  createPolylineSupport(particle, points, opts) {
    const o = options(opts, 'createPolylineSupport options');
    const d = lib.embra_default_polyline_support_def();
    d.particle = buf.int32(particle, 'particle');
    const xyz = buf.doublesIn(points, 'points');
    if (xyz === null) throw new TypeError('points: required');
    d.points = xyz;
    d.point_count = xyzCount(xyz, 'points');
    if (o.has('target')) d.target = buf.fixed(take(o, 'target'), 3, 'target');
    if (o.has('closed')) {
      const closed = take(o, 'closed');
      if (typeof closed !== 'boolean') throw new TypeError(`closed: expected true or false, got ${buf.describe(closed)}`);
      d.closed = closed ? 1 : 0;
    }
    if (o.has('compliance')) d.compliance = buf.number(take(o, 'compliance'), 'compliance');
    if (o.has('group')) d.group = toId(take(o, 'group'), GroupId, 'group');
    if (o.size) throw new TypeError(`createPolylineSupport: unknown option '${o.keys().next().value}'`);
    const pin = {};
    this.#call('embra_polyline_support_create', d, pin);
    return new PinId(pin.index, pin.generation);
  }

  /**
   * A frictionless support on a triangle mesh (embra_mesh_support_create): `particle` held on the
   * closest point of the mesh (`vertices`: xyz per vertex, m, offsets from the target, so
   * setPinTarget moves the mesh; `triangles`: three 0-based indices each). Options: target
   * (default [0, 0, 0]), compliance (0 hard, else m/N), group. Returns its PinId.
   */
  createMeshSupport(particle, vertices, triangles, opts) {
    const o = options(opts, 'createMeshSupport options');
    const d = lib.embra_default_mesh_support_def();
    d.particle = buf.int32(particle, 'particle');
    const xyz = buf.doublesIn(vertices, 'vertices');
    if (xyz === null) throw new TypeError('vertices: required');
    d.vertices = xyz;
    d.vertex_count = xyzCount(xyz, 'vertices');
    const tri = buf.intsIn(triangles, 'triangles');
    if (tri === null) throw new TypeError('triangles: required');
    if (tri.length % 3) throw new TypeError(`triangles: ${tri.length} indices is not a whole number of triangles`);
    d.triangles = tri;
    d.triangle_count = tri.length / 3;
    if (o.has('target')) d.target = buf.fixed(take(o, 'target'), 3, 'target');
    if (o.has('compliance')) d.compliance = buf.number(take(o, 'compliance'), 'compliance');
    if (o.has('group')) d.group = toId(take(o, 'group'), GroupId, 'group');
    if (o.size) throw new TypeError(`createMeshSupport: unknown option '${o.keys().next().value}'`);
    const pin = {};
    this.#call('embra_mesh_support_create', d, pin);
    return new PinId(pin.index, pin.generation);
  }

  /**
   * A polyline support's points as created (embra_polyline_support_get_points): an array of
   * [x, y, z] offsets from its target (m); setPinTarget moves the target, not these, so the curve's
   * world points are pinTarget(pin) plus each. Refused for a pin that is not one.
   */
  polylineSupportPoints(pin) {
    const p = toId(pin, PinId, 'pin');
    const n = [0];
    this.#call('embra_polyline_support_get_points', p, null, 0, n);
    const out = new Float64Array(3 * n[0]);
    this.#call('embra_polyline_support_get_points', p, out, n[0], n);
    const result = [];
    for (let k = 0; k < n[0]; k++) result.push([out[3 * k], out[3 * k + 1], out[3 * k + 2]]);
    return result;
  }

  destroyPin(pin) {
    this.#call('embra_pin_destroy', toId(pin, PinId, 'pin'));
  }

  /** Moves a pin's target (m); a hard-pinned particle travels there over the next step's substeps. */
  setPinTarget(pin, target) {
    this.#call('embra_pin_set_target', toId(pin, PinId, 'pin'), Float64Array.from(buf.fixed(target, 3, 'target')));
  }

  /** A pin's target [x, y, z] (m). */
  pinTarget(pin) {
    const out = new Float64Array(3);
    this.#call('embra_pin_get_target', toId(pin, PinId, 'pin'), out);
    return Array.from(out);
  }

  /** The particle a pin holds. */
  pinParticle(pin) {
    const p = [0];
    this.#call('embra_pin_get_particle', toId(pin, PinId, 'pin'), p);
    return p[0];
  }

  // --- colliders ----------------------------------------------------------------------------------

  /**
   * A collider: shape a SHAPES name or number; settings: embra_collider_def fields (position,
   * rotation {w, x, y, z}, radius, thickness, friction_static, friction_dynamic, half_extents,
   * half_length) and, for convex and mesh shapes, vertices (local xyz) and triangles.
   */
  createCollider(shape, settings) {
    const o = options(settings, 'createCollider settings');
    const d = lib.embra_default_collider_def();
    d.shape = enumValue(shape, SHAPES, 'shape');
    const vertices = buf.doublesIn(take(o, 'vertices'), 'vertices');
    const triangles = buf.intsIn(take(o, 'triangles'), 'triangles');
    for (const key of ['vertex_count', 'triangle_count']) {
      if (o.has(key)) throw new TypeError(`createCollider: ${key} is taken from vertices and triangles`);
    }
    fill(d, capi.ColliderDef, o, 'ColliderDef');
    if (vertices !== null) {
      d.vertex_count = xyzCount(vertices, 'vertices');
      d.vertices = vertices;
    }
    if (triangles !== null) {
      d.triangle_count = buf.int32(wholeTuples(triangles, 3, 'triangles', 'indices'), 'triangle count');
      d.triangles = triangles;
    }
    const c = {};
    this.#call('embra_collider_create', d, c);
    return new ColliderId(c.index, c.generation);
  }

  destroyCollider(collider) {
    this.#call('embra_collider_destroy', toId(collider, ColliderId, 'collider'));
  }

  /** Where the collider is at the end of the next step: position (m), rotation {w, x, y, z}. */
  setColliderTransform(collider, position, rotation = [1.0, 0.0, 0.0, 0.0]) {
    this.#call('embra_collider_set_transform', toId(collider, ColliderId, 'collider'),
      Float64Array.from(buf.fixed(position, 3, 'position')), Float64Array.from(buf.fixed(rotation, 4, 'rotation')));
  }

  /** Where the collider is now: {position: [x, y, z] (m), rotation: [w, x, y, z]}. */
  colliderTransform(collider) {
    const position = new Float64Array(3);
    const rotation = new Float64Array(4);
    this.#call('embra_collider_get_transform', toId(collider, ColliderId, 'collider'), position, rotation);
    return { position: Array.from(position), rotation: Array.from(rotation) };
  }

  // --- fields -------------------------------------------------------------------------------------

  #createField(def, type, create, what, fields) {
    fill(def, type, fields, what);
    const f = {};
    this.#call(create, def, f);
    return new FieldId(f.index, f.generation);
  }

  /** A wind field: embra_wind_def fields (body: a Body or BodyId, omitted = every body; direction, speed, ...). */
  createWind(fields) {
    return this.#createField(lib.embra_default_wind_def(), capi.WindDef, 'embra_wind_create', 'WindDef', fields);
  }

  /** Air pressure on a closed body (required: body): embra_pressure_def fields. */
  createPressure(fields) {
    return this.#createField(lib.embra_default_pressure_def(), capi.PressureDef, 'embra_pressure_create',
      'PressureDef', fields);
  }

  /** A soap-film tension on a body's triangles (required: body; tension, regularisation). */
  createSurfaceTension(fields) {
    return this.#createField(lib.embra_default_surface_tension_def(), capi.SurfaceTensionDef,
      'embra_surface_tension_create', 'SurfaceTensionDef', fields);
  }

  /** A decaying torsion field about an axis: embra_vortex_def fields (body, center, axis, strength, ...). */
  createVortex(fields) {
    return this.#createField(lib.embra_default_vortex_def(), capi.VortexDef, 'embra_vortex_create', 'VortexDef',
      fields);
  }

  #field(get, field) {
    const d = {};
    this.#call(get, toId(field, FieldId, 'field'), d);
    return d;
  }

  #setField(get, set, type, what, field, fields) {
    const d = fill(this.#field(get, field), type, fields, what); // the field's parameters, those given changed
    this.#call(set, toId(field, FieldId, 'field'), d);
  }

  /** A wind field's embra_wind_def (embra_wind_get). */
  wind(field) {
    return wrapIds(this.#field('embra_wind_get', field), capi.WindDef);
  }

  /** Changes the given embra_wind_def fields of a wind field from the next step on (embra_wind_set). */
  setWind(field, fields) {
    this.#setField('embra_wind_get', 'embra_wind_set', capi.WindDef, 'WindDef', field, fields);
  }

  pressure(field) {
    return wrapIds(this.#field('embra_pressure_get', field), capi.PressureDef);
  }

  setPressure(field, fields) {
    this.#setField('embra_pressure_get', 'embra_pressure_set', capi.PressureDef, 'PressureDef', field, fields);
  }

  surfaceTension(field) {
    return wrapIds(this.#field('embra_surface_tension_get', field), capi.SurfaceTensionDef);
  }

  setSurfaceTension(field, fields) {
    this.#setField('embra_surface_tension_get', 'embra_surface_tension_set', capi.SurfaceTensionDef,
      'SurfaceTensionDef', field, fields);
  }

  vortex(field) {
    return wrapIds(this.#field('embra_vortex_get', field), capi.VortexDef);
  }

  setVortex(field, fields) {
    this.#setField('embra_vortex_get', 'embra_vortex_set', capi.VortexDef, 'VortexDef', field, fields);
  }

  /** Destroys a field; its id becomes stale. */
  destroyField(field) {
    this.#call('embra_field_destroy', toId(field, FieldId, 'field'));
  }

  /** Number of live fields. */
  get fieldCount() {
    const n = [0];
    this.#call('embra_world_get_field_count', n);
    return n[0];
  }

  // --- stepping and reading back ------------------------------------------------------------------

  /**
   * Advances `frames` frames on this thread. NumericalError: the world is as before the failing frame (the
   * frames before it stay stepped).
   */
  step(frames = 1) {
    buf.int32(frames, 'frames');
    if (frames < 0) throw new RangeError(`frames: ${frames} is negative`);
    for (let i = 0; i < frames; i++) this.#call('embra_world_step');
  }

  /**
   * Advances `frames` frames on koffi's worker threads, one embra_world_step at a time; the promise
   * resolves when the last returns. While a frame runs, cancel() stops it (CancelledError) and every other
   * call on this World throws LockedError. A frame that fails rejects the promise with the error of its
   * status (NumericalError, CancelledError, ...): the world is as before that frame. The C message stays
   * on the worker thread, so the error's message is composed here. A frame that found the world in use
   * by a call made on the JS thread at that instant did not run and is dispatched again. stepAsync calls
   * made while one runs wait for it.
   */
  stepAsync(frames = 1) {
    buf.int32(frames, 'frames');
    if (frames < 0) throw new RangeError(`frames: ${frames} is negative`);
    const run = this.#queue.then(async () => {
      for (let i = 0; i < frames; i++) await this.#stepOnWorker();
    });
    this.#queue = run.catch(() => {});
    return run;
  }

  #stepOnWorker() {
    return new Promise((resolve, reject) => {
      const ptr = this.#ptr;
      if (ptr === null) {
        try {
          this.#call('embra_world_step'); // C refuses the NULL world with its message
        } catch (e) {
          reject(e);
        }
        return;
      }
      this.#inFlight = true;
      lib.embra_world_step.async(ptr, (failure, status) => {
        this.#inFlight = false;
        const closed = this.#destroyWhenReturned !== null;
        if (closed) {
          lib.embra_world_destroy(this.#destroyWhenReturned);
          this.#destroyWhenReturned = null;
        }
        if (failure) reject(failure);
        else if (status === capi.OK) resolve();
        // the JS thread was inside a call on this World just then (the frame did not run): again
        else if (status === capi.ERROR_LOCKED && !closed) this.#stepOnWorker().then(resolve, reject);
        else reject(this.#workerError(status, closed));
      });
    });
  }

  /** The error of a frame that failed on a worker thread (whose C message stays on that thread). */
  #workerError(status, closed) {
    let text = `embra_world_step (on a worker thread): ${lib.embra_status_name(status)}`;
    if (status === capi.ERROR_CANCELLED) text += ' by World.cancel()';
    if (status === capi.ERROR_NUMERICAL && !closed) {
      const w = this.warning();
      text += ` at particle ${w.particle} in frame ${w.frame} (World.warning())`;
    }
    if (status === capi.ERROR_CANCELLED || status === capi.ERROR_NUMERICAL) text += '; the world is as before the frame';
    if (closed) text += '; the World was closed meanwhile';
    return errorFor(status, text);
  }

  /** The report of the last step: {frame, time, kinetic_energy, max_speed, residual_max, ...}. */
  /**
   * Steps until the world is at rest (until 'settled') and, with until 'tolerance' (the default), every
   * panel mesh within its tolerance targets, or maxFrames frames (1000) or maxSeconds of wall time (0:
   * none) have passed; holdFrames (10) frames in a row at rest count as settled (embra_world_solve).
   * Returns why it stopped: {outcome: 'settled_within_tolerance' | 'settled_out_of_tolerance' |
   * 'oscillating' | 'drifting', settled, frames, period (s, of an oscillation, else 0), worst: null
   * without a panel mesh, else the metric furthest above its target, {metric (a PANEL_METRICS name),
   * body (BodyId), element (panel, or joint for 'miter'), layer ('top', 'bottom' or null), value,
   * target}}.
   */
  solve(opts = {}) {
    const given = options(opts, 'solve options');
    const def = lib.embra_default_solve_def();
    if (given.has('until')) {
      def.until = enumValue(given.get('until'), SOLVE_UNTIL, 'until');
      given.delete('until');
    }
    fill(def, capi.SolveDef, given, 'SolveDef');
    const r = {};
    this.#call('embra_world_solve', def, r);
    const out = {
      outcome: SOLVE_OUTCOMES[r.outcome], settled: r.outcome <= capi.SOLVE_SETTLED_OUT_OF_TOLERANCE,
      frames: r.frames, period: r.period, worst: null,
    };
    if (r.worst_metric === capi.SOLVE_WORST_RESIDUAL) {
      // A kind's constraint residual above its target (embra.h EMBRA_SOLVE_RESIDUAL_TARGET_*).
      out.worst = {
        metric: 'residual', kind: lib.embra_residual_name(r.worst_element),
        unit: lib.embra_residual_unit(r.worst_element), value: r.worst_value, target: r.worst_target,
      };
    } else if (r.worst_metric >= 0) {
      out.worst = {
        metric: METRIC_NAMES[r.worst_metric], body: new BodyId(r.worst_body.index, r.worst_body.generation),
        element: r.worst_element, layer: r.worst_layer === 0 ? 'top' : r.worst_layer === 1 ? 'bottom' : null,
        value: r.worst_value, target: r.worst_target,
      };
    }
    return out;
  }

  /**
   * The last step's residuals by kind, each in its own unit (embra_world_get_residuals): an object from
   * the kind's name ('distance', 'dihedral', ..., 'pins', 'contacts') to {unit ('m', 'rad', 'm^3'),
   * count, max, rms}, for every kind the world holds, in kind order.
   */
  residuals() {
    const n = [0];
    this.#call('embra_world_get_residuals', null, 0, n);
    const { koffi } = capi;
    const size = koffi.sizeof(capi.KindResidual);
    const out = Buffer.alloc(Math.max(n[0], 1) * size);
    this.#call('embra_world_get_residuals', out, n[0], n);
    const result = {};
    for (let k = 0; k < n[0]; k++) {
      const r = koffi.decode(out, k * size, capi.KindResidual);
      result[lib.embra_residual_name(r.kind)] = {
        unit: lib.embra_residual_unit(r.kind), count: Number(r.count), max: r.max, rms: r.rms,
      };
    }
    return result;
  }

  /**
   * The `count` (10) constraints and soft pins of the last step that fight hardest, worst first
   * (embra_world_get_worst_constraints: ranked by violation x force, an energy for every kind): [{kind
   * (a KINDS name, or 'pins'), group, index (in the group's constraints of that kind, as added; -1 for
   * a pin), pin (PinId or null), particles, residual and violation (in unit), unit, force (N; N m for
   * angles, N/m^2 for volumes)}].
   */
  worstConstraints(count = 10) {
    buf.int32(count, 'count');
    const { koffi } = capi;
    const size = koffi.sizeof(capi.ConstraintResidual);
    const out = Buffer.alloc(Math.max(count, 1) * size);
    const n = [0];
    this.#call('embra_world_get_worst_constraints', out, count, n);
    const result = [];
    for (let k = 0; k < n[0]; k++) {
      const c = koffi.decode(out, k * size, capi.ConstraintResidual);
      const pin = c.kind === capi.RESIDUAL_PINS;
      const arity = pin ? 1 : lib.embra_constraint_arity(c.kind);
      result.push({
        kind: lib.embra_residual_name(c.kind), group: new GroupId(c.group.index, c.group.generation), index: c.index,
        pin: pin ? new PinId(c.pin.index, c.pin.generation) : null, particles: Array.from(c.particles).slice(0, arity),
        residual: c.residual, violation: c.violation, unit: lib.embra_residual_unit(c.kind), force: c.force,
      });
    }
    return result;
  }

  /**
   * Pairs of groups whose forces on shared particles oppose in the last step, largest first
   * (embra_world_get_group_conflicts): [{a, b (GroupIds, a first in the projection order), force (N),
   * particles (where they point more than 120 degrees apart)}].
   */
  groupConflicts() {
    const { koffi } = capi;
    const n = [0];
    this.#call('embra_world_get_group_conflicts', null, 0, n);
    const size = koffi.sizeof(capi.GroupConflict);
    const out = Buffer.alloc(Math.max(n[0], 1) * size);
    this.#call('embra_world_get_group_conflicts', out, n[0], n);
    const result = [];
    for (let k = 0; k < n[0]; k++) {
      const c = koffi.decode(out, k * size, capi.GroupConflict);
      result.push({
        a: new GroupId(c.a.index, c.a.generation), b: new GroupId(c.b.index, c.b.generation), force: c.force,
        particles: Number(c.particles),
      });
    }
    return result;
  }

  /**
   * The residual of every constraint of `kind` in `group` after the last step, in the order they were
   * added, in the kind's unit (embra_group_get_residuals): a Float64Array.
   */
  groupResiduals(group, kind) {
    return this.#perConstraint('embra_group_get_residuals', group, kind);
  }

  /**
   * The force of every constraint of `kind` in `group` after the last step, in the order they were
   * added (embra_group_get_forces): -lambda / h^2 of the last substep; for a distance or tether its
   * tension in N (positive pulling its ends together). A Float64Array.
   */
  constraintForces(group, kind) {
    return this.#perConstraint('embra_group_get_forces', group, kind);
  }

  /** One value per constraint of `kind` in `group`, through a two-call listing: a Float64Array. */
  #perConstraint(name, group, kind) {
    if (!(group instanceof GroupId)) throw new TypeError(`group: expected a GroupId, got ${buf.describe(group)}`);
    const k = enumValue(kind, KINDS, 'kind');
    const n = [0];
    this.#call(name, group, k, null, 0, n);
    const out = new Float64Array(Number(n[0]));
    this.#call(name, group, k, out, out.length, n);
    return out;
  }

  /**
   * The force (N) every live pin exerts on its particle after the last step
   * (embra_world_get_reactions): [{pin (PinId), particle, force ([x, y, z])}], pins in creation-slot
   * order. At a static rest they sum to minus the weights and point loads.
   */
  reactions() {
    const { koffi } = capi;
    const n = [0];
    this.#call('embra_world_get_reactions', null, 0, n);
    const size = koffi.sizeof(capi.Reaction);
    const out = Buffer.alloc(Math.max(n[0], 1) * size);
    this.#call('embra_world_get_reactions', out, n[0], n);
    const result = [];
    for (let k = 0; k < n[0]; k++) {
      const r = koffi.decode(out, k * size, capi.Reaction);
      result.push({ pin: new PinId(r.pin.index, r.pin.generation), particle: r.particle, force: Array.from(r.force) });
    }
    return result;
  }

  /**
   * The force (N) every live collider exerts on the world after the last step, from its contacts of
   * the last substep, normal push and friction (embra_world_get_collider_reactions):
   * [{collider (ColliderId), contacts, force ([x, y, z], N), moment ([x, y, z], N m about the
   * collider's position)}], colliders in creation-slot order. At a static rest they and the pins'
   * reactions sum to minus the weights and loads.
   */
  colliderReactions() {
    const { koffi } = capi;
    const n = [0];
    this.#call('embra_world_get_collider_reactions', null, 0, n);
    const size = koffi.sizeof(capi.ColliderReaction);
    const out = Buffer.alloc(Math.max(n[0], 1) * size);
    this.#call('embra_world_get_collider_reactions', out, n[0], n);
    const result = [];
    for (let k = 0; k < n[0]; k++) {
      const r = koffi.decode(out, k * size, capi.ColliderReaction);
      result.push({
        collider: new ColliderId(r.collider.index, r.collider.generation),
        contacts: Number(r.contacts),
        force: Array.from(r.force),
        moment: Array.from(r.moment),
      });
    }
    return result;
  }

  report() {
    const r = {};
    this.#call('embra_world_get_report', r);
    return r;
  }

  /** The last numerical failure: {frame, particle} (-1 if none). */
  warning() {
    const w = {};
    this.#call('embra_world_get_warning', w);
    return w;
  }

  #read(name, first, count, out) {
    buf.int32(first, 'first');
    let n = count;
    if (n === null || n === undefined) n = Math.max(this.particleCount - first, 0);
    buf.int32(n, 'count');
    const result = buf.doublesOut(3 * Math.max(n, 0), out, 'out');
    this.#call(name, result, result.length, first, n);
    return result;
  }

  /**
   * Positions (m) of particles [first, first + count) (count omitted: to the last particle), flat xyz:
   * a new Float64Array, or `out` written in place (too small: BufferTooSmallError, nothing written).
   */
  positions(first = 0, count = null, out = null) {
    return this.#read('embra_world_get_positions', first, count, out);
  }

  /** Velocities (m/s), as positions(). */
  velocities(first = 0, count = null, out = null) {
    return this.#read('embra_world_get_velocities', first, count, out);
  }

  #write(name, xyz, first) {
    const data = buf.doublesIn(xyz, 'xyz');
    if (data === null) throw new TypeError('xyz: required');
    const n = xyzCount(data, 'xyz');
    this.#call(name, data, buf.int32(first, 'first'), n);
  }

  /** Moves particles [first, first + xyz.length / 3) to xyz (m); velocities are kept. */
  setPositions(xyz, first = 0) {
    this.#write('embra_world_set_positions', xyz, first);
  }

  /** Sets particles' velocities (m/s), as setPositions. */
  setVelocities(xyz, first = 0) {
    this.#write('embra_world_set_velocities', xyz, first);
  }

  /** Point loads (N) of particles [first, first + count), as positions(). */
  loads(first = 0, count = null, out = null) {
    return this.#read('embra_world_get_loads', first, count, out);
  }

  /**
   * Sets point loads (N, flat xyz per particle) on particles [first, first + xyz.length / 3): forces
   * applied every substep beside gravity until set again.
   */
  setLoads(xyz, first = 0) {
    this.#write('embra_world_set_loads', xyz, first);
  }

  /**
   * Replaces the area loads (embra_world_set_area_loads) with `loads`, an array of
   * {particles: [a, b, c] (three distinct particles), pressure (Pa), mode ('normal', 'true_area' or
   * 'projected_area'; default 'normal'), direction ([x, y, z], the fixed modes')}: a third of each
   * triangle's force on each corner, every substep beside gravity, until set again. [] removes them.
   */
  setAreaLoads(loads) {
    const { koffi } = capi;
    if (!Array.isArray(loads)) throw new TypeError(`loads: expected an array, got ${buf.describe(loads)}`);
    const size = koffi.sizeof(capi.AreaLoad);
    const out = Buffer.alloc(Math.max(loads.length, 1) * size);
    loads.forEach((l, i) => {
      const o = options(l, `loads[${i}]`);
      const d = {
        particles: buf.fixed(take(o, 'particles'), 3, `loads[${i}].particles`).map((c) => buf.int32(c, `loads[${i}].particles`)),
        mode: o.has('mode') ? enumValue(take(o, 'mode'), AREA_LOAD_MODES, `loads[${i}].mode`) : AREA_LOAD_MODES.normal,
        pressure: buf.number(take(o, 'pressure'), `loads[${i}].pressure`),
        direction: o.has('direction') ? buf.fixed(take(o, 'direction'), 3, `loads[${i}].direction`) : [0, 0, -1],
      };
      if (o.size) throw new TypeError(`loads[${i}]: unknown key '${o.keys().next().value}'`);
      koffi.encode(out, i * size, capi.AreaLoad, d);
    });
    this.#call('embra_world_set_area_loads', out, loads.length);
  }

  /** The area loads as set: [{particles, mode (name), pressure, direction}]. */
  areaLoads() {
    const { koffi } = capi;
    const n = [0];
    this.#call('embra_world_get_area_loads', null, 0, n);
    const size = koffi.sizeof(capi.AreaLoad);
    const out = Buffer.alloc(Math.max(n[0], 1) * size);
    this.#call('embra_world_get_area_loads', out, n[0], n);
    const result = [];
    for (let k = 0; k < n[0]; k++) {
      const l = koffi.decode(out, k * size, capi.AreaLoad);
      result.push({ particles: Array.from(l.particles), mode: AREA_LOAD_MODE_NAMES[l.mode] ?? l.mode,
        pressure: l.pressure, direction: Array.from(l.direction) });
    }
    return result;
  }

  /**
   * Replaces the line loads (embra_world_set_line_loads) with `loads`, an array of
   * {particles: [a, b] (two distinct particles), load ([x, y, z], N per m of the edge)}: half of each
   * edge's force on each end, every substep beside gravity, until set again.
   */
  setLineLoads(loads) {
    const { koffi } = capi;
    if (!Array.isArray(loads)) throw new TypeError(`loads: expected an array, got ${buf.describe(loads)}`);
    const size = koffi.sizeof(capi.LineLoad);
    const out = Buffer.alloc(Math.max(loads.length, 1) * size);
    loads.forEach((l, i) => {
      const o = options(l, `loads[${i}]`);
      const d = {
        particles: buf.fixed(take(o, 'particles'), 2, `loads[${i}].particles`).map((c) => buf.int32(c, `loads[${i}].particles`)),
        load: buf.fixed(take(o, 'load'), 3, `loads[${i}].load`),
      };
      if (o.size) throw new TypeError(`loads[${i}]: unknown key '${o.keys().next().value}'`);
      koffi.encode(out, i * size, capi.LineLoad, d);
    });
    this.#call('embra_world_set_line_loads', out, loads.length);
  }

  /** The line loads as set: [{particles, load}]. */
  lineLoads() {
    const { koffi } = capi;
    const n = [0];
    this.#call('embra_world_get_line_loads', null, 0, n);
    const size = koffi.sizeof(capi.LineLoad);
    const out = Buffer.alloc(Math.max(n[0], 1) * size);
    this.#call('embra_world_get_line_loads', out, n[0], n);
    const result = [];
    for (let k = 0; k < n[0]; k++) {
      const l = koffi.decode(out, k * size, capi.LineLoad);
      result.push({ particles: Array.from(l.particles), load: Array.from(l.load) });
    }
    return result;
  }

  // --- JSON scenes --------------------------------------------------------------------------------

  /** The world as scene JSON text (complete: loading it steps on bit-identically). */
  saveJson() {
    const n = [0];
    this.#call('embra_world_save_json', null, 0, n);
    const out = Buffer.alloc(n[0]);
    this.#call('embra_world_save_json', out, out.length, n);
    return out.toString('utf8', 0, n[0] - 1);
  }

  /** Writes the world as scene JSON to a file (replaced whole). */
  saveFile(path) {
    this.#call('embra_world_save_file', buf.cString(path, 'path'));
  }

  // --- OBJ ---------------------------------------------------------------------------------------

  /** The world as Wavefront OBJ text (embra_world_export_obj): every particle a `v` line in world
   * order, each body's triangles as `f` lines, a body without triangles (a hanging net) as `l`
   * lines of its edges. */
  exportObj() {
    const n = [0];
    this.#call('embra_world_export_obj', null, 0, n);
    const out = Buffer.alloc(n[0]);
    this.#call('embra_world_export_obj', out, out.length, n);
    return out.toString('utf8', 0, n[0] - 1);
  }

  /** Writes exportObj()'s text to a file (replaced whole; no partial file on failure). */
  writeObj(path) {
    this.#call('embra_world_write_obj', buf.cString(path, 'path'));
  }

  /** The scene's own frame count (600 for a world not loaded from a scene). */
  sceneFrames() {
    const f = [0];
    this.#call('embra_world_get_scene_frames', f);
    return f[0];
  }
}

if (typeof Symbol.dispose === 'symbol') {
  World.prototype[Symbol.dispose] = World.prototype.close; // `using world = new World()`
}

module.exports = {
  World, Body, Id, GroupId, BodyId, PinId, ColliderId, FieldId, SHAPES, KINDS, GENERATE, PANEL_PINS, PANEL_CORNERS, PANEL_PRECISION, PANEL_METRICS, SOLVE_UNTIL,
  CUTS_FORMATS, EmbraError, wrapIds,
};
