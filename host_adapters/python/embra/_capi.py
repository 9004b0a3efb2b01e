"""The C ABI of libembra as ctypes sees it: structs, constants and one table of prototypes.

Everything here mirrors ``capi/include/embra/embra.h`` field for field. To bind a function added to
the header, add a line to ``PROTOTYPES`` (and, for a new struct, a ``Structure`` below); the test
``test_every_header_function_is_bound`` fails until every ``EMBRA_API`` function is in the table.
"""

import ctypes
import ctypes.util
import os
import sys
from ctypes import POINTER, c_char, c_char_p, c_double, c_int32, c_int64, c_uint32, c_void_p

ABI_VERSION = 0  # the EMBRA_ABI_VERSION these bindings were written against (the SONAME's number)

# --- status codes ----------------------------------------------------------------------------
OK = 0
ERROR_INVALID_ARGUMENT = -1
ERROR_STALE_ID = -2
ERROR_BUFFER_TOO_SMALL = -3
ERROR_SCHEMA = -4
ERROR_VERSION = -5
ERROR_LOCKED = -6
ERROR_NUMERICAL = -7
ERROR_INTERNAL = -8
ERROR_CANCELLED = -9

# --- ranges and limits (EMBRA_MAX_*, EMBRA_MIN_POSITIVE: what a world accepts; beyond: refused) -----
MAX_ABS_VALUE = 1e300
MIN_POSITIVE = 1e-300
MAX_DT = 1e6
MAX_UNIT_SCALE = 1e12
MAX_PARTICLES = 2097152
MAX_CONSTRAINTS = 16777216
MAX_PASSES_PER_STEP = 100000
MAX_OBJ_BYTES = 268435456

# --- enums -----------------------------------------------------------------------------------
GENERATE_STRETCH = 1
GENERATE_SHEAR = 2
GENERATE_BEND = 4
GENERATE_VOLUME = 8

CONSTRAINT_DISTANCE = 0
CONSTRAINT_EDGE_ANGLE = 1
CONSTRAINT_DIHEDRAL = 2
CONSTRAINT_TET_VOLUME = 3
CONSTRAINT_WELD = 4
CONSTRAINT_TETHER = 5
CONSTRAINT_PLANARITY = 6
CONSTRAINT_PLANE_OFFSET = 7

COLLIDER_PLANE = 0
COLLIDER_SPHERE = 1
COLLIDER_BOX = 2
COLLIDER_CAPSULE = 3
COLLIDER_CONVEX = 4
COLLIDER_MESH = 5

PANEL_PINS_NONE = 0
PANEL_PINS_TOP_CORNERS = 1
PANEL_PINS_TOP_AND_BOTTOM_CORNERS = 2

PANEL_METRIC_PLANARITY = 0
PANEL_METRIC_THICKNESS = 1
PANEL_METRIC_MITER = 2
PANEL_METRIC_CORNER_DISTANCE = 3
PANEL_METRIC_CONICAL = 4

CUTS_JSON = 0
CUTS_CSV = 1

# --- def versions ----------------------------------------------------------------------------
SOLVER_DEF_VERSION = 1
GROUP_DEF_VERSION = 1
BODY_DEF_VERSION = 1
CONSTRAINT_DEF_VERSION = 1
CONSTRAINT_BATCH_DEF_VERSION = 1
PIN_DEF_VERSION = 1
COLLIDER_DEF_VERSION = 2
PANEL_MESH_DEF_VERSION = 1
TOLERANCES_VERSION = 1
PANEL_METRICS_VERSION = 1
WIND_DEF_VERSION = 1
PRESSURE_DEF_VERSION = 1
SURFACE_TENSION_DEF_VERSION = 1
VORTEX_DEF_VERSION = 1
LOAD_OPTIONS_VERSION = 1

_d3 = c_double * 3
_d4 = c_double * 4
_i4 = c_int32 * 4
_pd = POINTER(c_double)
_pi = POINTER(c_int32)


class _Id(ctypes.Structure):
    _fields_ = [("index", c_uint32), ("generation", c_uint32)]

    def __eq__(self, other):
        return (type(self) is type(other) and self.index == other.index
                and self.generation == other.generation)

    def __hash__(self):
        return hash((type(self).__name__, self.index, self.generation))

    def __repr__(self):
        return f"{type(self).__name__}(index={self.index}, generation={self.generation})"


class GroupId(_Id):
    """embra_group_id: a constraint group ({0, 0} = the default group where a field says so)."""


class BodyId(_Id):
    """embra_body_id."""


class PinId(_Id):
    """embra_pin_id."""


class ColliderId(_Id):
    """embra_collider_id."""


class FieldId(_Id):
    """embra_field_id: a wind, pressure, surface tension or vortex field."""


class SolverDef(ctypes.Structure):
    _fields_ = [("version", c_int32), ("substeps", c_int32), ("dt", c_double), ("iterations", c_int32),
                ("chebyshev_rho_milli", c_int32), ("gravity", _d3), ("damping", c_double), ("settle_speed", c_double),
                ("tethers", c_int32), ("realign_passes", c_int32), ("self_collision", c_int32),
                ("chain_solve", c_int32)]


class WorldCounts(ctypes.Structure):
    _fields_ = [("particles", c_int32), ("bodies", c_int32), ("groups", c_int32), ("pins", c_int32),
                ("colliders", c_int32), ("reserved0", c_int32), ("constraints", c_int64)]


class GroupDef(ctypes.Structure):
    _fields_ = [("version", c_int32), ("order", c_int32), ("weight", c_int32)]


class Material(ctypes.Structure):
    _fields_ = [("mass", c_double), ("density", c_double), ("stretch_compliance", c_double),
                ("shear_compliance", c_double), ("bend_compliance", c_double), ("volume_compliance", c_double),
                ("damping", c_double), ("thickness", c_double), ("friction_static", c_double),
                ("friction_dynamic", c_double)]


class BodyDef(ctypes.Structure):
    _fields_ = [("version", c_int32), ("vertex_count", c_int32), ("positions", _pd), ("masses", _pd),
                ("uvs", _pd), ("edge_count", c_int32), ("triangle_count", c_int32), ("edges", _pi),
                ("triangles", _pi), ("tets", _pi), ("tet_count", c_int32), ("generate", c_int32),
                ("material", Material), ("stretch_group", GroupId), ("shear_group", GroupId),
                ("bend_group", GroupId), ("volume_group", GroupId)]


class ConstraintDef(ctypes.Structure):
    _fields_ = [("version", c_int32), ("kind", c_int32), ("group", GroupId), ("particles", _i4),
                ("rest_from_current", c_int32), ("reserved0", c_int32), ("rest", c_double),
                ("compliance", c_double)]


class ConstraintBatchDef(ctypes.Structure):
    _fields_ = [("version", c_int32), ("kind", c_int32), ("group", GroupId), ("count", c_int32),
                ("reserved0", c_int32), ("particles", _pi), ("rest", _pd), ("compliances", _pd),
                ("compliance", c_double)]


class PinDef(ctypes.Structure):
    _fields_ = [("version", c_int32), ("particle", c_int32), ("target", _d3), ("compliance", c_double),
                ("group", GroupId)]


class ColliderDef(ctypes.Structure):
    _fields_ = [("version", c_int32), ("shape", c_int32), ("position", _d3), ("rotation", _d4),
                ("radius", c_double), ("thickness", c_double), ("friction_static", c_double),
                ("friction_dynamic", c_double), ("half_extents", _d3), ("half_length", c_double),
                ("vertex_count", c_int32), ("triangle_count", c_int32), ("vertices", _pd), ("triangles", _pi)]


class StepReport(ctypes.Structure):
    _fields_ = [("frame", c_int64), ("time", c_double), ("kinetic_energy", c_double), ("max_speed", c_double),
                ("residual_max", c_double), ("residual_rms", c_double), ("constraint_count", c_int64),
                ("contact_count", c_int64), ("settled", c_int32), ("reserved0", c_int32)]


class GroupReport(ctypes.Structure):
    _fields_ = [("count", c_int64), ("residual_max", c_double), ("residual_rms", c_double)]


class PanelMeshDef(ctypes.Structure):
    _fields_ = [("version", c_int32), ("vertex_count", c_int32), ("positions", _pd), ("quads", _pi),
                ("quad_count", c_int32), ("grid_columns", c_int32), ("grid_rows", c_int32), ("pins", c_int32),
                ("panel_size", c_double), ("origin", _d3), ("thickness", c_double), ("mass", c_double),
                ("density", c_double), ("damping", c_double), ("friction_static", c_double),
                ("friction_dynamic", c_double), ("slide_compliance", c_double), ("group", GroupId)]


class Tolerance(ctypes.Structure):
    _fields_ = [("target", c_double), ("max", c_double)]


class Tolerances(ctypes.Structure):
    _fields_ = [("version", c_int32), ("reserved0", c_int32), ("unit_scale", c_double), ("planarity", Tolerance),
                ("planarity_distance", Tolerance), ("thickness", Tolerance), ("miter", Tolerance)]


class MetricSummary(ctypes.Structure):
    _fields_ = [("max", c_double), ("rms", c_double), ("count", c_int64), ("within_target", c_int64),
                ("within_max", c_int64), ("above_max", c_int64)]


class PanelMetrics(ctypes.Structure):
    _fields_ = [("version", c_int32), ("within_tolerance", c_int32), ("planarity_top", MetricSummary),
                ("planarity_bottom", MetricSummary), ("corner_distance_top", MetricSummary),
                ("corner_distance_bottom", MetricSummary), ("diagonal_top", MetricSummary),
                ("diagonal_bottom", MetricSummary), ("thickness", MetricSummary), ("miter", MetricSummary),
                ("conical", MetricSummary)]


class WindDef(ctypes.Structure):
    _fields_ = [("version", c_int32), ("reserved0", c_int32), ("body", BodyId), ("direction", _d3),
                ("speed", c_double), ("air_density", c_double), ("drag", c_double), ("lift", c_double)]


class PressureDef(ctypes.Structure):
    _fields_ = [("version", c_int32), ("keep_volume", c_int32), ("body", BodyId), ("inside_pressure", c_double),
                ("outside_pressure", c_double), ("volume_compliance", c_double), ("rest_volume", c_double)]


class SurfaceTensionDef(ctypes.Structure):
    _fields_ = [("version", c_int32), ("reserved0", c_int32), ("body", BodyId), ("tension", c_double),
                ("regularisation", c_double)]


class VortexDef(ctypes.Structure):
    _fields_ = [("version", c_int32), ("reserved0", c_int32), ("body", BodyId), ("center", _d3), ("axis", _d3),
                ("strength", c_double), ("radius", c_double), ("twist", c_double), ("decay", c_double),
                ("start_time", c_double)]


class LoadOptions(ctypes.Structure):
    _fields_ = [("version", c_int32), ("allow_paths_outside_base", c_int32), ("base_dir", c_char_p)]


class Warning(ctypes.Structure):  # noqa: A001 - the C name (embra_warning)
    _fields_ = [("frame", c_int64), ("particle", c_int32), ("reserved0", c_int32)]


_status = c_int32
_world = c_void_p  # embra_world*, opaque
_world_out = POINTER(c_void_p)
_P = POINTER

# name -> (restype, argtypes). Functions returning embra_status are checked by the callers in
# world.py (embra.errors.check); the rest cannot fail.
PROTOTYPES = {
    # errors and versions
    "embra_last_error_message": (c_char_p, []),
    "embra_status_name": (c_char_p, [_status]),
    "embra_version": (c_int32, []),
    "embra_version_string": (c_char_p, []),
    "embra_abi_version": (c_int32, []),
    "embra_check_abi": (_status, [c_int32]),
    # world and solver settings
    "embra_default_solver_def": (SolverDef, []),
    "embra_world_create": (_status, [_world_out, _P(SolverDef)]),
    "embra_world_destroy": (None, [_world]),
    "embra_world_get_solver": (_status, [_world, _P(SolverDef)]),
    "embra_world_set_solver": (_status, [_world, _P(SolverDef)]),
    "embra_world_set_gravity": (_status, [_world, _pd]),
    "embra_world_get_counts": (_status, [_world, _P(WorldCounts)]),
    "embra_world_get_bodies": (_status, [_world, _P(BodyId), c_int32, _pi]),
    "embra_world_get_groups": (_status, [_world, _P(GroupId), c_int32, _pi]),
    "embra_world_get_pins": (_status, [_world, _P(PinId), c_int32, _pi]),
    "embra_world_get_colliders": (_status, [_world, _P(ColliderId), c_int32, _pi]),
    # groups
    "embra_default_group_def": (GroupDef, []),
    "embra_group_create": (_status, [_world, _P(GroupDef), _P(GroupId)]),
    "embra_group_destroy": (_status, [_world, GroupId]),
    "embra_group_set_order": (_status, [_world, GroupId, c_int32]),
    "embra_group_set_weight": (_status, [_world, GroupId, c_int32]),
    "embra_world_default_group": (_status, [_world, _P(GroupId)]),
    "embra_world_contact_group": (_status, [_world, _P(GroupId)]),
    # bodies
    "embra_default_material": (Material, []),
    "embra_default_body_def": (BodyDef, []),
    "embra_body_create": (_status, [_world, _P(BodyDef), _P(BodyId), _P(c_int32)]),
    "embra_body_get_particles": (_status, [_world, BodyId, _P(c_int32), _P(c_int32)]),
    "embra_body_set_rest_scale": (_status, [_world, BodyId, c_double, c_double, c_double]),
    "embra_body_get_triangles": (_status, [_world, BodyId, _pi, c_int64, _P(c_int64)]),
    # panel meshes
    "embra_default_panel_mesh_def": (PanelMeshDef, []),
    "embra_panel_mesh_create": (_status, [_world, _P(PanelMeshDef), _P(BodyId), _P(c_int32)]),
    "embra_panel_mesh_get_panel_count": (_status, [_world, BodyId, _P(c_int32)]),
    "embra_default_tolerances": (Tolerances, []),
    "embra_world_get_tolerances": (_status, [_world, _P(Tolerances)]),
    "embra_world_set_tolerances": (_status, [_world, _P(Tolerances)]),
    "embra_panel_mesh_get_metrics": (_status, [_world, BodyId, _P(Tolerances), _P(PanelMetrics)]),
    "embra_panel_mesh_get_corner_gap": (_status, [_world, BodyId, _P(MetricSummary)]),
    "embra_panel_mesh_get_vertex_errors": (_status, [_world, BodyId, c_int32, _pd, c_int64, _P(c_int64)]),
    "embra_panel_mesh_export_cuts": (_status, [_world, BodyId, c_int32, _P(c_char), c_int64, _P(c_int64)]),
    # constraints
    "embra_constraint_arity": (c_int32, [c_int32]),
    "embra_default_constraint_def": (ConstraintDef, []),
    "embra_constraint_add": (_status, [_world, _P(ConstraintDef)]),
    "embra_default_constraint_batch_def": (ConstraintBatchDef, []),
    "embra_constraints_add": (_status, [_world, _P(ConstraintBatchDef)]),
    # pins
    "embra_default_pin_def": (PinDef, []),
    "embra_pin_create": (_status, [_world, _P(PinDef), _P(PinId)]),
    "embra_pin_destroy": (_status, [_world, PinId]),
    "embra_pin_set_target": (_status, [_world, PinId, _pd]),
    "embra_pin_get_target": (_status, [_world, PinId, _pd]),
    "embra_pin_get_particle": (_status, [_world, PinId, _pi]),
    # colliders
    "embra_default_collider_def": (ColliderDef, []),
    "embra_collider_create": (_status, [_world, _P(ColliderDef), _P(ColliderId)]),
    "embra_collider_destroy": (_status, [_world, ColliderId]),
    "embra_collider_set_transform": (_status, [_world, ColliderId, _pd, _pd]),
    "embra_collider_get_transform": (_status, [_world, ColliderId, _pd, _pd]),
    # stepping and reading back
    "embra_world_step": (_status, [_world]),
    "embra_world_cancel": (_status, [_world]),
    "embra_world_get_report": (_status, [_world, _P(StepReport)]),
    "embra_group_get_report": (_status, [_world, GroupId, _P(GroupReport)]),
    "embra_world_get_warning": (_status, [_world, _P(Warning)]),
    "embra_world_get_positions": (_status, [_world, _pd, c_int64, c_int32, c_int32]),
    "embra_world_get_velocities": (_status, [_world, _pd, c_int64, c_int32, c_int32]),
    "embra_world_set_positions": (_status, [_world, _pd, c_int32, c_int32]),
    "embra_world_set_velocities": (_status, [_world, _pd, c_int32, c_int32]),
    # JSON scenes
    "embra_world_load_json": (_status, [_world_out, c_char_p, c_int64, c_char_p]),
    "embra_world_load_file": (_status, [_world_out, c_char_p]),
    "embra_default_load_options": (LoadOptions, []),
    "embra_world_load_json_with_options": (_status, [_world_out, c_char_p, c_int64, _P(LoadOptions)]),
    "embra_world_save_json": (_status, [_world, _P(c_char), c_int64, _P(c_int64)]),
    "embra_world_save_file": (_status, [_world, c_char_p]),
    "embra_world_get_scene_frames": (_status, [_world, _P(c_int64)]),
    # fields
    "embra_default_wind_def": (WindDef, []),
    "embra_wind_create": (_status, [_world, _P(WindDef), _P(FieldId)]),
    "embra_default_pressure_def": (PressureDef, []),
    "embra_pressure_create": (_status, [_world, _P(PressureDef), _P(FieldId)]),
    "embra_default_surface_tension_def": (SurfaceTensionDef, []),
    "embra_surface_tension_create": (_status, [_world, _P(SurfaceTensionDef), _P(FieldId)]),
    "embra_default_vortex_def": (VortexDef, []),
    "embra_vortex_create": (_status, [_world, _P(VortexDef), _P(FieldId)]),
    "embra_field_destroy": (_status, [_world, FieldId]),
    "embra_world_get_field_count": (_status, [_world, _P(c_int32)]),
}

LIBRARY_ENV = "EMBRA_LIBRARY"


def _candidates():
    """Where libembra is looked for, in order: $EMBRA_LIBRARY, next to this package, the system."""
    env = os.environ.get(LIBRARY_ENV)
    if env:
        yield env
        return
    here = os.path.dirname(os.path.abspath(__file__))
    names = [f"libembra.so.{ABI_VERSION}", "libembra.so"] if sys.platform.startswith("linux") else \
        ["libembra.dylib", "embra.dll", "libembra.so"]
    # beside the package (or its folder); then the library folder of an installed prefix, which
    # holds the package in lib/python3/dist-packages/embra (cmake --install)
    for folder in (here, os.path.dirname(here), os.path.normpath(os.path.join(here, "..", "..", ".."))):
        for name in names:
            path = os.path.join(folder, name)
            if os.path.exists(path):
                yield path
    found = ctypes.util.find_library("embra")
    if found:
        yield found
    yield names[0]  # let the dynamic loader search LD_LIBRARY_PATH and the cache


def _load():
    tried = []
    for path in _candidates():
        try:
            lib = ctypes.CDLL(path)  # CDLL releases the GIL for every call: worlds step in parallel
        except OSError as e:
            tried.append(f"{path}: {e}")
            continue
        for name, (restype, argtypes) in PROTOTYPES.items():
            fn = getattr(lib, name)  # AttributeError names a missing symbol: a library older than these bindings
            fn.restype = restype
            fn.argtypes = argtypes
        return lib, path
    raise OSError("embra: cannot load libembra (set %s to its path); tried:\n  %s" % (LIBRARY_ENV, "\n  ".join(tried)))


lib, library_path = _load()
