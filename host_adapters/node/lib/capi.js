'use strict';
// The C ABI of libembra as koffi sees it: constants, structs and one table of prototypes.
//
// Everything here mirrors capi/include/embra/embra.h field for field. To bind a function added to the
// header, add a line to PROTOTYPES (and, for a new struct, a koffi.struct below); the test
// tests/adapters/node/mirror.test.js fails until every EMBRA_API function, constant and struct of the
// header is here, and layout.test.js until every struct has the C compiler's size and offsets.
//
// Conventions of these declarations (koffi 3):
// - a world is an opaque `embra_world *`, a BigInt to JS; World (world.js) never lets a caller pass one;
// - bulk inputs and outputs are plain `double *` / `int32_t *` / `char *` parameters, given a
//   Float64Array / Int32Array / Buffer, whose memory C reads or writes during the call, no copy;
// - small outputs (ids, counts, reports, defs) are `_Out_` pointers filled into a JS object or a
//   one-element array;
// - fixed arrays inside structs (gravity[3], rotation[4], ...) decode as plain JS arrays.

const koffi = require('koffi');

/** The EMBRA_ABI_VERSION these bindings were written against (the SONAME's number). */
const ABI_VERSION = 0;
const LIBRARY_ENV = 'EMBRA_LIBRARY';

// --- status codes ---------------------------------------------------------------------------------
const OK = 0;
const ERROR_INVALID_ARGUMENT = -1;
const ERROR_STALE_ID = -2;
const ERROR_BUFFER_TOO_SMALL = -3;
const ERROR_SCHEMA = -4;
const ERROR_VERSION = -5;
const ERROR_LOCKED = -6;
const ERROR_NUMERICAL = -7;
const ERROR_INTERNAL = -8;
const ERROR_CANCELLED = -9;

// --- ranges and limits (what a world accepts; beyond them: EMBRA_ERROR_INVALID_ARGUMENT) -----------
const MAX_ABS_VALUE = 1e300;
const MIN_POSITIVE = 1e-300;
const MAX_DT = 1e6;
const MAX_UNIT_SCALE = 1e12;
const MAX_PARTICLES = 2097152;
const MAX_CONSTRAINTS = 16777216;
const MAX_PASSES_PER_STEP = 100000;
const MAX_OBJ_BYTES = 268435456;

// --- enums ----------------------------------------------------------------------------------------
const GENERATE_STRETCH = 1;
const GENERATE_SHEAR = 2;
const GENERATE_BEND = 4;
const GENERATE_VOLUME = 8;

const CONSTRAINT_DISTANCE = 0;
const CONSTRAINT_EDGE_ANGLE = 1;
const CONSTRAINT_DIHEDRAL = 2;
const CONSTRAINT_TET_VOLUME = 3;
const CONSTRAINT_WELD = 4;
const CONSTRAINT_TETHER = 5;
const CONSTRAINT_PLANARITY = 6;
const CONSTRAINT_PLANE_OFFSET = 7;

const COLLIDER_PLANE = 0;
const COLLIDER_SPHERE = 1;
const COLLIDER_BOX = 2;
const COLLIDER_CAPSULE = 3;
const COLLIDER_CONVEX = 4;
const COLLIDER_MESH = 5;

const PANEL_PINS_NONE = 0;
const PANEL_PINS_TOP_CORNERS = 1;
const PANEL_PINS_TOP_AND_BOTTOM_CORNERS = 2;

const PANEL_METRIC_PLANARITY = 0;
const PANEL_METRIC_THICKNESS = 1;
const PANEL_METRIC_MITER = 2;
const PANEL_METRIC_CORNER_DISTANCE = 3;
const PANEL_METRIC_CONICAL = 4;

const CUTS_JSON = 0;
const CUTS_CSV = 1;

// --- def versions ---------------------------------------------------------------------------------
const SOLVER_DEF_VERSION = 1;
const GROUP_DEF_VERSION = 1;
const BODY_DEF_VERSION = 1;
const CONSTRAINT_DEF_VERSION = 1;
const CONSTRAINT_BATCH_DEF_VERSION = 1;
const PIN_DEF_VERSION = 1;
const COLLIDER_DEF_VERSION = 2;
const PANEL_MESH_DEF_VERSION = 1;
const TOLERANCES_VERSION = 1;
const PANEL_METRICS_VERSION = 1;
const WIND_DEF_VERSION = 1;
const PRESSURE_DEF_VERSION = 1;
const SURFACE_TENSION_DEF_VERSION = 1;
const VORTEX_DEF_VERSION = 1;
const LOAD_OPTIONS_VERSION = 1;

// --- types ----------------------------------------------------------------------------------------
koffi.alias('embra_status', 'int32_t');
koffi.alias('embra_constraint_kind', 'int32_t');
koffi.alias('embra_collider_shape', 'int32_t');
koffi.opaque('embra_world');

const d3 = koffi.array('double', 3, 'Array');
const d4 = koffi.array('double', 4, 'Array');
const i4 = koffi.array('int32_t', 4, 'Array');

function idStruct(name) {
  return koffi.struct(name, { index: 'uint32_t', generation: 'uint32_t' });
}

const GroupIdType = idStruct('embra_group_id');
const BodyIdType = idStruct('embra_body_id');
const PinIdType = idStruct('embra_pin_id');
const ColliderIdType = idStruct('embra_collider_id');
const FieldIdType = idStruct('embra_field_id');

const SolverDef = koffi.struct('embra_solver_def', {
  version: 'int32_t', substeps: 'int32_t', dt: 'double', iterations: 'int32_t', chebyshev_rho_milli: 'int32_t',
  gravity: d3, damping: 'double', settle_speed: 'double', tethers: 'int32_t', realign_passes: 'int32_t',
  self_collision: 'int32_t', chain_solve: 'int32_t',
});

const WorldCounts = koffi.struct('embra_world_counts', {
  particles: 'int32_t', bodies: 'int32_t', groups: 'int32_t', pins: 'int32_t', colliders: 'int32_t',
  reserved0: 'int32_t', constraints: 'int64_t',
});

const GroupDef = koffi.struct('embra_group_def', { version: 'int32_t', order: 'int32_t', weight: 'int32_t' });

const Material = koffi.struct('embra_material', {
  mass: 'double', density: 'double', stretch_compliance: 'double', shear_compliance: 'double',
  bend_compliance: 'double', volume_compliance: 'double', damping: 'double', thickness: 'double',
  friction_static: 'double', friction_dynamic: 'double',
});

const BodyDef = koffi.struct('embra_body_def', {
  version: 'int32_t', vertex_count: 'int32_t', positions: 'const double *', masses: 'const double *',
  uvs: 'const double *', edge_count: 'int32_t', triangle_count: 'int32_t', edges: 'const int32_t *',
  triangles: 'const int32_t *', tets: 'const int32_t *', tet_count: 'int32_t', generate: 'int32_t',
  material: Material, stretch_group: GroupIdType, shear_group: GroupIdType, bend_group: GroupIdType,
  volume_group: GroupIdType,
});

const ConstraintDef = koffi.struct('embra_constraint_def', {
  version: 'int32_t', kind: 'embra_constraint_kind', group: GroupIdType, particles: i4,
  rest_from_current: 'int32_t', reserved0: 'int32_t', rest: 'double', compliance: 'double',
});

const ConstraintBatchDef = koffi.struct('embra_constraint_batch_def', {
  version: 'int32_t', kind: 'embra_constraint_kind', group: GroupIdType, count: 'int32_t', reserved0: 'int32_t',
  particles: 'const int32_t *', rest: 'const double *', compliances: 'const double *', compliance: 'double',
});

const PinDef = koffi.struct('embra_pin_def', {
  version: 'int32_t', particle: 'int32_t', target: d3, compliance: 'double', group: GroupIdType,
});

const ColliderDef = koffi.struct('embra_collider_def', {
  version: 'int32_t', shape: 'embra_collider_shape', position: d3, rotation: d4, radius: 'double',
  thickness: 'double', friction_static: 'double', friction_dynamic: 'double', half_extents: d3,
  half_length: 'double', vertex_count: 'int32_t', triangle_count: 'int32_t', vertices: 'const double *',
  triangles: 'const int32_t *',
});

const StepReport = koffi.struct('embra_step_report', {
  frame: 'int64_t', time: 'double', kinetic_energy: 'double', max_speed: 'double', residual_max: 'double',
  residual_rms: 'double', constraint_count: 'int64_t', contact_count: 'int64_t', settled: 'int32_t',
  reserved0: 'int32_t',
});

const GroupReport = koffi.struct('embra_group_report', {
  count: 'int64_t', residual_max: 'double', residual_rms: 'double',
});

const Warning = koffi.struct('embra_warning', { frame: 'int64_t', particle: 'int32_t', reserved0: 'int32_t' });

const PanelMeshDef = koffi.struct('embra_panel_mesh_def', {
  version: 'int32_t', vertex_count: 'int32_t', positions: 'const double *', quads: 'const int32_t *',
  quad_count: 'int32_t', grid_columns: 'int32_t', grid_rows: 'int32_t', pins: 'int32_t', panel_size: 'double',
  origin: d3, thickness: 'double', mass: 'double', density: 'double', damping: 'double',
  friction_static: 'double', friction_dynamic: 'double', slide_compliance: 'double', group: GroupIdType,
});

const Tolerance = koffi.struct('embra_tolerance', { target: 'double', max: 'double' });

const Tolerances = koffi.struct('embra_tolerances', {
  version: 'int32_t', reserved0: 'int32_t', unit_scale: 'double', planarity: Tolerance,
  planarity_distance: Tolerance, thickness: Tolerance, miter: Tolerance,
});

const MetricSummary = koffi.struct('embra_metric_summary', {
  max: 'double', rms: 'double', count: 'int64_t', within_target: 'int64_t', within_max: 'int64_t',
  above_max: 'int64_t',
});

const PanelMetrics = koffi.struct('embra_panel_metrics', {
  version: 'int32_t', within_tolerance: 'int32_t', planarity_top: MetricSummary, planarity_bottom: MetricSummary,
  corner_distance_top: MetricSummary, corner_distance_bottom: MetricSummary, diagonal_top: MetricSummary,
  diagonal_bottom: MetricSummary, thickness: MetricSummary, miter: MetricSummary, conical: MetricSummary,
});

const WindDef = koffi.struct('embra_wind_def', {
  version: 'int32_t', reserved0: 'int32_t', body: BodyIdType, direction: d3, speed: 'double',
  air_density: 'double', drag: 'double', lift: 'double',
});

const PressureDef = koffi.struct('embra_pressure_def', {
  version: 'int32_t', keep_volume: 'int32_t', body: BodyIdType, inside_pressure: 'double',
  outside_pressure: 'double', volume_compliance: 'double', rest_volume: 'double',
});

const SurfaceTensionDef = koffi.struct('embra_surface_tension_def', {
  version: 'int32_t', reserved0: 'int32_t', body: BodyIdType, tension: 'double', regularisation: 'double',
});

const VortexDef = koffi.struct('embra_vortex_def', {
  version: 'int32_t', reserved0: 'int32_t', body: BodyIdType, center: d3, axis: d3, strength: 'double',
  radius: 'double', twist: 'double', decay: 'double', start_time: 'double',
});

const LoadOptions = koffi.struct('embra_load_options', {
  version: 'int32_t', allow_paths_outside_base: 'int32_t', base_dir: 'const char *',
});

/** Every struct of embra.h by its C name (the layout test compares each with the C compiler's). */
const STRUCTS = {
  embra_group_id: GroupIdType, embra_body_id: BodyIdType, embra_pin_id: PinIdType,
  embra_collider_id: ColliderIdType, embra_field_id: FieldIdType, embra_solver_def: SolverDef,
  embra_world_counts: WorldCounts, embra_group_def: GroupDef, embra_material: Material, embra_body_def: BodyDef,
  embra_constraint_def: ConstraintDef, embra_constraint_batch_def: ConstraintBatchDef, embra_pin_def: PinDef,
  embra_collider_def: ColliderDef, embra_step_report: StepReport, embra_group_report: GroupReport,
  embra_warning: Warning, embra_panel_mesh_def: PanelMeshDef, embra_tolerance: Tolerance,
  embra_tolerances: Tolerances, embra_metric_summary: MetricSummary, embra_panel_metrics: PanelMetrics,
  embra_wind_def: WindDef, embra_pressure_def: PressureDef, embra_surface_tension_def: SurfaceTensionDef,
  embra_vortex_def: VortexDef, embra_load_options: LoadOptions,
};

// --- functions ------------------------------------------------------------------------------------
// name -> its C prototype in koffi's syntax. Functions returning embra_status are checked by their
// callers in world.js (errors.check); the rest cannot fail.
const W = 'embra_world *world';
const CW = 'const embra_world *world';
const PROTOTYPES = {
  // errors and versions
  embra_last_error_message: 'const char *embra_last_error_message(void)',
  embra_status_name: 'const char *embra_status_name(embra_status status)',
  embra_version: 'int32_t embra_version(void)',
  embra_version_string: 'const char *embra_version_string(void)',
  embra_abi_version: 'int32_t embra_abi_version(void)',
  embra_check_abi: 'embra_status embra_check_abi(int32_t header_abi_version)',
  // world and solver settings
  embra_default_solver_def: 'embra_solver_def embra_default_solver_def(void)',
  embra_world_create: 'embra_status embra_world_create(_Out_ embra_world **out_world, const embra_solver_def *def)',
  embra_world_destroy: `void embra_world_destroy(${W})`,
  embra_world_get_solver: `embra_status embra_world_get_solver(${CW}, _Out_ embra_solver_def *out_def)`,
  embra_world_set_solver: `embra_status embra_world_set_solver(${W}, const embra_solver_def *def)`,
  embra_world_set_gravity: `embra_status embra_world_set_gravity(${W}, const double *gravity)`,
  embra_world_get_counts: `embra_status embra_world_get_counts(${CW}, _Out_ embra_world_counts *out_counts)`,
  // ids of live objects: `out` is a Uint32Array of 2 * capacity values (index, generation per id)
  embra_world_get_bodies: `embra_status embra_world_get_bodies(${CW}, embra_body_id *out, int32_t capacity,
    _Out_ int32_t *out_count)`,
  embra_world_get_groups: `embra_status embra_world_get_groups(${CW}, embra_group_id *out, int32_t capacity,
    _Out_ int32_t *out_count)`,
  embra_world_get_pins: `embra_status embra_world_get_pins(${CW}, embra_pin_id *out, int32_t capacity,
    _Out_ int32_t *out_count)`,
  embra_world_get_colliders: `embra_status embra_world_get_colliders(${CW}, embra_collider_id *out,
    int32_t capacity, _Out_ int32_t *out_count)`,
  // groups
  embra_default_group_def: 'embra_group_def embra_default_group_def(void)',
  embra_group_create:
    `embra_status embra_group_create(${W}, const embra_group_def *def, _Out_ embra_group_id *out_group)`,
  embra_group_destroy: `embra_status embra_group_destroy(${W}, embra_group_id group)`,
  embra_group_set_order: `embra_status embra_group_set_order(${W}, embra_group_id group, int32_t order)`,
  embra_group_set_weight: `embra_status embra_group_set_weight(${W}, embra_group_id group, int32_t weight)`,
  embra_world_default_group: `embra_status embra_world_default_group(${CW}, _Out_ embra_group_id *out_group)`,
  embra_world_contact_group: `embra_status embra_world_contact_group(${CW}, _Out_ embra_group_id *out_group)`,
  // bodies
  embra_default_material: 'embra_material embra_default_material(void)',
  embra_default_body_def: 'embra_body_def embra_default_body_def(void)',
  embra_body_create: `embra_status embra_body_create(${W}, const embra_body_def *def, _Out_ embra_body_id *out_body,
    _Out_ int32_t *out_first_particle)`,
  embra_body_get_particles: `embra_status embra_body_get_particles(${CW}, embra_body_id body,
    _Out_ int32_t *out_first, _Out_ int32_t *out_count)`,
  embra_body_set_rest_scale: `embra_status embra_body_set_rest_scale(${W}, embra_body_id body, double scale,
    double scale_u, double scale_v)`,
  embra_body_get_triangles: `embra_status embra_body_get_triangles(${CW}, embra_body_id body, int32_t *out,
    int64_t capacity, _Out_ int64_t *out_count)`,
  // constraints
  embra_constraint_arity: 'int32_t embra_constraint_arity(embra_constraint_kind kind)',
  embra_default_constraint_def: 'embra_constraint_def embra_default_constraint_def(void)',
  embra_constraint_add: `embra_status embra_constraint_add(${W}, const embra_constraint_def *def)`,
  embra_default_constraint_batch_def: 'embra_constraint_batch_def embra_default_constraint_batch_def(void)',
  embra_constraints_add: `embra_status embra_constraints_add(${W}, const embra_constraint_batch_def *def)`,
  // pins
  embra_default_pin_def: 'embra_pin_def embra_default_pin_def(void)',
  embra_pin_create: `embra_status embra_pin_create(${W}, const embra_pin_def *def, _Out_ embra_pin_id *out_pin)`,
  embra_pin_destroy: `embra_status embra_pin_destroy(${W}, embra_pin_id pin)`,
  embra_pin_set_target: `embra_status embra_pin_set_target(${W}, embra_pin_id pin, const double *target)`,
  embra_pin_get_target: `embra_status embra_pin_get_target(${CW}, embra_pin_id pin, double *out_target)`,
  embra_pin_get_particle:
    `embra_status embra_pin_get_particle(${CW}, embra_pin_id pin, _Out_ int32_t *out_particle)`,
  // colliders
  embra_default_collider_def: 'embra_collider_def embra_default_collider_def(void)',
  embra_collider_create: `embra_status embra_collider_create(${W}, const embra_collider_def *def,
    _Out_ embra_collider_id *out_collider)`,
  embra_collider_destroy: `embra_status embra_collider_destroy(${W}, embra_collider_id collider)`,
  embra_collider_set_transform: `embra_status embra_collider_set_transform(${W}, embra_collider_id collider,
    const double *position, const double *rotation)`,
  embra_collider_get_transform: `embra_status embra_collider_get_transform(${CW}, embra_collider_id collider,
    double *out_position, double *out_rotation)`,
  // stepping and reading back
  embra_world_step: `embra_status embra_world_step(${W})`,
  embra_world_cancel: `embra_status embra_world_cancel(${W})`,
  embra_world_get_report: `embra_status embra_world_get_report(${CW}, _Out_ embra_step_report *out_report)`,
  embra_group_get_report: `embra_status embra_group_get_report(${CW}, embra_group_id group,
    _Out_ embra_group_report *out_report)`,
  embra_world_get_warning: `embra_status embra_world_get_warning(${CW}, _Out_ embra_warning *out_warning)`,
  embra_world_get_positions: `embra_status embra_world_get_positions(${CW}, double *out_xyz, int64_t capacity,
    int32_t first, int32_t count)`,
  embra_world_get_velocities: `embra_status embra_world_get_velocities(${CW}, double *out_xyz, int64_t capacity,
    int32_t first, int32_t count)`,
  embra_world_set_positions:
    `embra_status embra_world_set_positions(${W}, const double *xyz, int32_t first, int32_t count)`,
  embra_world_set_velocities:
    `embra_status embra_world_set_velocities(${W}, const double *xyz, int32_t first, int32_t count)`,
  // panel meshes
  embra_default_panel_mesh_def: 'embra_panel_mesh_def embra_default_panel_mesh_def(void)',
  embra_panel_mesh_create: `embra_status embra_panel_mesh_create(${W}, const embra_panel_mesh_def *def,
    _Out_ embra_body_id *out_body, _Out_ int32_t *out_first_particle)`,
  embra_panel_mesh_get_panel_count: `embra_status embra_panel_mesh_get_panel_count(${CW}, embra_body_id body,
    _Out_ int32_t *out_count)`,
  embra_default_tolerances: 'embra_tolerances embra_default_tolerances(void)',
  embra_world_get_tolerances:
    `embra_status embra_world_get_tolerances(${CW}, _Out_ embra_tolerances *out_tolerances)`,
  embra_world_set_tolerances: `embra_status embra_world_set_tolerances(${W}, const embra_tolerances *tolerances)`,
  embra_panel_mesh_get_metrics: `embra_status embra_panel_mesh_get_metrics(${CW}, embra_body_id body,
    const embra_tolerances *tolerances, _Out_ embra_panel_metrics *out_metrics)`,
  embra_panel_mesh_get_corner_gap: `embra_status embra_panel_mesh_get_corner_gap(${CW}, embra_body_id body,
    _Out_ embra_metric_summary *out_summary)`,
  embra_panel_mesh_get_vertex_errors: `embra_status embra_panel_mesh_get_vertex_errors(${CW}, embra_body_id body,
    int32_t metric, double *out, int64_t capacity, _Out_ int64_t *out_count)`,
  embra_panel_mesh_export_cuts: `embra_status embra_panel_mesh_export_cuts(${CW}, embra_body_id body,
    int32_t format, char *out, int64_t capacity, _Out_ int64_t *out_length)`,
  // JSON scenes
  embra_world_load_json: `embra_status embra_world_load_json(_Out_ embra_world **out_world, const char *json,
    int64_t length, const char *base_dir)`,
  embra_world_load_file: 'embra_status embra_world_load_file(_Out_ embra_world **out_world, const char *path)',
  embra_default_load_options: 'embra_load_options embra_default_load_options(void)',
  embra_world_load_json_with_options: `embra_status embra_world_load_json_with_options(_Out_ embra_world **out_world,
    const char *json, int64_t length, const embra_load_options *options)`,
  embra_world_save_json:
    `embra_status embra_world_save_json(${CW}, char *out, int64_t capacity, _Out_ int64_t *out_length)`,
  embra_world_save_file: `embra_status embra_world_save_file(${CW}, const char *path)`,
  embra_world_get_scene_frames: `embra_status embra_world_get_scene_frames(${CW}, _Out_ int64_t *out_frames)`,
  // fields
  embra_default_wind_def: 'embra_wind_def embra_default_wind_def(void)',
  embra_wind_create:
    `embra_status embra_wind_create(${W}, const embra_wind_def *def, _Out_ embra_field_id *out_field)`,
  embra_default_pressure_def: 'embra_pressure_def embra_default_pressure_def(void)',
  embra_pressure_create:
    `embra_status embra_pressure_create(${W}, const embra_pressure_def *def, _Out_ embra_field_id *out_field)`,
  embra_default_surface_tension_def: 'embra_surface_tension_def embra_default_surface_tension_def(void)',
  embra_surface_tension_create: `embra_status embra_surface_tension_create(${W},
    const embra_surface_tension_def *def, _Out_ embra_field_id *out_field)`,
  embra_default_vortex_def: 'embra_vortex_def embra_default_vortex_def(void)',
  embra_vortex_create:
    `embra_status embra_vortex_create(${W}, const embra_vortex_def *def, _Out_ embra_field_id *out_field)`,
  embra_field_destroy: `embra_status embra_field_destroy(${W}, embra_field_id field)`,
  embra_world_get_field_count: `embra_status embra_world_get_field_count(${CW}, _Out_ int32_t *out_count)`,
};

// --- loading --------------------------------------------------------------------------------------
function defaultLibraryName() {
  if (process.platform === 'darwin') return `libembra.${ABI_VERSION}.dylib`;
  if (process.platform === 'win32') return 'embra.dll';
  return `libembra.so.${ABI_VERSION}`; // by SONAME, through the dynamic loader's search
}

function load() {
  const env = process.env[LIBRARY_ENV];
  const path = env ? env : defaultLibraryName();
  let handle;
  try {
    handle = koffi.load(path);
  } catch (e) {
    throw new Error(`embra: cannot load libembra from '${path}' (set ${LIBRARY_ENV} to its path): ${e.message}`);
  }
  const lib = {};
  for (const [name, prototype] of Object.entries(PROTOTYPES)) {
    try {
      lib[name] = handle.func(prototype.replace(/\s+/g, ' '));
    } catch (e) {
      // a missing symbol: a library older than these bindings
      throw new Error(`embra: ${path} has no usable ${name} (${e.message})`);
    }
  }
  return { lib: Object.freeze(lib), libraryPath: path };
}

const { lib, libraryPath } = load();

module.exports = {
  koffi, lib, libraryPath, LIBRARY_ENV, ABI_VERSION, PROTOTYPES, STRUCTS,
  OK, ERROR_INVALID_ARGUMENT, ERROR_STALE_ID, ERROR_BUFFER_TOO_SMALL, ERROR_SCHEMA, ERROR_VERSION, ERROR_LOCKED,
  ERROR_NUMERICAL, ERROR_INTERNAL, ERROR_CANCELLED,
  MAX_ABS_VALUE, MIN_POSITIVE, MAX_DT, MAX_UNIT_SCALE, MAX_PARTICLES, MAX_CONSTRAINTS, MAX_PASSES_PER_STEP,
  MAX_OBJ_BYTES,
  GENERATE_STRETCH, GENERATE_SHEAR, GENERATE_BEND, GENERATE_VOLUME,
  CONSTRAINT_DISTANCE, CONSTRAINT_EDGE_ANGLE, CONSTRAINT_DIHEDRAL, CONSTRAINT_TET_VOLUME, CONSTRAINT_WELD,
  CONSTRAINT_TETHER, CONSTRAINT_PLANARITY, CONSTRAINT_PLANE_OFFSET,
  COLLIDER_PLANE, COLLIDER_SPHERE, COLLIDER_BOX, COLLIDER_CAPSULE, COLLIDER_CONVEX, COLLIDER_MESH,
  PANEL_PINS_NONE, PANEL_PINS_TOP_CORNERS, PANEL_PINS_TOP_AND_BOTTOM_CORNERS,
  PANEL_METRIC_PLANARITY, PANEL_METRIC_THICKNESS, PANEL_METRIC_MITER, PANEL_METRIC_CORNER_DISTANCE,
  PANEL_METRIC_CONICAL,
  CUTS_JSON, CUTS_CSV,
  SOLVER_DEF_VERSION, GROUP_DEF_VERSION, BODY_DEF_VERSION, CONSTRAINT_DEF_VERSION, CONSTRAINT_BATCH_DEF_VERSION,
  PIN_DEF_VERSION, COLLIDER_DEF_VERSION, PANEL_MESH_DEF_VERSION, TOLERANCES_VERSION, PANEL_METRICS_VERSION,
  WIND_DEF_VERSION, PRESSURE_DEF_VERSION, SURFACE_TENSION_DEF_VERSION, VORTEX_DEF_VERSION, LOAD_OPTIONS_VERSION,
  SolverDef, WorldCounts, GroupDef, Material, BodyDef, ConstraintDef, ConstraintBatchDef, PinDef, ColliderDef,
  StepReport, GroupReport, Warning, PanelMeshDef, Tolerance, Tolerances, MetricSummary, PanelMetrics, WindDef,
  PressureDef, SurfaceTensionDef, VortexDef, LoadOptions, GroupIdType, BodyIdType, PinIdType, ColliderIdType,
  FieldIdType,
};
