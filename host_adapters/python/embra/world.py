"""The World: a Python view of one embra_world*, covering the whole C ABI.

A refused call raises the exception of its status (see :mod:`embra.errors`) with the C library's
message and leaves the world unchanged, exactly as the C function does. The C library takes one
call at a time per world and refuses a second concurrent one (EMBRA_ERROR_LOCKED); a World holds a
lock around each call, so threads sharing one World take turns (and close() waits for a call in
progress) instead of being refused. cancel() is the exception: it takes no turn, so another thread
can stop a long step in progress. Different Worlds step on different threads at once: ctypes
releases the GIL for every call into libembra.
"""

import ctypes
import os
import threading
from ctypes import byref, c_char, c_double, c_int32, c_int64, c_void_p

from . import _buffers as buf
from . import _capi
from ._capi import (AreaLoad, BodyDef, BodyId, ColliderDef, ColliderId, ConstraintBatchDef, ConstraintDef, FieldId, GroupDef,
                    ConstraintResidual, GroupConflict, GroupId, GroupReport, KindResidual, Material, MetricSummary, PanelMetrics, PinDef, PinId, Reaction, ColliderReaction, SolveResult, SolverDef,
                    StepReport, PressureDef, SurfaceTensionDef, VortexDef, WindDef,
                    Tolerances, Warning, WorldCounts, LineLoad, lib)
from .errors import EmbraError, check, error_for

# The names each enum's values go by here and in scenes: generated from embra.h with the enums.
SHAPES = dict(_capi.COLLIDER_NAMES)
KINDS = dict(_capi.CONSTRAINT_NAMES)
GENERATE = dict(_capi.GENERATE_NAMES)
PANEL_PINS = dict(_capi.PANEL_PINS_NAMES)
PANEL_CORNERS = dict(_capi.PANEL_CORNERS_NAMES)
PANEL_PRECISION = dict(_capi.PANEL_PRECISION_NAMES)
PIN_SUPPORTS = dict(_capi.PIN_SUPPORT_NAMES)
AREA_LOAD_MODES = dict(_capi.AREA_LOAD_NAMES)
AREA_LOAD_MODE_NAMES = {v: k for k, v in _capi.AREA_LOAD_NAMES.items()}
PANEL_METRICS = dict(_capi.PANEL_METRIC_NAMES)
CUTS_FORMATS = dict(_capi.CUTS_NAMES)
SOLVE_UNTIL = dict(_capi.SOLVE_UNTIL_NAMES)
SOLVE_OUTCOMES = {v: k for k, v in _capi.SOLVE_NAMES.items()}


def as_dict(struct):
    """A ctypes struct (def, report, counts) as a plain dict, arrays as tuples, nested structs as dicts."""
    out = {}
    for name, _ in struct._fields_:
        v = getattr(struct, name)
        if isinstance(v, ctypes.Array):
            v = tuple(v)
        elif isinstance(v, ctypes.Structure) and not isinstance(v, _capi._Id):
            v = as_dict(v)
        out[name] = v
    return out


def _fill(struct, fields, what):
    """Sets named fields of a ctypes struct from keyword arguments; unknown names are a TypeError."""
    names = {name: ctype for name, ctype in struct._fields_}
    for key, value in fields.items():
        if key not in names:
            raise TypeError(f"{what} has no field '{key}' (fields: {', '.join(names)})")
        ctype = names[key]
        if issubclass(ctype, ctypes.Array):
            values = list(value)
            if len(values) != ctype._length_:
                raise ValueError(f"{what}.{key}: expected {ctype._length_} numbers, got {len(values)}")
            setattr(struct, key, ctype(*values))
        elif issubclass(ctype, _capi._Id):
            setattr(struct, key, _id(value, ctype, f"{what}.{key}"))
        elif issubclass(ctype, ctypes.Structure):
            inner = getattr(struct, key)
            _fill(inner, as_dict(value) if isinstance(value, ctypes.Structure) else dict(value), f"{what}.{key}")
        elif ctype in (c_int32, c_int64) or ctype is ctypes.c_uint32:
            setattr(struct, key, buf.int32(value, f"{what}.{key}") if ctype is c_int32 else int(value))
        else:
            setattr(struct, key, float(value))
    return struct


def _flag(value, name):
    """A yes/no option: only True or False (a security choice is not guessed from a truthy value)."""
    if not isinstance(value, bool):
        raise TypeError(f"{name}: expected True or False, got {type(value).__name__}")
    return value


def _load_options(base_dir, allow_paths_outside_base):
    o = lib.embra_default_load_options()
    o.allow_paths_outside_base = 1 if _flag(allow_paths_outside_base, "allow_paths_outside_base") else 0
    o.base_dir = None if base_dir is None else os.fsencode(base_dir)
    return o


def _id(value, cls, name):
    if value is None:
        return cls()
    if isinstance(value, Body) and cls is BodyId:
        return value.id
    if not isinstance(value, cls):
        raise TypeError(f"{name}: expected {cls.__name__}, got {type(value).__name__}")
    return value


def _enum(value, table, name):
    if isinstance(value, str):
        if value not in table:
            raise ValueError(f"{name}: unknown name '{value}' (known: {', '.join(table)})")
        return table[value]
    return buf.int32(value, name)


class Body:
    """A body's id and its particle range [first, first + count)."""

    __slots__ = ("id", "first", "count")

    def __init__(self, body_id, first, count):
        self.id, self.first, self.count = body_id, first, count

    def __repr__(self):
        return f"Body(index={self.id.index}, first={self.first}, count={self.count})"


class World:
    """An embra world. Use it as a context manager, or call close(); a closed World refuses every call."""

    def __init__(self, solver=None, **settings):
        """Creates a world from embra_default_solver_def(), `solver` (a SolverDef or dict) and keyword
        settings (any SolverDef field: dt, substeps, iterations, gravity, damping, ...)."""
        self._ptr = None
        self._lock = threading.Lock()  # one call at a time (the C library refuses a second: LOCKED)
        self._cancel_lock = threading.Lock()  # cancel() against close(): never a destroyed pointer
        d = lib.embra_default_solver_def()
        if solver is not None:
            _fill(d, as_dict(solver) if isinstance(solver, SolverDef) else dict(solver), "SolverDef")
        _fill(d, settings, "SolverDef")
        ptr = c_void_p()
        check(lib.embra_world_create(byref(ptr), byref(d)))
        self._ptr = ptr

    @classmethod
    def _adopt(cls, ptr):
        w = cls.__new__(cls)
        w._ptr = ptr
        w._lock = threading.Lock()
        w._cancel_lock = threading.Lock()
        return w

    @classmethod
    def load_json(cls, text, base_dir=None, *, allow_paths_outside_base=False):
        """A world from scene JSON text (str or bytes). The scene's OBJ paths are relative to
        `base_dir` (None: the current folder) and must stay inside it, unless
        allow_paths_outside_base=True (for scenes the host trusts: absolute paths and ".." allowed)."""
        data = text.encode("utf-8") if isinstance(text, str) else bytes(text)
        options = _load_options(base_dir, allow_paths_outside_base)
        ptr = c_void_p()
        check(lib.embra_world_load_json_with_options(byref(ptr), data, len(data), byref(options)))
        return cls._adopt(ptr)

    @classmethod
    def load_file(cls, path, *, allow_paths_outside_base=False):
        """A world from a scene file. Its OBJ paths are relative to the file's folder and must stay
        inside it, unless allow_paths_outside_base=True (as for load_json)."""
        if not _flag(allow_paths_outside_base, "allow_paths_outside_base"):
            ptr = c_void_p()
            check(lib.embra_world_load_file(byref(ptr), os.fsencode(path)))
            return cls._adopt(ptr)
        # embra_world_load_file has no options: read the file here, its folder as base_dir
        with open(path, "rb") as f:
            data = f.read()
        return cls.load_json(data, os.path.dirname(os.fspath(path)) or ".", allow_paths_outside_base=True)

    # --- lifetime ------------------------------------------------------------------------------
    def close(self):
        """Destroys the world (embra_world_destroy). Idempotent; waits for a call in progress (call
        cancel() first to stop a long step)."""
        lock = getattr(self, "_lock", None)
        if lock is None:  # __init__ failed before the world existed
            return
        with lock, self._cancel_lock:
            ptr, self._ptr = self._ptr, None
            if ptr is not None and ptr.value:
                lib.embra_world_destroy(ptr)

    def cancel(self):
        """Asks the step in progress (on another thread) to stop: that step raises CancelledError with
        the world as before its frame. Callable from any thread at any time; it does not wait for the
        World's lock (the step holds it). A request made while no step runs stops the next frame
        stepped, before its first iteration. A closed World raises InvalidArgumentError."""
        with self._cancel_lock:  # held only for the C call: close() cannot free the world meanwhile
            ptr = self._ptr
            status = lib.embra_world_cancel(ptr)
            if status != _capi.OK:
                err = error_for(status)
        if status != _capi.OK:
            if ptr is None:
                err = type(err)(f"{err.message} (this World was closed)")
            raise err

    @property
    def closed(self):
        return self._ptr is None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def __del__(self):
        try:
            self.close()
        except Exception:  # interpreter shutdown: the library may already be gone
            pass

    def _call(self, name, *args):
        """Calls a C function with this world first; a closed World passes NULL, which C refuses."""
        with self._lock:
            ptr = self._ptr
            status = getattr(lib, name)(ptr, *args)
            if status != _capi.OK:
                err = error_for(status)  # read the message before another call on this thread
        if status != _capi.OK:
            if ptr is None:
                err = type(err)(f"{err.message} (this World was closed)")
            raise err

    # --- solver settings -----------------------------------------------------------------------
    @property
    def solver(self):
        """The solver settings (a SolverDef copy)."""
        d = SolverDef()
        self._call("embra_world_get_solver", byref(d))
        return d

    def set_solver(self, solver=None, **settings):
        """Replaces the settings: the current ones, then `solver` (SolverDef or dict), then keywords."""
        d = self.solver
        if solver is not None:
            _fill(d, as_dict(solver) if isinstance(solver, SolverDef) else dict(solver), "SolverDef")
        _fill(d, settings, "SolverDef")
        self._call("embra_world_set_solver", byref(d))

    def set_gravity(self, gravity):
        """Gravity in m/s^2 from the next step on (reverse it for the Gaudi paradigm)."""
        self._call("embra_world_set_gravity", buf.d3(gravity, "gravity"))

    def counts(self):
        c = WorldCounts()
        self._call("embra_world_get_counts", byref(c))
        return c

    @property
    def particle_count(self):
        return self.counts().particles

    def _ids(self, name, cls):
        n = c_int32()
        self._call(name, None, 0, byref(n))
        out = (cls * max(n.value, 1))()
        self._call(name, out, n.value, byref(n))
        return [cls(out[i].index, out[i].generation) for i in range(n.value)]

    def bodies(self):
        """Ids of every body, in creation order (a loaded scene's order, as saved)."""
        return self._ids("embra_world_get_bodies", BodyId)

    def groups(self):
        """Ids of the live groups in creation order: the default and contact groups first."""
        return self._ids("embra_world_get_groups", GroupId)

    def pins(self):
        """Ids of the live pins, in creation order (a loaded scene's order, as saved)."""
        return self._ids("embra_world_get_pins", PinId)

    def colliders(self):
        """Ids of the live colliders, in creation order (a loaded scene's order, as saved)."""
        return self._ids("embra_world_get_colliders", ColliderId)

    # --- groups --------------------------------------------------------------------------------
    def create_group(self, order=0, weight=1):
        d = lib.embra_default_group_def()
        d.order, d.weight = buf.int32(order, "order"), buf.int32(weight, "weight")
        g = GroupId()
        self._call("embra_group_create", byref(d), byref(g))
        return g

    def destroy_group(self, group):
        self._call("embra_group_destroy", _id(group, GroupId, "group"))

    def set_group_order(self, group, order):
        self._call("embra_group_set_order", _id(group, GroupId, "group"), buf.int32(order, "order"))

    def set_group_weight(self, group, weight):
        self._call("embra_group_set_weight", _id(group, GroupId, "group"), buf.int32(weight, "weight"))

    def default_group(self):
        g = GroupId()
        self._call("embra_world_default_group", byref(g))
        return g

    def contact_group(self):
        g = GroupId()
        self._call("embra_world_contact_group", byref(g))
        return g

    def group_report(self, group):
        r = GroupReport()
        self._call("embra_group_get_report", _id(group, GroupId, "group"), byref(r))
        return r

    def set_group_enabled(self, group, enabled):
        """Enables or disables a group (embra_group_set_enabled): a disabled group keeps its constraints
        and soft pins but is not projected, measured or diagnosed. Not the contact group."""
        self._call("embra_group_set_enabled", _id(group, GroupId, "group"), 1 if _flag(enabled, "enabled") else 0)

    def group_enabled(self, group):
        e = c_int32()
        self._call("embra_group_get_enabled", _id(group, GroupId, "group"), byref(e))
        return e.value == 1

    # --- bodies --------------------------------------------------------------------------------
    def create_body(self, positions, *, triangles=None, edges=None, tets=None, masses=None, uvs=None,
                    generate=None, material=None, stretch_group=None, shear_group=None, bend_group=None,
                    volume_group=None, **material_fields):
        """Adds a body (embra_body_create) and returns its Body (id, first particle, count).

        positions: xyz per vertex (flat or nested, numpy (n, 3) used in place); triangles, edges,
        tets: body-local vertex indices; masses (kg per vertex), uvs (2 per vertex); generate: flags
        or names ("stretch", "shear", "bend", "volume"); material: a Material or dict, and/or
        material fields as keywords (mass=0.5, stretch_compliance=1e-2, ...)."""
        d = lib.embra_default_body_def()
        keep = []

        def elements(data, width, name):
            buf.check_rows(data, width, name)
            p, n, k = buf.ints_in(data, name)
            if n % width:
                raise ValueError(f"{name}: {n} indices is not a whole number of {width}-tuples")
            keep.append(k)
            return p, n // width

        buf.check_rows(positions, 3, "positions")
        p, n, k = buf.doubles_in(positions, "positions")
        if n % 3:
            raise ValueError(f"positions: {n} numbers is not a whole number of xyz triples")
        keep.append(k)
        d.positions, d.vertex_count = p, buf.int32(n // 3, "vertex count")
        if masses is not None:
            p, m, k = buf.doubles_in(masses, "masses")
            if m != n // 3:
                raise ValueError(f"masses: {m} values for {n // 3} vertices")
            keep.append(k)
            d.masses = p
        if uvs is not None:
            buf.check_rows(uvs, 2, "uvs")
            p, m, k = buf.doubles_in(uvs, "uvs")
            if m != 2 * (n // 3):
                raise ValueError(f"uvs: {m} numbers for {n // 3} vertices (2 per vertex)")
            keep.append(k)
            d.uvs = p
        if triangles is not None:
            d.triangles, d.triangle_count = elements(triangles, 3, "triangles")
        if edges is not None:
            d.edges, d.edge_count = elements(edges, 2, "edges")
        if tets is not None:
            d.tets, d.tet_count = elements(tets, 4, "tets")
        if generate is not None:
            if isinstance(generate, (list, tuple, set, frozenset)):
                flags = 0
                for g in generate:
                    flags |= _enum(g, GENERATE, "generate")
                d.generate = flags
            else:
                d.generate = _enum(generate, GENERATE, "generate")
        if material is not None:
            _fill(d.material, as_dict(material) if isinstance(material, Material) else dict(material), "Material")
        _fill(d.material, material_fields, "Material")
        d.stretch_group = _id(stretch_group, GroupId, "stretch_group")
        d.shear_group = _id(shear_group, GroupId, "shear_group")
        d.bend_group = _id(bend_group, GroupId, "bend_group")
        d.volume_group = _id(volume_group, GroupId, "volume_group")
        body, first = BodyId(), c_int32()
        self._call("embra_body_create", byref(d), byref(body), byref(first))
        return Body(body, first.value, d.vertex_count)

    def body_particles(self, body):
        """(first, count) of a body's particles."""
        first, count = c_int32(), c_int32()
        self._call("embra_body_get_particles", _id(body, BodyId, "body"), byref(first), byref(count))
        return first.value, count.value

    def material(self, body):
        """The body's Material (embra_body_get_material)."""
        m = Material()
        self._call("embra_body_get_material", _id(body, BodyId, "body"), byref(m))
        return m

    def set_material(self, body, material=None, **fields):
        """Changes a body's material from the next step on, without a rebuild (embra_body_set_material):
        the compliances of what it generated, its damping, thickness and friction. Starts from the
        body's material; `material` (a Material or dict) and keyword fields override it. Mass and
        density must stay the body's own."""
        m = self.material(body)
        if material is not None:
            _fill(m, as_dict(material) if isinstance(material, Material) else dict(material), "Material")
        _fill(m, fields, "Material")
        self._call("embra_body_set_material", _id(body, BodyId, "body"), byref(m))

    def body_masses(self, body):
        """The masses (kg) of a body's particles, one each, 0 = immovable (embra_body_get_masses):
        numpy (n,) float64, or a flat array('d')."""
        b = _id(body, BodyId, "body")
        n = c_int32()
        self._call("embra_body_get_masses", b, None, 0, byref(n))
        out, pointer, capacity, keep = buf.doubles_out(n.value, None, "masses", width=1)
        self._call("embra_body_get_masses", b, pointer, buf.int32(capacity, "capacity"), byref(n))
        return out

    def set_body_masses(self, body, masses):
        """Sets the masses (kg) of a body's particles from the next step on, without a rebuild
        (embra_body_set_masses): one per particle of the body, each 0 (immovable) or positive. A
        hard-pinned particle keeps following its pin. Refused, changing nothing, for a wrong count or
        a negative or non-finite mass."""
        shape = getattr(masses, "shape", None)
        if shape is not None and len(shape) != 1:
            raise ValueError(f"masses: expected one mass per particle, a 1-D array, got shape {tuple(shape)}")
        p, n, keep = buf.doubles_in(masses, "masses")
        self._call("embra_body_set_masses", _id(body, BodyId, "body"), p, buf.int32(n, "count"))

    def set_rest_scale(self, body, scale=1.0, scale_u=1.0, scale_v=1.0):
        self._call("embra_body_set_rest_scale", _id(body, BodyId, "body"), float(scale), float(scale_u),
                   float(scale_v))

    def _body_int32s(self, function, body, width):
        """A body's int32 list read by `function` (asked for its count first): numpy (n / width,
        width) int32, or a flat array('i')."""
        b = _id(body, BodyId, "body")
        n = c_int64()
        self._call(function, b, None, 0, byref(n))
        if buf.np is not None:
            out = buf.np.empty((n.value // width, width), dtype=buf.np.int32)
            pointer = out.ctypes.data_as(ctypes.POINTER(c_int32))
        else:
            from array import array
            out = array(buf._INT32_CODE, bytes(4 * n.value))
            pointer = ctypes.cast((c_int32 * n.value).from_buffer(out), ctypes.POINTER(c_int32))
        self._call(function, b, pointer, n.value, byref(n))
        return out

    def body_triangles(self, body):
        """A body's triangles as world particle indices: numpy (t, 3) int32, or flat array('i')."""
        return self._body_int32s("embra_body_get_triangles", body, 3)

    # --- panel meshes --------------------------------------------------------------------------
    def create_panel_mesh(self, positions=None, quads=None, *, pins=None, corners=None, precision=None, group=None,
                          **fields):
        """Builds a Planar Offset Quad panel mesh (embra_panel_mesh_create) and returns its Body (id,
        first particle, count: 8 particles per panel welded, 2 per vertex shared).

        positions and quads: the top quad mesh (xyz per vertex; 4 vertex indices per quad, flat,
        nested or numpy); without them, a grid of grid_columns x grid_rows square panels of
        panel_size at origin. pins: "none", "top_corners", "top_and_bottom_corners" or the number;
        corners: "welded" or "shared" (PANEL_CORNERS) or the number; precision: "full" or "single"
        (PANEL_PRECISION) or the number; any other PanelMeshDef field as a keyword (thickness=0.01,
        mass=16.0, damping=9.0, ...)."""
        d = lib.embra_default_panel_mesh_def()
        _fill(d, fields, "PanelMeshDef")
        keep = []
        if positions is not None or quads is not None:
            if positions is None or quads is None:
                raise ValueError("positions and quads go together (neither: a grid)")
            buf.check_rows(positions, 3, "positions")
            buf.check_rows(quads, 4, "quads")
            p, n, k = buf.doubles_in(positions, "positions")
            if n % 3:
                raise ValueError(f"positions: {n} numbers is not a whole number of xyz triples")
            keep.append(k)
            d.positions, d.vertex_count = p, buf.int32(n // 3, "vertex count")
            q, m, k = buf.ints_in(quads, "quads")
            if m % 4:
                raise ValueError(f"quads: {m} indices is not a whole number of 4-tuples")
            keep.append(k)
            d.quads, d.quad_count = q, buf.int32(m // 4, "quad count")
        if pins is not None:
            d.pins = _enum(pins, PANEL_PINS, "pins")
        if corners is not None:
            d.corners = _enum(corners, PANEL_CORNERS, "corners")
        if precision is not None:
            d.precision = _enum(precision, PANEL_PRECISION, "precision")
        d.group = _id(group, GroupId, "group")
        body, first = BodyId(), c_int32()
        self._call("embra_panel_mesh_create", byref(d), byref(body), byref(first))
        return Body(body, first.value, self.body_particles(body)[1])

    def panel_corner_particles(self, body):
        """The world particle of each panel corner (embra_panel_mesh_get_corner_particles): numpy
        (panels, 8) int32 (top corners 0-3, then bottom corners 0-3), or a flat array('i')."""
        return self._body_int32s("embra_panel_mesh_get_corner_particles", body, 8)

    def panel_count(self, body):
        """The number of panels of a panel-mesh body."""
        n = c_int32()
        self._call("embra_panel_mesh_get_panel_count", _id(body, BodyId, "body"), byref(n))
        return n.value

    @property
    def tolerances(self):
        """The fabrication tolerances the metrics are judged against (a Tolerances copy)."""
        t = Tolerances()
        self._call("embra_world_get_tolerances", byref(t))
        return t

    @tolerances.setter
    def tolerances(self, tolerances):
        self.set_tolerances(tolerances)

    def set_tolerances(self, tolerances=None, **fields):
        """Replaces the tolerances: the current ones, then `tolerances` (Tolerances or dict), then
        keywords (miter={"target": 1e-3, "max": 1e-2}, unit_scale=1000.0, ...)."""
        t = self.tolerances
        if tolerances is not None:
            _fill(t, as_dict(tolerances) if isinstance(tolerances, Tolerances) else dict(tolerances), "Tolerances")
        _fill(t, fields, "Tolerances")
        self._call("embra_world_set_tolerances", byref(t))

    def panel_metrics(self, body, tolerances=None):
        """The section 4.1 metrics of a panel-mesh body at the current positions (a PanelMetrics;
        as_dict() makes it a dict), judged against `tolerances` (Tolerances or dict over the
        defaults) or, when None, the world's."""
        t = None
        if tolerances is not None:
            t = lib.embra_default_tolerances()
            _fill(t, as_dict(tolerances) if isinstance(tolerances, Tolerances) else dict(tolerances), "Tolerances")
        m = PanelMetrics()
        self._call("embra_panel_mesh_get_metrics", _id(body, BodyId, "body"), None if t is None else byref(t),
                   byref(m))
        return m

    def corner_gap(self, body):
        """The welds' error of a panel-mesh body (a MetricSummary, in model units): per mesh vertex of
        two or more panels, the largest distance between two of its corner copies in one layer."""
        s = MetricSummary()
        self._call("embra_panel_mesh_get_corner_gap", _id(body, BodyId, "body"), byref(s))
        return s

    def vertex_errors(self, body, metric, out=None):
        """One error value per particle of a panel-mesh body (8 per panel, in body order) for a colour
        map: metric "planarity", "thickness", "miter", "corner_distance", "conical" or its number.
        A numpy float64 array written in place by C when numpy is installed, else array('d'); or
        into `out` (a writable double buffer, too small: BufferTooSmallError, nothing written)."""
        b, m = _id(body, BodyId, "body"), _enum(metric, PANEL_METRICS, "metric")
        n = c_int64()
        if out is None:
            self._call("embra_panel_mesh_get_vertex_errors", b, m, None, 0, byref(n))
        result, pointer, capacity, keep = buf.doubles_out(n.value, out, "out", width=1)
        self._call("embra_panel_mesh_get_vertex_errors", b, m, pointer, capacity, byref(n))
        return result

    def export_cuts(self, body, format="json"):
        """The cut list of a panel-mesh body at the current positions, as text: format "json" or "csv"
        (or its number)."""
        b, f = _id(body, BodyId, "body"), _enum(format, CUTS_FORMATS, "format")
        n = c_int64()
        self._call("embra_panel_mesh_export_cuts", b, f, None, 0, byref(n))
        out = (c_char * n.value)()
        self._call("embra_panel_mesh_export_cuts", b, f, out, n.value, byref(n))
        return out.raw[:n.value - 1].decode("utf-8")

    # --- constraints ---------------------------------------------------------------------------
    def add_constraint(self, kind, particles, rest=None, compliance=0.0, group=None):
        """One constraint (embra_constraint_add); rest None measures it from current positions."""
        d = lib.embra_default_constraint_def()
        d.kind = _enum(kind, KINDS, "kind")
        ids = [buf.int32(p, "particles") for p in particles]
        arity = lib.embra_constraint_arity(d.kind)
        if arity and len(ids) != arity:
            raise ValueError(f"particles: kind {kind} takes {arity} particles, got {len(ids)}")
        if len(ids) > 4:
            raise ValueError(f"particles: at most 4, got {len(ids)}")
        for i, p in enumerate(ids):
            d.particles[i] = p
        d.group = _id(group, GroupId, "group")
        if rest is not None:
            d.rest_from_current, d.rest = 0, float(rest)
        d.compliance = float(compliance)
        self._call("embra_constraint_add", byref(d))

    def add_constraints(self, kind, particles, rest=None, compliances=None, compliance=0.0, group=None):
        """Many constraints of one kind at once (embra_constraints_add), all or none.

        particles: arity indices per constraint (flat, nested or numpy (count, arity)); rest and
        compliances: one value per constraint or None."""
        d = lib.embra_default_constraint_batch_def()
        d.kind = _enum(kind, KINDS, "kind")
        arity = lib.embra_constraint_arity(d.kind)
        if arity:
            buf.check_rows(particles, arity, "particles")
        p, n, keep_p = buf.ints_in(particles, "particles")
        if arity and n % arity:
            raise ValueError(f"particles: {n} indices is not a whole number of {arity}-tuples")
        count = n // arity if arity else n
        d.count, d.particles = buf.int32(count, "count"), p
        keep = [keep_p]
        if rest is not None:
            r, m, k = buf.doubles_in(rest, "rest")
            if m != count:
                raise ValueError(f"rest: {m} values for {count} constraints")
            d.rest = r
            keep.append(k)
        if compliances is not None:
            c, m, k = buf.doubles_in(compliances, "compliances")
            if m != count:
                raise ValueError(f"compliances: {m} values for {count} constraints")
            d.compliances = c
            keep.append(k)
        d.compliance = float(compliance)
        d.group = _id(group, GroupId, "group")
        self._call("embra_constraints_add", byref(d))
        return count

    def add_rigid_set(self, particles, compliance=0.0, group=None):
        """Keeps three or more points (particle indices) in their current shape, moving as one rigid
        body (embra_rigid_set_add): bracing by distance constraints to a base of three or four of
        them, with the base's volume (solid) or each point's offset from its plane (flat). Returns
        how many constraints were added (4 n - 9)."""
        p, n, keep = buf.ints_in(particles, "particles")
        added = c_int32(0)
        self._call("embra_rigid_set_add", _id(group, GroupId, "group"), p, buf.int32(n, "count"), float(compliance),
                   byref(added))
        return added.value

    def add_shape_match(self, particles, compliance=0.0, group=None):
        """Shape matching (embra_shape_match_add): three or more points (particle indices), not on one
        line, pulled every projection toward the best-fit rigid placement (mass-weighted, proper
        rotation) of their current shape. compliance in m/N (0 = hard). Returns its index among the
        group's shape matches."""
        p, n, keep = buf.ints_in(particles, "particles")
        index = c_int32(0)
        self._call("embra_shape_match_add", _id(group, GroupId, "group"), p, buf.int32(n, "count"), float(compliance),
                   byref(index))
        return index.value

    def remove_shape_match(self, index, group=None):
        """Removes shape match `index` of the group (embra_shape_match_remove); later ones move down."""
        self._call("embra_shape_match_remove", _id(group, GroupId, "group"), buf.int32(index, "index"))

    def shape_match_count(self, group=None):
        """How many shape matches the group holds (embra_group_get_shape_match_count)."""
        count = c_int32(0)
        self._call("embra_group_get_shape_match_count", _id(group, GroupId, "group"), byref(count))
        return count.value

    def add_polygon_planarity(self, particles, compliance=0.0, group=None):
        """Holds a polygon of four or more corners (particle indices in order round it) in one plane
        (embra_polygon_planarity_add): planarity constraints of rest 0 on its windows of four
        consecutive corners, all of them cyclically for more than four. Returns how many were added."""
        p, n, keep = buf.ints_in(particles, "particles")
        added = c_int32(0)
        self._call("embra_polygon_planarity_add", _id(group, GroupId, "group"), p, buf.int32(n, "count"),
                   float(compliance), byref(added))
        return added.value

    # Edits of one constraint, named as the diagnostics name it: group (None: the default group), kind
    # and index among the group's constraints of that kind (those bodies generated first, then the
    # added ones in the order added). Only added constraints are edited; a body's follow its material.
    def constraint_count(self, group, kind):
        """(count, generated): the group's constraints of `kind` and how many of them bodies generated."""
        n, g = c_int32(), c_int32()
        self._call("embra_group_get_constraint_count", _id(group, GroupId, "group"), _enum(kind, KINDS, "kind"),
                   byref(n), byref(g))
        return n.value, g.value

    def constraint(self, group, kind, index):
        """One constraint as a dict: kind, group, particles (its arity), rest, compliance."""
        d = ConstraintDef()
        k = _enum(kind, KINDS, "kind")
        self._call("embra_constraint_get", _id(group, GroupId, "group"), k, buf.int32(index, "index"), byref(d))
        arity = lib.embra_constraint_arity(d.kind)
        return {"kind": d.kind, "group": GroupId(d.group.index, d.group.generation),
                "particles": tuple(d.particles[:arity]), "rest": d.rest, "compliance": d.compliance}

    def set_constraint_compliance(self, group, kind, index, compliance):
        self._call("embra_constraint_set_compliance", _id(group, GroupId, "group"), _enum(kind, KINDS, "kind"),
                   buf.int32(index, "index"), float(compliance))

    def set_constraint_rest(self, group, kind, index, rest):
        self._call("embra_constraint_set_rest", _id(group, GroupId, "group"), _enum(kind, KINDS, "kind"),
                   buf.int32(index, "index"), float(rest))

    def set_constraint_plasticity(self, group, kind, index, yield_strain, rupture):
        """Plasticity and rupture of an added distance or dihedral (embra_constraint_set_plasticity):
        past `yield_strain` its rest follows it, past `rupture` it breaks (see broken()); 0: never."""
        self._call("embra_constraint_set_plasticity", _id(group, GroupId, "group"), _enum(kind, KINDS, "kind"),
                   buf.int32(index, "index"), float(yield_strain), float(rupture))

    def constraint_plasticity(self, group, kind, index):
        """(yield, rupture) of a constraint (embra_constraint_get_plasticity); 0 is none."""
        y, r = c_double(), c_double()
        self._call("embra_constraint_get_plasticity", _id(group, GroupId, "group"), _enum(kind, KINDS, "kind"),
                   buf.int32(index, "index"), byref(y), byref(r))
        return y.value, r.value

    def broken(self):
        """The constraints broken since the last call (embra_world_get_broken), in the order they
        broke: a list of dicts {group (GroupId), kind (name), index, particles, frame, strain}; the
        world's list is emptied."""
        n = c_int32()
        self._call("embra_world_get_broken", None, 0, byref(n))
        out = (_capi.BrokenConstraint * max(n.value, 1))()
        self._call("embra_world_get_broken", out, max(n.value, 1), byref(n))
        names = {v: k for k, v in KINDS.items()}
        return [{"group": GroupId(b.group.index, b.group.generation), "kind": names.get(b.kind, b.kind),
                 "index": b.index, "particles": [p for p in b.particles if p >= 0], "frame": b.frame,
                 "strain": b.strain} for b in out[:n.value]]

    def set_constraint_group(self, group, kind, index, to):
        """Moves the constraint to the end of group `to`'s; returns its index there."""
        at = c_int32()
        self._call("embra_constraint_set_group", _id(group, GroupId, "group"), _enum(kind, KINDS, "kind"),
                   buf.int32(index, "index"), _id(to, GroupId, "to"), byref(at))
        return at.value

    def remove_constraint(self, group, kind, index):
        """Removes the constraint; those after it in its group move down by one."""
        self._call("embra_constraint_remove", _id(group, GroupId, "group"), _enum(kind, KINDS, "kind"),
                   buf.int32(index, "index"))

    # --- pins ----------------------------------------------------------------------------------
    def create_pin(self, particle, target, compliance=0.0, group=None):
        """Holds `particle` at `target` (m); compliance 0 = hard, > 0 (m/N) a soft pin in `group`."""
        d = lib.embra_default_pin_def()
        d.particle = buf.int32(particle, "particle")
        d.target = buf.d3(target, "target")
        d.compliance = float(compliance)
        d.group = _id(group, GroupId, "group")
        pin = PinId()
        self._call("embra_pin_create", byref(d), byref(pin))
        return pin

    def create_support(self, particle, target, support="plane", axis=(0.0, 0.0, 1.0), compliance=0.0, group=None):
        """A frictionless sliding support (embra_support_create): `particle` held on the plane through
        `target` (m) normal to `axis` ("plane"), or on the line through it along `axis` ("line"); or a
        per-axis anchor ("axes", a roller): the world coordinates whose `axis` component is 1 held at
        the target's, those with 0 free ((0, 0, 1): z held); compliance 0 = hard, > 0 m/N; projected
        in `group`. Returns its PinId."""
        d = lib.embra_default_support_def()
        d.particle = buf.int32(particle, "particle")
        d.support = _enum(support, PIN_SUPPORTS, "support")
        d.target = buf.d3(target, "target")
        d.axis = buf.d3(axis, "axis")
        d.compliance = float(compliance)
        d.group = _id(group, GroupId, "group")
        pin = PinId()
        self._call("embra_support_create", byref(d), byref(pin))
        return pin

    def create_polyline_support(self, particle, points, target=(0.0, 0.0, 0.0), closed=False, compliance=0.0,
                                group=None):
        """A frictionless support on a polyline (embra_polyline_support_create): `particle` held on the
        closest point of the polyline through `points` ((n, 3), m, offsets from `target`, so
        set_pin_target moves the curve); `closed` joins its ends; compliance 0 = hard, > 0 m/N;
        projected in `group`. Returns its PinId."""
        d = lib.embra_default_polyline_support_def()
        d.particle = buf.int32(particle, "particle")
        d.target = buf.d3(target, "target")
        d.closed = 1 if closed else 0
        d.compliance = float(compliance)
        d.group = _id(group, GroupId, "group")
        buf.check_rows(points, 3, "points")
        p, n, keep = buf.doubles_in(points, "points")
        if n % 3:
            raise ValueError(f"points: {n} numbers is not a whole number of xyz triples")
        d.points, d.point_count = p, buf.int32(n // 3, "point count")
        pin = PinId()
        self._call("embra_polyline_support_create", byref(d), byref(pin))
        return pin

    def create_mesh_support(self, particle, vertices, triangles, target=(0.0, 0.0, 0.0), compliance=0.0,
                            group=None):
        """A frictionless support on a triangle mesh (embra_mesh_support_create): `particle` held on the
        closest point of the mesh (`vertices` (n, 3), m, offsets from `target`, so set_pin_target
        moves the mesh; `triangles` (t, 3), 0-based); compliance 0 = hard, > 0 m/N; projected in
        `group`. Returns its PinId."""
        d = lib.embra_default_mesh_support_def()
        d.particle = buf.int32(particle, "particle")
        d.target = buf.d3(target, "target")
        d.compliance = float(compliance)
        d.group = _id(group, GroupId, "group")
        buf.check_rows(vertices, 3, "vertices")
        buf.check_rows(triangles, 3, "triangles")
        v, nv, keep_v = buf.doubles_in(vertices, "vertices")
        t, nt, keep_t = buf.ints_in(triangles, "triangles")
        if nv % 3:
            raise ValueError(f"vertices: {nv} numbers is not a whole number of xyz triples")
        if nt % 3:
            raise ValueError(f"triangles: {nt} indices is not a whole number of triangles")
        d.vertices, d.vertex_count = v, buf.int32(nv // 3, "vertex count")
        d.triangles, d.triangle_count = t, buf.int32(nt // 3, "triangle count")
        pin = PinId()
        self._call("embra_mesh_support_create", byref(d), byref(pin))
        del keep_v, keep_t
        return pin

    def polyline_support_points(self, pin):
        """A polyline support's points as created (embra_polyline_support_get_points): a list of
        (x, y, z) offsets from its target (m); set_pin_target moves the target, not these, so the
        curve's world points are pin_target(pin) plus each. Refused for a pin that is not one."""
        p = _id(pin, PinId, "pin")
        n = c_int32()
        self._call("embra_polyline_support_get_points", p, None, 0, byref(n))
        out = (c_double * max(3 * n.value, 1))()
        self._call("embra_polyline_support_get_points", p, out, n.value, byref(n))
        return [tuple(out[3 * i:3 * i + 3]) for i in range(n.value)]

    def destroy_pin(self, pin):
        self._call("embra_pin_destroy", _id(pin, PinId, "pin"))

    def set_pin_target(self, pin, target):
        self._call("embra_pin_set_target", _id(pin, PinId, "pin"), buf.d3(target, "target"))

    def pin_target(self, pin):
        out = (c_double * 3)()
        self._call("embra_pin_get_target", _id(pin, PinId, "pin"), out)
        return tuple(out)

    def pin_particle(self, pin):
        out = c_int32()
        self._call("embra_pin_get_particle", _id(pin, PinId, "pin"), byref(out))
        return out.value

    # --- colliders -----------------------------------------------------------------------------
    def create_collider(self, shape, *, vertices=None, triangles=None, **fields):
        """A collider: shape ("plane", "sphere", "box", "capsule", "convex", "mesh" or its number),
        ColliderDef fields as keywords (position, rotation {w,x,y,z}, radius, half_extents, ...),
        and for convex and mesh shapes their local vertices (and triangles)."""
        d = lib.embra_default_collider_def()
        d.shape = _enum(shape, SHAPES, "shape")
        _fill(d, fields, "ColliderDef")
        keep = []
        if vertices is not None:
            buf.check_rows(vertices, 3, "vertices")
            p, n, k = buf.doubles_in(vertices, "vertices")
            if n % 3:
                raise ValueError(f"vertices: {n} numbers is not a whole number of xyz triples")
            d.vertices, d.vertex_count = p, buf.int32(n // 3, "vertex count")
            keep.append(k)
        if triangles is not None:
            buf.check_rows(triangles, 3, "triangles")
            p, n, k = buf.ints_in(triangles, "triangles")
            if n % 3:
                raise ValueError(f"triangles: {n} indices is not a whole number of triples")
            d.triangles, d.triangle_count = p, buf.int32(n // 3, "triangle count")
            keep.append(k)
        c = ColliderId()
        self._call("embra_collider_create", byref(d), byref(c))
        return c

    def destroy_collider(self, collider):
        self._call("embra_collider_destroy", _id(collider, ColliderId, "collider"))

    def set_collider_transform(self, collider, position, rotation=(1.0, 0.0, 0.0, 0.0)):
        self._call("embra_collider_set_transform", _id(collider, ColliderId, "collider"),
                   buf.d3(position, "position"), buf.d4(rotation, "rotation"))

    def collider_transform(self, collider):
        """(position, rotation {w, x, y, z}) where the collider is now (scene actions included)."""
        p, q = (c_double * 3)(), (c_double * 4)()
        self._call("embra_collider_get_transform", _id(collider, ColliderId, "collider"), p, q)
        return tuple(p), tuple(q)

    # --- fields --------------------------------------------------------------------------------
    def _create_field(self, default, create, what, fields):
        d = getattr(lib, default)()
        _fill(d, fields, what)
        f = FieldId()
        self._call(create, byref(d), byref(f))
        return f

    def create_wind(self, **fields):
        """A wind field from embra_default_wind_def() and WindDef fields as keywords (body: a Body or
        BodyId, None = every body; direction, speed, air_density, drag, lift). Returns its FieldId."""
        return self._create_field("embra_default_wind_def", "embra_wind_create", "WindDef", fields)

    def create_pressure(self, **fields):
        """Air pressure on a closed body (required: body) and, with keep_volume=1, a held volume:
        PressureDef fields as keywords (inside_pressure, outside_pressure, volume_compliance,
        rest_volume). Returns its FieldId."""
        return self._create_field("embra_default_pressure_def", "embra_pressure_create", "PressureDef", fields)

    def create_surface_tension(self, **fields):
        """A soap-film tension on a body's triangles (required: body; tension, regularisation).
        Returns its FieldId."""
        return self._create_field("embra_default_surface_tension_def", "embra_surface_tension_create",
                                  "SurfaceTensionDef", fields)

    def create_vortex(self, **fields):
        """A decaying torsion field about an axis: VortexDef fields as keywords (body, None = every
        particle; center, axis, strength, radius, twist, decay, start_time). Returns its FieldId."""
        return self._create_field("embra_default_vortex_def", "embra_vortex_create", "VortexDef", fields)

    def _field(self, get, cls, field):
        d = cls()
        self._call(get, _id(field, FieldId, "field"), byref(d))
        return d

    def _set_field(self, get, set_, cls, what, field, fields):
        d = _fill(self._field(get, cls, field), fields, what)  # the field's parameters, those given changed
        self._call(set_, _id(field, FieldId, "field"), byref(d))

    def wind(self, field):
        """A wind field's WindDef (embra_wind_get)."""
        return self._field("embra_wind_get", WindDef, field)

    def set_wind(self, field, **fields):
        """Changes the given WindDef fields of a wind field from the next step on (embra_wind_set)."""
        self._set_field("embra_wind_get", "embra_wind_set", WindDef, "WindDef", field, fields)

    def pressure(self, field):
        return self._field("embra_pressure_get", PressureDef, field)

    def set_pressure(self, field, **fields):
        self._set_field("embra_pressure_get", "embra_pressure_set", PressureDef, "PressureDef", field, fields)

    def surface_tension(self, field):
        return self._field("embra_surface_tension_get", SurfaceTensionDef, field)

    def set_surface_tension(self, field, **fields):
        self._set_field("embra_surface_tension_get", "embra_surface_tension_set", SurfaceTensionDef,
                        "SurfaceTensionDef", field, fields)

    def vortex(self, field):
        return self._field("embra_vortex_get", VortexDef, field)

    def set_vortex(self, field, **fields):
        self._set_field("embra_vortex_get", "embra_vortex_set", VortexDef, "VortexDef", field, fields)

    def destroy_field(self, field):
        """Destroys a field; its id becomes stale."""
        self._call("embra_field_destroy", _id(field, FieldId, "field"))

    @property
    def field_count(self):
        """Number of live fields."""
        n = c_int32()
        self._call("embra_world_get_field_count", byref(n))
        return n.value

    # --- stepping and reading back -------------------------------------------------------------
    def step(self, frames=1):
        """Advances `frames` frames. NumericalError or CancelledError (cancel() from another thread):
        the world is as before the failing frame, and the frames before it stay stepped."""
        for _ in range(buf.int32(frames, "frames")):
            self._call("embra_world_step")

    def solve(self, until="tolerance", max_frames=None, hold_frames=None, max_seconds=None):
        """Steps until the world is at rest (until="settled") and, with until="tolerance", every panel
        mesh within its tolerance targets, or max_frames frames (default 1000) or max_seconds of wall
        time have passed (embra_world_solve). Returns a Solved: why it stopped (outcome
        "settled_within_tolerance", "settled_out_of_tolerance", "oscillating" or "drifting"), the
        frames stepped, the period (s) of an oscillation and the worst fabrication metric and where."""
        d = lib.embra_default_solve_def()
        d.until = _enum(until, SOLVE_UNTIL, "until")
        if max_frames is not None:
            d.max_frames = buf.int32(max_frames, "max_frames")
        if hold_frames is not None:
            d.hold_frames = buf.int32(hold_frames, "hold_frames")
        if max_seconds is not None:
            d.max_seconds = float(max_seconds)
        r = SolveResult()
        self._call("embra_world_solve", byref(d), byref(r))
        return Solved(r)

    def residuals(self):
        """The last step's residuals by kind, each in its own unit (embra_world_get_residuals): a dict
        from the kind's name ("distance", "dihedral", ..., "pins", "contacts") to {"unit" ("m", "rad",
        "m^3"), "count", "max", "rms"}, for every kind the world holds, in kind order."""
        n = c_int32()
        self._call("embra_world_get_residuals", None, 0, byref(n))
        out = (KindResidual * max(n.value, 1))()
        self._call("embra_world_get_residuals", out, n.value, byref(n))
        return {lib.embra_residual_name(r.kind).decode(): {"unit": lib.embra_residual_unit(r.kind).decode(),
                                                           "count": r.count, "max": r.max, "rms": r.rms}
                for r in out[:n.value]}

    def worst_constraints(self, count=10):
        """The `count` constraints and soft pins of the last step that fight hardest, worst first
        (embra_world_get_worst_constraints: ranked by violation x force, an energy for every kind): a
        list of dicts {kind (a KINDS name, or "pins"), group, index (in the group's constraints of that
        kind, as added; -1 for a pin), pin (PinId or None), particles, residual and violation (in
        unit), unit, force (N; N m for angles, N/m^2 for volumes)}."""
        out = (ConstraintResidual * max(count, 1))()
        n = c_int32()
        self._call("embra_world_get_worst_constraints", out, buf.int32(count, "count"), byref(n))
        result = []
        for c in out[:n.value]:
            arity = 1 if c.kind == _capi.RESIDUAL_PINS else lib.embra_constraint_arity(c.kind)
            result.append({"kind": lib.embra_residual_name(c.kind).decode(),
                           "group": GroupId(c.group.index, c.group.generation), "index": c.index,
                           "pin": PinId(c.pin.index, c.pin.generation) if c.kind == _capi.RESIDUAL_PINS else None,
                           "particles": list(c.particles[:arity]), "residual": c.residual,
                           "violation": c.violation, "unit": lib.embra_residual_unit(c.kind).decode(),
                           "force": c.force})
        return result

    def group_conflicts(self):
        """Pairs of groups whose forces on shared particles oppose in the last step, largest first
        (embra_world_get_group_conflicts): a list of dicts {a, b (GroupIds, a first in the projection
        order), force (N), particles (where they point more than 120 degrees apart)}."""
        n = c_int32()
        self._call("embra_world_get_group_conflicts", None, 0, byref(n))
        out = (GroupConflict * max(n.value, 1))()
        self._call("embra_world_get_group_conflicts", out, n.value, byref(n))
        return [{"a": GroupId(c.a.index, c.a.generation), "b": GroupId(c.b.index, c.b.generation), "force": c.force,
                 "particles": c.particles} for c in out[:n.value]]

    def group_residuals(self, group, kind):
        """The residual of every constraint of `kind` in `group` after the last step, in the order they
        were added, in the kind's unit (embra_group_get_residuals): a list of floats."""
        return self._per_constraint("embra_group_get_residuals", group, kind)

    def constraint_forces(self, group, kind):
        """The force of every constraint of `kind` in `group` after the last step, in the order they
        were added (embra_group_get_forces): -lambda / h^2 of the last substep; for a distance or
        tether its tension in N (positive pulling its ends together). A list of floats."""
        return self._per_constraint("embra_group_get_forces", group, kind)

    def _per_constraint(self, name, group, kind):
        """One value per constraint of `kind` in `group`, through a two-call listing: a list of floats."""
        g, k = _id(group, GroupId, "group"), _enum(kind, KINDS, "kind")
        n = c_int64()
        self._call(name, g, k, None, 0, byref(n))
        out = (c_double * max(n.value, 1))()
        self._call(name, g, k, out, n.value, byref(n))
        return list(out[:n.value])

    def reactions(self):
        """The force (N) every live pin exerts on its particle after the last step
        (embra_world_get_reactions): a list of dicts {pin (PinId), particle, force ([x, y, z])}, pins in
        creation-slot order. At a static rest they sum to minus the weights and the point, area and
        line loads."""
        n = c_int32()
        self._call("embra_world_get_reactions", None, 0, byref(n))
        out = (Reaction * max(n.value, 1))()
        self._call("embra_world_get_reactions", out, n.value, byref(n))
        return [{"pin": PinId(r.pin.index, r.pin.generation), "particle": r.particle, "force": list(r.force)}
                for r in out[:n.value]]

    def collider_reactions(self):
        """The force (N) every live collider exerts on the world after the last step, from its contacts
        of the last substep, normal push and friction (embra_world_get_collider_reactions): a list of
        dicts {collider (ColliderId), contacts, force ([x, y, z], N), moment ([x, y, z], N m about the
        collider's position)}, colliders in creation-slot order. At a static rest they and the pins'
        reactions sum to minus the weights and the point, area and line loads."""
        n = c_int32()
        self._call("embra_world_get_collider_reactions", None, 0, byref(n))
        out = (ColliderReaction * max(n.value, 1))()
        self._call("embra_world_get_collider_reactions", out, n.value, byref(n))
        return [{"collider": ColliderId(r.collider.index, r.collider.generation), "contacts": r.contacts,
                 "force": list(r.force), "moment": list(r.moment)} for r in out[:n.value]]

    def report(self):
        r = StepReport()
        self._call("embra_world_get_report", byref(r))
        return r

    def warning(self):
        w = Warning()
        self._call("embra_world_get_warning", byref(w))
        return w

    def _read(self, name, first, count, out):
        first = buf.int32(first, "first")
        if count is None:
            count = max(self.particle_count - first, 0)
        count = buf.int32(count, "count")
        result, pointer, capacity, keep = buf.doubles_out(max(count, 0), out, "out")
        self._call(name, pointer, capacity, first, count)
        return result

    def positions(self, first=0, count=None, out=None):
        """Positions (m) of particles [first, first + count): numpy (count, 3) written in place by C
        when numpy is installed, else a flat array('d'); or into `out` (a writable double buffer)."""
        return self._read("embra_world_get_positions", first, count, out)

    def velocities(self, first=0, count=None, out=None):
        """Velocities (m/s), as positions()."""
        return self._read("embra_world_get_velocities", first, count, out)

    def _write(self, name, xyz, first):
        buf.check_rows(xyz, 3, "xyz")
        p, n, keep = buf.doubles_in(xyz, "xyz")
        if n % 3:
            raise ValueError(f"xyz: {n} numbers is not a whole number of xyz triples")
        self._call(name, p, buf.int32(first, "first"), buf.int32(n // 3, "count"))

    def set_positions(self, xyz, first=0):
        """Moves particles [first, first + len) to xyz (m); velocities are kept."""
        self._write("embra_world_set_positions", xyz, first)

    def set_velocities(self, xyz, first=0):
        self._write("embra_world_set_velocities", xyz, first)

    def loads(self, first=0, count=None, out=None):
        """Point loads (N) of particles [first, first + count), as positions()."""
        return self._read("embra_world_get_loads", first, count, out)

    def set_loads(self, xyz, first=0):
        """Sets point loads (N, one xyz row per particle) on particles [first, first + len): forces
        applied every substep beside gravity until set again."""
        self._write("embra_world_set_loads", xyz, first)

    def set_area_loads(self, loads):
        """Replaces the area loads (embra_world_set_area_loads) with `loads`, a list of dicts
        {particles: [a, b, c] (three distinct particles), pressure (Pa), mode ("normal", "true_area"
        or "projected_area"; default "normal"), direction ([x, y, z], the fixed modes')}: a third of
        each triangle's force on each corner, every substep beside gravity, until set again. An
        empty list removes them. Refused, changing nothing, as the C ABI refuses."""
        loads = list(loads)
        arr = (AreaLoad * max(len(loads), 1))()
        for i, l in enumerate(loads):
            corners = list(l["particles"])
            if len(corners) != 3:
                raise ValueError(f"loads[{i}].particles: expected 3 particles, got {len(corners)}")
            arr[i].particles = (c_int32 * 3)(*(buf.int32(c, f"loads[{i}].particles") for c in corners))
            arr[i].mode = _enum(l.get("mode", "normal"), AREA_LOAD_MODES, f"loads[{i}].mode")
            arr[i].pressure = float(l["pressure"])
            arr[i].direction = buf.d3(l.get("direction", (0.0, 0.0, -1.0)), f"loads[{i}].direction")
        self._call("embra_world_set_area_loads", arr, len(loads))

    def area_loads(self):
        """The area loads as set: a list of dicts {particles, mode (name), pressure, direction}."""
        n = c_int32()
        self._call("embra_world_get_area_loads", None, 0, byref(n))
        out = (AreaLoad * max(n.value, 1))()
        self._call("embra_world_get_area_loads", out, n.value, byref(n))
        return [{"particles": list(l.particles), "mode": AREA_LOAD_MODE_NAMES.get(l.mode, l.mode),
                 "pressure": l.pressure, "direction": list(l.direction)} for l in out[:n.value]]

    def set_line_loads(self, loads):
        """Replaces the line loads (embra_world_set_line_loads) with `loads`, a list of dicts
        {particles: [a, b] (two distinct particles), load ([x, y, z], N per m of the edge)}: half of
        each edge's force on each end, every substep beside gravity, until set again."""
        loads = list(loads)
        arr = (LineLoad * max(len(loads), 1))()
        for i, l in enumerate(loads):
            ends = list(l["particles"])
            if len(ends) != 2:
                raise ValueError(f"loads[{i}].particles: expected 2 particles, got {len(ends)}")
            arr[i].particles = (c_int32 * 2)(*(buf.int32(c, f"loads[{i}].particles") for c in ends))
            arr[i].load = buf.d3(l["load"], f"loads[{i}].load")
        self._call("embra_world_set_line_loads", arr, len(loads))

    def line_loads(self):
        """The line loads as set: a list of dicts {particles, load}."""
        n = c_int32()
        self._call("embra_world_get_line_loads", None, 0, byref(n))
        out = (LineLoad * max(n.value, 1))()
        self._call("embra_world_get_line_loads", out, n.value, byref(n))
        return [{"particles": list(l.particles), "load": list(l.load)} for l in out[:n.value]]

    # --- JSON scenes ---------------------------------------------------------------------------
    def save_json(self):
        """The world as scene JSON text (complete: loading it steps on bit-identically)."""
        n = c_int64()
        self._call("embra_world_save_json", None, 0, byref(n))
        out = (c_char * n.value)()
        self._call("embra_world_save_json", out, n.value, byref(n))
        return out.raw[:n.value - 1].decode("utf-8")

    def save_file(self, path):
        self._call("embra_world_save_file", str(path).encode())

    # --- OBJ -----------------------------------------------------------------------------------
    def export_obj(self):
        """The world as Wavefront OBJ text (embra_world_export_obj): every particle as a `v` line in
        world order, each body's triangles as `f` lines, a body without triangles (a hanging net)
        as `l` lines of its edges."""
        n = c_int64()
        self._call("embra_world_export_obj", None, 0, byref(n))
        out = (c_char * n.value)()
        self._call("embra_world_export_obj", out, n.value, byref(n))
        return out.raw[:n.value - 1].decode("utf-8")

    def write_obj(self, path):
        """Writes export_obj()'s text to the file `path` (replaced whole; no partial file on failure)."""
        self._call("embra_world_write_obj", os.fsencode(path))

    def scene_frames(self):
        f = c_int64()
        self._call("embra_world_get_scene_frames", byref(f))
        return f.value


class Solved:
    """What World.solve found. outcome: "settled_within_tolerance", "settled_out_of_tolerance",
    "oscillating" or "drifting"; frames: stepped by the call; period: s, for an oscillation (else 0);
    worst: None without a panel mesh (and every residual within its target), else a dict of the metric
    furthest above its target (value / target): metric (a PANEL_METRICS name), body (BodyId), element
    (panel, or joint for "miter"), layer ("top", "bottom" or None), value and target (1 - n1.n2 for
    planarity, else m); or, for a kind's constraint residual above its target (embra.h
    EMBRA_SOLVE_RESIDUAL_TARGET_*), metric "residual", kind (its name), unit, value and target."""

    def __init__(self, r):
        self.outcome = SOLVE_OUTCOMES[r.outcome]
        self.frames = r.frames
        self.period = r.period
        self.settled = r.outcome <= _capi.SOLVE_SETTLED_OUT_OF_TOLERANCE
        self.worst = None
        if r.worst_metric == _capi.SOLVE_WORST_RESIDUAL:
            self.worst = {"metric": "residual", "kind": lib.embra_residual_name(r.worst_element).decode(),
                          "unit": lib.embra_residual_unit(r.worst_element).decode(),
                          "value": r.worst_value, "target": r.worst_target}
        elif r.worst_metric >= 0:
            names = {v: k for k, v in PANEL_METRICS.items()}
            self.worst = {"metric": names[r.worst_metric], "body": BodyId(r.worst_body.index, r.worst_body.generation),
                          "element": r.worst_element, "layer": {0: "top", 1: "bottom"}.get(r.worst_layer),
                          "value": r.worst_value, "target": r.worst_target}

    def __repr__(self):
        text = f"Solved({self.outcome}, frames={self.frames}"
        if self.outcome == "oscillating":
            text += f", period={self.period:.6g} s"
        if self.worst is not None and self.worst["metric"] == "residual":
            w = self.worst
            text += f", worst={w['kind']} residual {w['value']:.3e} {w['unit']} (target {w['target']:.3e})"
        elif self.worst is not None:
            w = self.worst
            layer = f" {w['layer']}" if w["layer"] else ""
            text += (f", worst={w['metric']} {w['value']:.3e} (target {w['target']:.3e}) at "
                     f"{'joint' if w['metric'] == 'miter' else 'panel'} {w['element']}{layer}")
        return text + ")"


__all__ = ["World", "Body", "Solved", "as_dict", "SHAPES", "KINDS", "GENERATE", "PANEL_PINS", "PANEL_CORNERS", "PANEL_PRECISION", "PANEL_METRICS",
           "CUTS_FORMATS", "SOLVE_UNTIL", "EmbraError"]
