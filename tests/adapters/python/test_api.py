"""The Python adapter covers the whole C ABI, and each part of it does what the header says."""

import ctypes
import math
import os
import re
import struct

import pytest

import embra
from embra import _capi
from tent import flat


def test_every_prototype_is_loaded():
    """Every function of the generated prototype table is loaded from the library with its types."""
    assert len(_capi.PROTOTYPES) > 40
    for name, (restype, argtypes) in _capi.PROTOTYPES.items():
        fn = getattr(_capi.lib, name)
        assert fn.restype is restype and list(fn.argtypes or []) == argtypes, name


def test_every_status_has_its_own_error():
    """Each EMBRA_ERROR_* code of embra.h raises its own exception class, which names that status."""
    from embra import errors
    statuses = {name: value for name, value in vars(_capi).items() if name.startswith("ERROR_")}
    assert {"ERROR_LOCKED", "ERROR_CANCELLED"} <= set(statuses)
    classes = set()
    for name, value in statuses.items():
        e = errors.error_for(value, "message")
        assert type(e) is not embra.EmbraError and isinstance(e, embra.EmbraError), name
        assert e.status == value and e.status_name == "EMBRA_" + name and e.message == "message"
        classes.add(type(e))
    assert len(classes) == len(statuses)
    assert isinstance(errors.error_for(_capi.ERROR_LOCKED, ""), embra.LockedError)
    assert isinstance(errors.error_for(_capi.ERROR_CANCELLED, ""), embra.CancelledError)
    assert embra.status_name(_capi.ERROR_CANCELLED) == "EMBRA_ERROR_CANCELLED"


def test_versions():
    v = embra.version()
    major, minor, patch = (int(x) for x in embra.version_string().split("."))
    assert v == major * 10000 + minor * 100 + patch
    assert embra.abi_version() == embra.ABI_VERSION
    embra.check_abi()
    with pytest.raises(embra.VersionError, match="embra_check_abi"):
        embra.check_abi(embra.ABI_VERSION + 1)
    assert embra.status_name(-2) == "EMBRA_ERROR_STALE_ID"
    assert embra.status_name(0) == "EMBRA_OK"


def test_defaults_are_the_documented_ones():
    s = embra.default_solver_def()
    assert (s.version, s.substeps, s.iterations, s.tethers, s.realign_passes, s.chain_solve, s.threads) == \
        (2, 16, 1, 2, 0, 1, 1)
    assert s.dt == 1.0 / 60.0 and tuple(s.gravity) == (0.0, 0.0, -9.81) and s.settle_speed == 1e-3
    m = embra.default_material()
    assert (m.mass, m.density, m.stretch_compliance, m.bend_compliance) == (0.0, 1.0, 0.0, 1.0)
    assert (m.friction_static, m.friction_dynamic) == (0.5, 0.3)
    assert [embra.constraint_arity(k) for k in ("distance", "edge_angle", "dihedral", "tet_volume", "weld",
                                                "tether", "planarity", "plane_offset", "equal_length",
                                                "conical", "length_min", "angle_min", "angle_max",
                                                "colinear", "direction", "cocircular", "cospherical")] == \
        [2, 3, 4, 4, 2, 2, 4, 4, 4, 5, 2, 3, 3, 3, 4, 4, 5]


def test_free_fall_is_symplectic_euler_in_closed_form():
    """One free particle: after N substeps of h, z = z0 + h^2 g N (N + 1) / 2 exactly (v0 = 0)."""
    with embra.World(gravity=(0.0, 0.0, -9.81), substeps=10) as w:
        body = w.create_body([(0.0, 0.0, 5.0)], mass=2.0)
        w.step(30)
        n, h = 300, (1.0 / 60.0) / 10
        z = flat(w.positions(body.first, 1))[2]
        assert abs(z - (5.0 - 9.81 * h * h * n * (n + 1) / 2)) < 1e-10  # rounding over 300 substeps
        vz = flat(w.velocities(body.first, 1))[2]
        assert abs(vz - (-9.81 * n * h)) < 1e-9  # v = (x - x_prev) / h: rounding over h
        r = w.report()
        assert r.frame == 30 and abs(r.time - 0.5) < 1e-12
        assert abs(r.kinetic_energy - 0.5 * 2.0 * vz * vz) < 1e-9


def test_equal_length_splits_a_pinned_line_evenly():
    """Four links between fixed ends, neighbours held equal (sharing a particle): a quarter each."""
    xyz = [(0.0, 0.0, 0.0), (0.1, 0.0, 0.0), (0.5, 0.0, 0.0), (0.6, 0.0, 0.0), (1.0, 0.0, 0.0)]
    with embra.World(gravity=(0.0, 0.0, 0.0), substeps=4, iterations=4, damping=20.0, tethers=0) as w:
        w.create_body(xyz, generate=0, masses=[0.0, 1.0, 2.0, 0.5, 0.0])
        assert w.add_constraints("equal_length", [(0, 1, 1, 2), (1, 2, 2, 3), (2, 3, 3, 4)], rest=[0.0] * 3) == 3
        w.step(200)
        p = flat(w.positions())
        for i in range(4):
            assert abs(math.dist(p[3 * i:3 * i + 3], p[3 * i + 3:3 * i + 6]) - 0.25) < 1e-9


def test_polygon_planarity_flattens_a_skew_hexagon():
    """A hexagon with its corners up and down in turn, held planar (six windows of four corners):
    every corner ends on the plane through corners 0, 2 and 4, and a range 0.3 <= |x0 - x3| (a
    length_min) is met."""
    xyz = [(math.cos(k * math.pi / 3), math.sin(k * math.pi / 3), 0.2 if k % 2 == 0 else -0.2) for k in range(6)]
    with embra.World(gravity=(0.0, 0.0, 0.0), substeps=4, iterations=10) as w:
        w.create_body(xyz, generate=0, masses=[1.0] * 6)
        assert w.add_polygon_planarity(range(6)) == 6
        assert w.add_constraints("length_min", [(0, 3)], rest=[2.5]) == 1
        w.step(60)
        p = [flat(w.positions())[3 * k:3 * k + 3] for k in range(6)]
        a = [p[2][i] - p[0][i] for i in range(3)]
        b = [p[4][i] - p[0][i] for i in range(3)]
        n = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
        ln = math.sqrt(sum(v * v for v in n))
        for k in range(6):
            assert abs(sum((p[k][i] - p[0][i]) * n[i] for i in range(3)) / ln) < 1e-9
        assert math.dist(p[0], p[3]) >= 2.5 - 1e-9
        with pytest.raises(embra.EmbraError, match="twice"):
            w.add_polygon_planarity([0, 1, 2, 1])


def test_rigid_set_keeps_its_shape_while_it_falls_and_turns():
    """Six points braced rigid (4 n - 9 = 15 constraints), one corner pinned, 60 frames of gravity at
    4 x 40 iterations: every pairwise distance as it was to 1e-6 m; points on one line are refused."""
    xyz = [(0, 0, 1), (0.4, 0, 1), (0, 0.4, 1), (0, 0, 1.4), (0.3, 0.3, 1.3), (-0.2, 0.1, 1.2)]
    with embra.World(gravity=(0.0, 0.0, -9.81), substeps=4, iterations=40, tethers=0) as w:
        w.create_body(xyz, generate=0, masses=[1.0] * 6)
        assert w.add_rigid_set(range(6)) == 15
        w.create_pin(0, xyz[0])
        w.step(60)
        p = [flat(w.positions())[3 * k:3 * k + 3] for k in range(6)]
        assert math.dist(p[4], xyz[4]) > 0.05  # it turned
        for i in range(6):
            for j in range(i + 1, 6):
                assert abs(math.dist(p[i], p[j]) - math.dist(xyz[i], xyz[j])) < 1e-6
    with embra.World() as w:
        w.create_body([(0, 0, 0), (1, 0, 0), (2, 0, 0)], generate=0, masses=[1.0] * 3)
        with pytest.raises(embra.EmbraError, match="line"):
            w.add_rigid_set([0, 1, 2])


def test_shape_match_keeps_a_falling_spinning_set_rigid():
    """Six points under one hard shape match, thrown spinning: after 60 frames every pairwise
    distance as it was to 1e-9 m, and their mass-weighted centre where a loose particle thrown with
    it is (1e-9 m); points on one line are refused; remove takes it away."""
    xyz = [(0, 0, 1), (0.4, 0, 1), (0, 0.4, 1), (0, 0, 1.4), (0.3, 0.3, 1.3), (-0.2, 0.1, 1.2)]
    masses = [1.0, 2.0, 0.5, 1.5, 1.0, 0.8]
    with embra.World(gravity=(0.0, 0.0, -9.81), tethers=0) as w:
        w.create_body(xyz + [(0, 0, 0)], generate=0, masses=masses + [1.0])
        assert w.add_shape_match(range(6)) == 0
        c = [sum(m * p[k] for m, p in zip(masses, xyz)) / sum(masses) for k in range(3)]
        v = []
        for p in xyz:  # 1 m/s along x plus 4 rad/s about z through the centre
            v += [1.0 - 4.0 * (p[1] - c[1]), 4.0 * (p[0] - c[0]), 2.0]
        w.set_positions(c, first=6)
        w.set_velocities(v + [1.0, 0.0, 2.0])
        w.step(60)
        p = [flat(w.positions())[3 * k:3 * k + 3] for k in range(7)]
        for i in range(6):
            for j in range(i + 1, 6):
                assert abs(math.dist(p[i], p[j]) - math.dist(xyz[i], xyz[j])) < 1e-9
        centre = [sum(m * q[k] for m, q in zip(masses, p)) / sum(masses) for k in range(3)]
        assert math.dist(centre, p[6]) < 1e-9
        assert w.shape_match_count() == 1
        w.remove_shape_match(0)
        assert w.shape_match_count() == 0
    with embra.World() as w:
        w.create_body([(0, 0, 0), (1, 0, 0), (2, 0, 0)], generate=0, masses=[1.0] * 3)
        with pytest.raises(embra.EmbraError, match="line"):
            w.add_shape_match([0, 1, 2])


def test_statics_two_bar_truss_forces_and_reactions():
    """A load hung from two pins by two hard bars at 45 degrees: each bar carries the load over
    2 sin 45 (tension, N), and the pins' reactions sum to minus every weight and point load."""
    xyz = [(-1.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 0.0, -1.0)]
    with embra.World(gravity=(0.0, 0.0, -9.81), substeps=4, iterations=20, damping=5.0, tethers=0,
                     realign_passes=2) as w:
        w.create_body(xyz, generate=0, masses=[1.0, 1.5, 2.0])
        w.add_constraints("distance", [(0, 2), (1, 2)])
        pins = [w.create_pin(0, xyz[0]), w.create_pin(1, xyz[1])]
        w.set_loads([(0.0, 0.0, -10.0)], first=2)
        assert list(flat(w.loads())) == [0.0] * 6 + [0.0, 0.0, -10.0]
        w.step(200)
        down = 2.0 * 9.81 + 10.0
        for t in w.constraint_forces(w.default_group(), "distance"):
            assert abs(t - down / math.sqrt(2.0)) < 1e-9 * down
        r = w.reactions()
        assert [x["pin"] for x in r] == pins and [x["particle"] for x in r] == [0, 1]
        total = [sum(x["force"][k] for x in r) for k in range(3)]
        assert abs(total[0]) < 1e-9 * down and abs(total[1]) < 1e-9 * down
        assert abs(total[2] - (4.5 * 9.81 + 10.0)) < 1e-9 * down
        with pytest.raises(embra.EmbraError):
            w.constraint_forces(w.default_group(), "weld")
        with pytest.raises((ValueError, embra.EmbraError)):
            w.set_loads([(0.0, float("nan"), 0.0)], first=0)
        assert list(flat(w.loads()))[:3] == [0.0, 0.0, 0.0]


def test_collider_reactions_carry_what_rests_on_a_ground_plane():
    """Three loose particles (1, 1.5, 2 kg) resting on the ground plane z = 0, one with a point load
    whose horizontal part friction holds: the plane's force is minus every weight and load, and its
    moment about its origin minus the loads' moment (N, N m, to 1e-9 relative)."""
    xyz = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)]
    masses = [1.0, 1.5, 2.0]
    with embra.World(gravity=(0.0, 0.0, -9.81), substeps=4, iterations=20, damping=5.0, tethers=0,
                     realign_passes=2) as w:
        floor = w.create_collider("plane", position=(0.0, 0.0, 0.0))
        w.create_body(xyz, generate=0, masses=masses)
        w.set_loads([(0.5, 0.0, -2.0)], first=2)
        w.step(50)
        loads = [(0.0, 0.0, -9.81 * m) for m in masses]
        loads[2] = (0.5, 0.0, -9.81 * masses[2] - 2.0)
        total = [sum(f[k] for f in loads) for k in range(3)]
        q = list(flat(w.positions()))
        moment = [0.0, 0.0, 0.0]
        for x, f in zip([q[3 * i:3 * i + 3] for i in range(3)], loads):
            moment = [moment[0] + x[1] * f[2] - x[2] * f[1], moment[1] + x[2] * f[0] - x[0] * f[2],
                      moment[2] + x[0] * f[1] - x[1] * f[0]]
        r = w.collider_reactions()
        assert len(r) == 1 and r[0]["collider"] == floor and r[0]["contacts"] == 3
        scale = math.hypot(*total)
        assert max(abs(r[0]["force"][k] + total[k]) for k in range(3)) < 1e-9 * scale
        assert max(abs(r[0]["moment"][k] + moment[k]) for k in range(3)) < 1e-9 * math.hypot(*moment)
        assert w.reactions() == []
        # Saved and loaded (the scene's state.forces), the plane reads the same force before a step.
        with embra.World.load_json(w.save_json()) as loaded:
            again = loaded.collider_reactions()
            assert [(c["force"], c["moment"], c["contacts"]) for c in again] == \
                [(c["force"], c["moment"], c["contacts"]) for c in r]


def test_area_and_line_loads_accelerate_free_particles_and_read_back():
    """A free triangle of three 0.5 kg particles (area 0.5 m^2) under a true-area load of 12 Pa along
    (0, 3, -4): each corner is pushed by 12 x 0.5 / 3 = 2 N along (0, 0.6, -0.8), 4 m/s^2, so after n
    substeps it has moved a h^2 n (n + 1) / 2 (symplectic Euler); a free edge of length 2 under a
    line load of (1, 0, 0) N/m: each end 1 N. Refusals change nothing."""
    tri = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)]
    edge = [(0.0, 0.0, 5.0), (2.0, 0.0, 5.0)]
    with embra.World(gravity=(0.0, 0.0, 0.0), substeps=4, iterations=1, tethers=0) as w:
        w.create_body(tri + edge, generate=0, masses=[0.5] * 5)
        w.set_area_loads([{"particles": [0, 1, 2], "mode": "true_area", "pressure": 12.0,
                           "direction": (0.0, 3.0, -4.0)}])
        w.set_line_loads([{"particles": [3, 4], "load": (1.0, 0.0, 0.0)}])
        assert w.area_loads() == [{"particles": [0, 1, 2], "mode": "true_area", "pressure": 12.0,
                                   "direction": [0.0, 3.0, -4.0]}]
        assert w.line_loads() == [{"particles": [3, 4], "load": [1.0, 0.0, 0.0]}]
        w.step(3)
        n, h = 12, (1.0 / 60.0) / 4
        s = h * h * n * (n + 1) / 2
        p = flat(w.positions())
        for i in range(3):
            moved = [p[3 * i + k] - tri[i][k] for k in range(3)]
            for k, u in enumerate((0.0, 0.6, -0.8)):
                assert abs(moved[k] - 4.0 * u * s) < 1e-12
        for i in range(2):
            assert abs(p[9 + 3 * i] - edge[i][0] - 2.0 * s) < 1e-12
        with pytest.raises(embra.EmbraError):
            w.set_area_loads([{"particles": [0, 1, 1], "pressure": 1.0}])
        with pytest.raises(embra.EmbraError):
            w.set_area_loads([{"particles": [0, 1, 2], "mode": "projected_area", "pressure": 1.0,
                               "direction": (0.0, 0.0, 0.0)}])
        with pytest.raises(embra.EmbraError):
            w.set_line_loads([{"particles": [3, 5], "load": (1.0, 0.0, 0.0)}])
        with pytest.raises(ValueError):
            w.set_area_loads([{"particles": [0, 1, 2], "mode": "plan", "pressure": 1.0}])
        assert w.area_loads()[0]["pressure"] == 12.0 and len(w.line_loads()) == 1
        w.set_area_loads([])
        w.set_line_loads([])
        assert w.area_loads() == [] and w.line_loads() == []


def _distance_to_polyline(pts, closed, q):
    best = math.inf
    n = len(pts)
    for s in range(n if closed else n - 1):
        a, b = pts[s], pts[(s + 1) % n]
        e = [b[k] - a[k] for k in range(3)]
        t = min(1.0, max(0.0, sum((q[k] - a[k]) * e[k] for k in range(3)) / sum(c * c for c in e)))
        best = min(best, math.dist(q, [a[k] + t * e[k] for k in range(3)]))
    return best


def test_polyline_support_holds_a_bead_on_a_circle():
    """A bead on a vertical circle-shaped polyline (48 segments, radius 0.6) under gravity swings and
    stays on it to 1e-9 m at every frame; a curve with a repeated point is refused."""
    pts = [(0.6 * math.cos(a), 0.0, 0.6 * math.sin(a))
           for a in (-math.pi / 2 + math.pi / 48 + 2 * math.pi * k / 48 for k in range(48))]
    with embra.World(gravity=(0.0, 0.0, -9.81), substeps=8, iterations=2, tethers=0) as w:
        w.create_body([(0.6, 0.0, 0.1)], generate=0, masses=[0.3])
        pin = w.create_polyline_support(0, pts, closed=True)
        low = math.inf
        for _ in range(60):
            w.step()
            q = list(flat(w.positions()))
            assert _distance_to_polyline(pts, True, q) < 1e-9
            low = min(low, q[2])
        assert low < -0.5, "it swung down"
        assert w.reactions()[0]["pin"] == pin
        with pytest.raises(embra.EmbraError):
            w.create_polyline_support(0, [pts[0], pts[0], pts[1]])
        assert w.counts().pins == 1


def test_polyline_support_points_read_back_and_move_with_the_target():
    """polyline_support_points returns the points exactly as created; set_pin_target moves the
    target (and so the curve) and leaves them as they are: the particle follows the moved curve."""
    pts = [(0.0, 0.0, 0.0), (1.0 / 3.0, 0.1, -0.2), (0.7, -0.4, 0.05)]
    with embra.World(gravity=(0.0, 0.0, 0.0), substeps=4, iterations=2, tethers=0) as w:
        w.create_body([(0.0, 0.0, 0.0), (1.0, 0.0, 0.0)], generate=0, masses=[1.0, 1.0])
        pin = w.create_polyline_support(0, pts, target=(0.0, 0.0, 0.0))
        plane = w.create_support(1, (0.0, 0.0, 0.0), "plane", compliance=1.0)
        assert w.polyline_support_points(pin) == pts
        shift = (0.25, -1.5, 2.0)
        w.set_pin_target(pin, shift)
        w.step(2)
        assert w.polyline_support_points(pin) == pts
        q = list(flat(w.positions()))[:3]
        curve = [[shift[k] + p[k] for k in range(3)] for p in pts]
        assert _distance_to_polyline(curve, False, q) < 1e-9
        with pytest.raises(embra.EmbraError):
            w.polyline_support_points(plane)


def test_mesh_support_holds_a_particle_sliding_down_an_inclined_face():
    """A particle on a mesh support (two triangles of a square inclined at 30 degrees) slides down it
    on the discrete path of g sin(theta), stays in the face, and the reaction is m g cos(theta)
    along its normal; a degenerate triangle is refused."""
    th = math.pi / 6
    n = (-math.sin(th), 0.0, math.cos(th))
    down = (-math.cos(th), 0.0, -math.sin(th))
    corners = [(1, 1), (-1, 1), (-1, -1), (1, -1)]
    verts = [tuple(10 * (a * down[k] + b * (0.0, 1.0, 0.0)[k]) for k in range(3)) for a, b in corners]
    with embra.World(gravity=(0.0, 0.0, -9.81), substeps=10, iterations=1, tethers=0) as w:
        w.create_body([(0.0, 0.3, 0.0)], generate=0, masses=[2.0])
        pin = w.create_mesh_support(0, verts, [(0, 3, 2), (0, 2, 1)])
        w.step(30)
        steps, h = 300, (1.0 / 60.0) / 10
        p = list(flat(w.positions()))
        along = sum(p[k] * down[k] for k in range(3))
        exact = 9.81 * math.sin(th) * h * h * steps * (steps + 1) / 2
        # rounding of the closest point (vertices of size 10) carried on by the velocity: steps^2 eps 10
        assert abs(along - exact) < steps * steps * 2.2e-16 * 10
        assert abs(sum(p[k] * n[k] for k in range(3))) < 1e-12
        r = w.reactions()
        assert r[0]["pin"] == pin
        for k in range(3):
            assert abs(r[0]["force"][k] - 2.0 * 9.81 * math.cos(th) * n[k]) < 1e-9 * 9.81
        with pytest.raises(embra.EmbraError):
            w.create_mesh_support(0, [(0, 0, 0), (1, 0, 0), (2, 0, 0)], [(0, 1, 2)])
        with pytest.raises(embra.EmbraError):
            w.create_mesh_support(0, verts, [(0, 1, 4)])
        assert w.counts().pins == 1


def test_plane_support_slides_at_g_sin_theta_and_pushes_along_its_normal():
    """A particle on a frictionless plane inclined at 30 degrees: s_n = g sin(theta) h^2 n (n + 1) / 2
    down the slope after n substeps (symplectic Euler, the plane projected exactly), and the
    support's reaction is m g cos(theta) along the normal."""
    th = math.pi / 6
    n = (-math.sin(th), 0.0, math.cos(th))
    with embra.World(gravity=(0.0, 0.0, -9.81), substeps=10, iterations=1, tethers=0) as w:
        w.create_body([(0.0, 0.0, 0.0)], generate=0, masses=[2.0])
        pin = w.create_support(0, (0.0, 0.0, 0.0), "plane", axis=[2 * c for c in n])
        w.step(30)
        steps, h = 300, (1.0 / 60.0) / 10
        p = list(flat(w.positions()))
        along = -(p[0] * math.cos(th) + p[2] * math.sin(th))
        exact = 9.81 * math.sin(th) * h * h * steps * (steps + 1) / 2
        assert abs(along - exact) < 1e-12 * exact
        r = w.reactions()
        assert r[0]["pin"] == pin
        for k in range(3):
            assert abs(r[0]["force"][k] - 2.0 * 9.81 * math.cos(th) * n[k]) < 1e-9 * 9.81
        with pytest.raises(embra.EmbraError):
            w.create_support(0, (0.0, 0.0, 0.0), "line", axis=(0.0, 0.0, 0.0))
        with pytest.raises(ValueError):
            w.create_support(0, (0.0, 0.0, 0.0), "curve")


def test_axes_support_holds_z_and_lets_x_and_y_accelerate_at_f_over_m():
    """A roller (per-axis anchor holding z) under gravity and a horizontal point load: z stays at the
    target's, x and y follow s_n = (F / m) h^2 n (n + 1) / 2 (symplectic Euler), and the reaction
    holds the weight in z with x and y exactly 0; an axis that is not 0/1 flags is refused."""
    with embra.World(gravity=(0.0, 0.0, -9.81), substeps=10, iterations=1, tethers=0) as w:
        w.create_body([(0.3, -0.4, 1.2)], generate=0, masses=[2.0])
        pin = w.create_support(0, (0.3, -0.4, 1.2), "axes", axis=(0, 0, 1))
        w.set_loads([(1.5, 0.5, 0.0)])
        steps, h = 300, (1.0 / 60.0) / 10
        for _ in range(30):
            w.step()
            assert abs(list(flat(w.positions()))[2] - 1.2) < 1e-12
        p = list(flat(w.positions()))
        for k, a in ((0, 0.75), (1, 0.25)):
            exact = a * h * h * steps * (steps + 1) / 2
            assert abs(p[k] - (0.3, -0.4)[k] - exact) < 1e-12
        r = w.reactions()[0]
        assert r["pin"] == pin
        assert r["force"][0] == 0.0 and r["force"][1] == 0.0
        assert abs(r["force"][2] - 2.0 * 9.81) < 1e-9 * 9.81
        with pytest.raises(embra.EmbraError):
            w.create_support(0, (0.0, 0.0, 0.0), "axes", axis=(0.0, 0.5, 1.0))
        with pytest.raises(embra.EmbraError):
            w.create_support(0, (0.0, 0.0, 0.0), "axes", axis=(0.0, 0.0, 0.0))
        assert w.counts().pins == 1


def test_groups_bulk_constraints_and_reports():
    """A chain of 5 links added in bulk, hard, hanging from a pin: every link at its rest length."""
    xyz = [(0.1 * i, 0.0, 0.0) for i in range(6)]
    with embra.World(iterations=20) as w:
        default, contact = w.default_group(), w.contact_group()
        assert default != contact
        links = w.create_group(order=5, weight=3)
        w.set_group_order(links, 4)
        w.set_group_weight(links, 2)
        body = w.create_body(xyz, generate=0, mass=0.6)
        assert w.body_particles(body) == (body.first, 6)
        added = w.add_constraints("distance", [(i, i + 1) for i in range(5)], group=links)
        assert added == 5 and w.counts().constraints == 5
        w.add_constraint("tether", [0, 5], rest=0.6, compliance=1e-3, group=links)  # slack: never pulls
        w.create_pin(0, xyz[0])
        w.step(120)
        assert w.counts().constraints == 6 and w.counts().groups == 3
        p = flat(w.positions())
        for i in range(5):
            length = math.dist(p[3 * i:3 * i + 3], p[3 * i + 3:3 * i + 6])
            assert abs(length - 0.1) < 1e-6
        g = w.group_report(links)
        assert g.count == 6 and g.residual_max < 1e-6
        w.destroy_group(links)
        assert w.counts().constraints == 0 and w.counts().groups == 2
        assert w.warning().frame == -1


def test_bulk_rest_and_compliances_arrays():
    xyz = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (2.0, 0.0, 0.0)]
    with embra.World(gravity=(0, 0, 0), iterations=50) as w:
        w.create_body(xyz, generate=0, mass=3.0)
        w.add_constraints(embra.KINDS["distance"], [0, 1, 1, 2], rest=[0.5, 0.25], compliances=[0.0, 0.0])
        w.step(60)
        p = flat(w.positions())
        assert abs(math.dist(p[0:3], p[3:6]) - 0.5) < 1e-9
        assert abs(math.dist(p[3:6], p[6:9]) - 0.25) < 1e-9


def test_pin_targets_move_particles():
    with embra.World() as w:
        w.create_body([(0.0, 0.0, 0.0)], mass=1.0)
        pin = w.create_pin(0, (0.0, 0.0, 0.0))
        w.set_pin_target(pin, (0.25, -0.5, 1.0))
        assert w.pin_target(pin) == (0.25, -0.5, 1.0)
        w.step()
        assert flat(w.positions()) == [0.25, -0.5, 1.0]


def test_colliders_hold_a_falling_particle():
    with embra.World() as w:
        w.create_body([(0.0, 0.0, 2.0)], mass=1.0)
        sphere = w.create_collider("sphere", position=(0.0, 0.0, 0.0), radius=1.0)
        floor = w.create_collider("plane", position=(0.0, 0.0, -5.0))
        w.step(120)
        z = flat(w.positions())[2]
        assert abs(z - 1.0) < 1e-6  # resting on top of the sphere
        w.set_collider_transform(sphere, (0.0, 0.0, -1.0))
        w.destroy_collider(floor)
        w.step(60)
        assert abs(flat(w.positions())[2] - 0.0) < 1e-6  # followed the sphere down
        hull = [(-1, -1, -1), (1, -1, -1), (0, 1, -1), (0, 0, 1)]
        w.create_collider("convex", position=(5, 0, 0), vertices=hull)
        w.create_collider("mesh", position=(9, 0, 0), vertices=hull, triangles=[(0, 2, 1), (0, 1, 3), (1, 2, 3),
                                                                                 (2, 0, 3)])
        w.create_collider("box", position=(-5, 0, 0), half_extents=(1, 2, 3))
        w.create_collider("capsule", position=(-9, 0, 0), radius=0.5, half_length=1.0)
        assert w.counts().colliders == 5


def test_rest_scale_shrinks_edges():
    with embra.World(gravity=(0, 0, 0), iterations=10) as w:
        body = w.create_body([(0.0, 0.0, 0.0), (1.0, 0.0, 0.0)], edges=[(0, 1)], mass=1.0)
        w.set_rest_scale(body, 0.5, 1.0, 1.0)
        w.step(120)
        p = flat(w.positions())
        assert abs(math.dist(p[0:3], p[3:6]) - 0.5) < 1e-9


def test_set_positions_and_velocities_round_trip():
    with embra.World() as w:
        w.create_body([(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)], triangles=[(0, 1, 2)], mass=1.0)
        w.set_positions([(0.5, 0.25, 2.0)], first=2)
        w.set_velocities([(1.0, 2.0, 3.0), (4.0, 5.0, 6.0)], first=0)
        assert flat(w.positions(2, 1)) == [0.5, 0.25, 2.0]
        assert flat(w.velocities()) == [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 0.0, 0.0, 0.0]
        assert flat(w.body_triangles(embra.BodyId(0, 1))) == [0, 1, 2]


def test_saved_scene_steps_on_bit_identically(tmp_path):
    xyz = [(0.1 * j, 0.1 * i, 0.0) for i in range(4) for j in range(4)]
    tri = [(v, v + 1, v + 5) for v in (0, 1, 2, 4, 5, 6, 8, 9, 10)] + \
          [(v, v + 5, v + 4) for v in (0, 1, 2, 4, 5, 6, 8, 9, 10)]
    with embra.World() as a:
        a.create_body(xyz, triangles=tri, mass=0.2)
        a.create_pin(0, xyz[0])
        a.step(10)
        text = a.save_json()
        a.save_file(tmp_path / "mid.json")
        with embra.World.load_json(text) as b, embra.World.load_file(tmp_path / "mid.json") as c:
            for w in (a, b, c):
                w.step(20)
            pa, pb, pc = (struct.pack("<48d", *flat(w.positions())) for w in (a, b, c))
            assert pa == pb == pc
            assert b.save_json() == a.save_json()


def test_solver_settings_round_trip():
    with embra.World(substeps=7, damping=0.5) as w:
        assert (w.solver.substeps, w.solver.damping) == (7, 0.5)
        w.set_solver(iterations=3)
        w.set_gravity((0.0, 0.0, 9.81))
        s = embra.as_dict(w.solver)
        assert (s["substeps"], s["iterations"], s["gravity"]) == (7, 3, (0.0, 0.0, 9.81))


@pytest.mark.skipif(not embra.have_numpy(), reason="numpy not installed")
def test_numpy_arrays_are_used_in_place():
    import numpy as np
    xyz = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    with embra.World() as w:
        body = w.create_body(xyz, triangles=np.array([[0, 1, 2]]), mass=1.0)
        out = np.zeros((3, 3))
        address = out.ctypes.data
        result = w.positions(body.first, 3, out=out)
        assert result is out and out.ctypes.data == address  # C wrote into the caller's array
        assert np.array_equal(out, xyz)
        p = w.positions()
        assert p.shape == (3, 3) and p.dtype == np.float64
        w.set_positions(xyz[1:] + 1.0, first=1)
        assert np.array_equal(w.positions(1, 2), xyz[1:] + 1.0)


def test_without_numpy_arrays_are_flat_doubles():
    from array import array
    with embra.World() as w:
        w.create_body(array("d", [0.0, 0.0, 0.0, 1.0, 0.0, 0.0]), edges=array("i", [0, 1]), mass=1.0)
        out = array("d", [0.0] * 6)
        assert w.positions(out=out) is out and list(out) == [0.0, 0.0, 0.0, 1.0, 0.0, 0.0]
        if not embra.have_numpy():
            assert isinstance(w.positions(), array)


def _which_library(env, cwd):
    import subprocess
    import sys
    code = "import embra; print(embra.library_path)"
    out = subprocess.run([sys.executable, "-c", code], env=env, cwd=cwd, check=True, capture_output=True, text=True)
    return out.stdout.strip()


def test_library_found_from_env_next_to_package_or_system(tmp_path, source_dir):
    """$EMBRA_LIBRARY first; else a libembra next to the package; else the loader's own search."""
    import shutil
    lib = os.path.realpath(_capi.library_path)
    pkg = os.path.join(source_dir, "host_adapters", "python", "embra")
    env = {k: v for k, v in os.environ.items() if k not in ("EMBRA_LIBRARY", "LD_LIBRARY_PATH", "PYTHONPATH")}
    env["PYTHONDONTWRITEBYTECODE"] = "1"
    beside = tmp_path / "beside"
    shutil.copytree(pkg, beside / "embra")
    shutil.copy(lib, beside / "embra" / f"libembra.so.{embra.ABI_VERSION}")
    assert _which_library(env, beside) == str(beside / "embra" / f"libembra.so.{embra.ABI_VERSION}")
    assert _which_library(dict(env, EMBRA_LIBRARY=lib), beside) == lib
    system = tmp_path / "system"
    shutil.copytree(pkg, system / "embra")
    found = _which_library(dict(env, LD_LIBRARY_PATH=os.path.dirname(lib)), system)
    assert found == f"libembra.so.{embra.ABI_VERSION}"  # by SONAME, through the dynamic loader's search
    import subprocess
    import sys
    failed = subprocess.run([sys.executable, "-c", "import embra"], env=env, cwd=system, capture_output=True, text=True)
    assert failed.returncode != 0 and "cannot load libembra" in failed.stderr and "EMBRA_LIBRARY" in failed.stderr


def test_public_limits_are_the_headers():
    """The ranges and limits (EMBRA_MAX_*, EMBRA_MIN_POSITIVE) are public under their header names, and the
    names the World methods accept are each enum's (embra._capi, generated from embra.h)."""
    for name in ("MAX_ABS_VALUE", "MIN_POSITIVE", "MAX_DT", "MAX_UNIT_SCALE", "MAX_PARTICLES", "MAX_CONSTRAINTS",
                 "MAX_PASSES_PER_STEP", "MAX_OBJ_BYTES"):
        assert getattr(embra, name) == getattr(_capi, name)
    assert embra.KINDS == _capi.CONSTRAINT_NAMES and embra.SHAPES == _capi.COLLIDER_NAMES
    assert embra.GENERATE == _capi.GENERATE_NAMES and embra.PANEL_PINS == _capi.PANEL_PINS_NAMES
    assert embra.PANEL_METRICS == _capi.PANEL_METRIC_NAMES and embra.CUTS_FORMATS == _capi.CUTS_NAMES


def test_struct_layouts_match_the_header(tmp_path, source_dir):
    """Every ctypes struct has the size and field offsets the C compiler gives its embra.h struct."""
    import shutil
    import subprocess
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        pytest.skip("no C compiler")
    structs = {"embra_solver_def": _capi.SolverDef, "embra_world_counts": _capi.WorldCounts,
               "embra_group_def": _capi.GroupDef, "embra_material": _capi.Material, "embra_body_def": _capi.BodyDef,
               "embra_constraint_def": _capi.ConstraintDef, "embra_constraint_batch_def": _capi.ConstraintBatchDef,
               "embra_pin_def": _capi.PinDef, "embra_collider_def": _capi.ColliderDef,
               "embra_step_report": _capi.StepReport, "embra_group_report": _capi.GroupReport,
               "embra_solve_def": _capi.SolveDef, "embra_solve_result": _capi.SolveResult,
               "embra_kind_residual": _capi.KindResidual,
               "embra_constraint_residual": _capi.ConstraintResidual, "embra_group_conflict": _capi.GroupConflict,
               "embra_warning": _capi.Warning, "embra_panel_mesh_def": _capi.PanelMeshDef,
               "embra_tolerance": _capi.Tolerance, "embra_tolerances": _capi.Tolerances,
               "embra_metric_summary": _capi.MetricSummary, "embra_panel_metrics": _capi.PanelMetrics,
               "embra_wind_def": _capi.WindDef, "embra_pressure_def": _capi.PressureDef,
               "embra_surface_tension_def": _capi.SurfaceTensionDef, "embra_vortex_def": _capi.VortexDef,
               "embra_load_options": _capi.LoadOptions, "embra_reaction": _capi.Reaction,
               "embra_collider_reaction": _capi.ColliderReaction, "embra_broken_constraint": _capi.BrokenConstraint,
               "embra_support_def": _capi.SupportDef, "embra_area_load": _capi.AreaLoad,
               "embra_line_load": _capi.LineLoad, "embra_polyline_support_def": _capi.PolylineSupportDef,
               "embra_mesh_support_def": _capi.MeshSupportDef}
    with open(os.path.join(source_dir, "capi", "include", "embra", "embra.h")) as f:
        declared = set(re.findall(r"typedef struct (embra_\w+) \{", f.read()))
    assert declared - {"embra_group_id", "embra_body_id", "embra_pin_id", "embra_collider_id",
                        "embra_field_id"} == set(structs)
    lines = ['#include <stddef.h>', '#include <stdio.h>', '#include "embra/embra.h"', "int main(void) {"]
    for c_name, cls in structs.items():
        lines.append(f'  printf("{c_name} %zu\\n", sizeof({c_name}));')
        for field, _ in cls._fields_:
            lines.append(f'  printf("{c_name}.{field} %zu\\n", offsetof({c_name}, {field}));')
    lines += ["  return 0;", "}"]
    (tmp_path / "layout.c").write_text("\n".join(lines) + "\n")
    generated = os.path.join(os.path.dirname(_capi.library_path), "generated")  # embra_version.h, in the build tree
    subprocess.run([cc, "-I", os.path.join(source_dir, "capi", "include"), "-I", generated, "-o",
                    str(tmp_path / "layout"), str(tmp_path / "layout.c")], check=True)
    c = dict(line.rsplit(" ", 1) for line in subprocess.run(
        [str(tmp_path / "layout")], check=True, capture_output=True, text=True).stdout.splitlines())
    for c_name, cls in structs.items():
        assert ctypes.sizeof(cls) == int(c[c_name]), c_name
        for field, _ in cls._fields_:
            assert getattr(cls, field).offset == int(c[f"{c_name}.{field}"]), f"{c_name}.{field}"
