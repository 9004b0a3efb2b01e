'use strict';
// embra for Node.js: the whole C ABI of libembra through koffi.
//
//   const embra = require('embra');
//   const world = new embra.World({ gravity: [0, 0, 9.81] });
//   const body = world.createBody(xyz, { triangles, mass: 0.5 });
//   world.createPin(body.first, xyz.slice(0, 3));
//   world.step(100);
//   console.log(world.positions());
//   world.close();
//
// libembra is loaded from $EMBRA_LIBRARY, else from beside the package (embra.dll on Windows,
// libembra.so.2 on Linux), else by that name through the system's search (on Windows PATH too).

const capi = require('./capi');
const errors = require('./errors');
const world = require('./world');

const { lib } = capi;
const { check } = errors;

/** The library's version as MAJOR * 10000 + MINOR * 100 + PATCH. */
function version() {
  return lib.embra_version();
}

/** The library's version as "MAJOR.MINOR.PATCH". */
function versionString() {
  return lib.embra_version_string();
}

/** The library's ABI version (the SONAME's number). */
function abiVersion() {
  return lib.embra_abi_version();
}

/** Throws VersionError unless the library's ABI is `headerAbiVersion` (default: these bindings'). */
function checkAbi(headerAbiVersion = capi.ABI_VERSION) {
  check(lib.embra_check_abi(require('./buffers').int32(headerAbiVersion, 'headerAbiVersion')));
}

/** The C constant's name of a status code, e.g. "EMBRA_ERROR_STALE_ID". */
function statusName(status) {
  return lib.embra_status_name(require('./buffers').int32(status, 'status'));
}

/** The calling thread's last C error message ("" if none). */
function lastErrorMessage() {
  return lib.embra_last_error_message();
}

/** Number of particles one constraint of `kind` (a KINDS name or number) takes; 0 for an unknown kind. */
function constraintArity(kind) {
  const k = typeof kind === 'string' ? world.KINDS[kind] : kind;
  if (k === undefined) throw new RangeError(`kind: unknown name '${kind}' (known: ${Object.keys(world.KINDS)})`);
  return lib.embra_constraint_arity(require('./buffers').int32(k, 'kind'));
}

function defaults(name, type) {
  return () => world.wrapIds(lib[name](), type);
}

checkAbi(); // these bindings and the loaded library must agree before anything else

module.exports = {
  ...errors,
  World: world.World, Body: world.Body, Id: world.Id, GroupId: world.GroupId, BodyId: world.BodyId,
  PinId: world.PinId, ColliderId: world.ColliderId, FieldId: world.FieldId,
  SHAPES: world.SHAPES, KINDS: world.KINDS, GENERATE: world.GENERATE, PANEL_PINS: world.PANEL_PINS, PANEL_CORNERS: world.PANEL_CORNERS, PANEL_PRECISION: world.PANEL_PRECISION,
  PANEL_METRICS: world.PANEL_METRICS, CUTS_FORMATS: world.CUTS_FORMATS, SOLVE_UNTIL: world.SOLVE_UNTIL,
  version, versionString, abiVersion, checkAbi, statusName, lastErrorMessage, constraintArity,
  defaultSolverDef: defaults('embra_default_solver_def', capi.SolverDef),
  formFindingSolverDef: defaults('embra_form_finding_solver_def', capi.SolverDef),
  defaultSolveDef: defaults('embra_default_solve_def', capi.SolveDef),
  defaultGroupDef: defaults('embra_default_group_def', capi.GroupDef),
  defaultMaterial: defaults('embra_default_material', capi.Material),
  defaultBodyDef: defaults('embra_default_body_def', capi.BodyDef),
  defaultConstraintDef: defaults('embra_default_constraint_def', capi.ConstraintDef),
  defaultConstraintBatchDef: defaults('embra_default_constraint_batch_def', capi.ConstraintBatchDef),
  defaultPinDef: defaults('embra_default_pin_def', capi.PinDef),
  defaultColliderDef: defaults('embra_default_collider_def', capi.ColliderDef),
  defaultPanelMeshDef: defaults('embra_default_panel_mesh_def', capi.PanelMeshDef),
  defaultTolerances: defaults('embra_default_tolerances', capi.Tolerances),
  defaultWindDef: defaults('embra_default_wind_def', capi.WindDef),
  defaultPressureDef: defaults('embra_default_pressure_def', capi.PressureDef),
  defaultSurfaceTensionDef: defaults('embra_default_surface_tension_def', capi.SurfaceTensionDef),
  defaultVortexDef: defaults('embra_default_vortex_def', capi.VortexDef),
  defaultLoadOptions: defaults('embra_default_load_options', capi.LoadOptions),
  ABI_VERSION: capi.ABI_VERSION, libraryPath: capi.libraryPath, capi,
};
