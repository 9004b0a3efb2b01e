"""embra for Python: the whole C ABI of libembra through ctypes and the standard library.

    import embra
    with embra.World(gravity=(0, 0, 9.81)) as world:
        body = world.create_body(xyz, triangles=tri, mass=0.5)
        world.create_pin(body.first, xyz[0])
        world.step(100)
        print(world.positions())

libembra is found from $EMBRA_LIBRARY, next to this package, or the system's library path. numpy
is optional: when installed, arrays go to and from C without copies.
"""

from . import _capi
from ._capi import (ABI_VERSION, MAX_ABS_VALUE, MAX_CONSTRAINTS, MAX_DT, MAX_OBJ_BYTES, MAX_PARTICLES,
                    MAX_PASSES_PER_STEP, MAX_UNIT_SCALE, MIN_POSITIVE, BodyId, ColliderDef, ColliderId,
                    ConstraintBatchDef, ConstraintDef, FieldId, GroupDef, GroupId, GroupReport, LoadOptions, Material,
                    MetricSummary, PanelMeshDef, PanelMetrics, PinDef, PinId, PressureDef, SolveDef, SolveResult, SolverDef, StepReport,
                    SurfaceTensionDef, Tolerance, Tolerances, VortexDef, WindDef, WorldCounts, library_path)
from ._capi import Warning as StepWarning
from ._buffers import have_numpy
from .errors import (BufferTooSmallError, CancelledError, EmbraError, InternalError, InvalidArgumentError, LockedError,
                     NumericalError, SchemaError, StaleIdError, VersionError, check)
from .world import CUTS_FORMATS, GENERATE, KINDS, PANEL_CORNERS, PANEL_METRICS, PANEL_PRECISION, PANEL_PINS, SHAPES, SOLVE_UNTIL, Body, Solved, World, as_dict

_lib = _capi.lib


def sweep(document, out="sweep_out", **options):
    """Runs a design-space sweep on Dask (embra.sweeps.sweep: its options and what it writes)."""
    from .sweeps import sweep as run

    return run(document, out, **options)


def __getattr__(name):  # embra.Sweep, embra.SweepError: embra.sweeps imported only when used
    if name in ("Sweep", "SweepError"):
        from . import sweeps

        return getattr(sweeps, name)
    raise AttributeError(f"module 'embra' has no attribute '{name}'")


def version():
    """The library's version as MAJOR * 10000 + MINOR * 100 + PATCH."""
    return _lib.embra_version()


def version_string():
    return _lib.embra_version_string().decode()


def abi_version():
    return _lib.embra_abi_version()


def check_abi(header_abi_version=ABI_VERSION):
    """Raises VersionError unless the library's ABI is `header_abi_version`."""
    check(_lib.embra_check_abi(int(header_abi_version)))


def status_name(status):
    return _lib.embra_status_name(int(status)).decode()


def last_error_message():
    """The calling thread's last C error message ("" if none)."""
    return _lib.embra_last_error_message().decode("utf-8", "replace")


def constraint_arity(kind):
    return _lib.embra_constraint_arity(KINDS[kind] if isinstance(kind, str) else int(kind))


def default_solver_def():
    return _lib.embra_default_solver_def()


def form_finding_solver_def():
    """embra_form_finding_solver_def(): settings for reaching a settled form fast (World(solver=...))."""
    return _lib.embra_form_finding_solver_def()


def default_solve_def():
    return _lib.embra_default_solve_def()


def default_material():
    return _lib.embra_default_material()


def default_panel_mesh_def():
    return _lib.embra_default_panel_mesh_def()


def default_tolerances():
    """The tolerances a world has until a scene or set_tolerances gives it others."""
    return _lib.embra_default_tolerances()


def default_wind_def():
    return _lib.embra_default_wind_def()


def default_pressure_def():
    return _lib.embra_default_pressure_def()


def default_surface_tension_def():
    return _lib.embra_default_surface_tension_def()


def default_vortex_def():
    return _lib.embra_default_vortex_def()


def default_load_options():
    """embra_default_load_options(): OBJ paths confined to the scene's folder (World.load_json and
    World.load_file take the same choice as their allow_paths_outside_base keyword)."""
    return _lib.embra_default_load_options()


check_abi()  # these bindings and the loaded library must agree before anything else

__version__ = version_string()
__all__ = [
    "World", "Body", "as_dict", "sweep", "Sweep", "SweepError", "version", "version_string", "abi_version", "check_abi", "status_name",
    "last_error_message", "constraint_arity", "default_solver_def", "form_finding_solver_def", "default_solve_def",
    "Solved", "SOLVE_UNTIL", "default_material", "default_panel_mesh_def",
    "default_tolerances", "default_wind_def", "default_pressure_def", "default_surface_tension_def",
    "default_vortex_def", "default_load_options", "have_numpy", "library_path", "ABI_VERSION",
    "EmbraError", "InvalidArgumentError", "StaleIdError", "BufferTooSmallError", "SchemaError", "VersionError",
    "LockedError", "NumericalError", "CancelledError", "InternalError",
    "MAX_ABS_VALUE", "MIN_POSITIVE", "MAX_DT", "MAX_UNIT_SCALE", "MAX_PARTICLES", "MAX_CONSTRAINTS",
    "MAX_PASSES_PER_STEP", "MAX_OBJ_BYTES",
    "SolverDef", "SolveDef", "SolveResult", "Material", "GroupDef", "ConstraintDef", "ConstraintBatchDef", "PinDef", "ColliderDef",
    "PanelMeshDef", "Tolerance", "Tolerances", "MetricSummary", "PanelMetrics", "WindDef", "PressureDef",
    "SurfaceTensionDef", "VortexDef", "LoadOptions", "StepReport", "GroupReport", "StepWarning", "WorldCounts",
    "GroupId", "BodyId", "PinId", "ColliderId", "FieldId",
    "SHAPES", "KINDS", "GENERATE", "PANEL_PINS", "PANEL_CORNERS", "PANEL_PRECISION", "PANEL_METRICS", "CUTS_FORMATS",
]
