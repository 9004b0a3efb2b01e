"""Planar Offset Quad panel meshes through Python: the paper's 4 x 4 drape of examples/poq_drape.json,
built with the World methods from the scene's own numbers, gives the bits the C host gives for the
scene (positions, metrics, cut lists); the metrics agree with the positions; every refusal is the
usual exception with the C message and changes nothing."""

import json
import math
import os
import struct
import subprocess

import pytest

import embra
from conftest import read_obj_vertices
from tent import flat

FRAMES = 150  # the posts drawn in (frames 0-30), the drape settled, and the sphere on its way (120-180)


def bits(values):
    return struct.pack(f"<{len(values)}d", *values)


@pytest.fixture(scope="session")
def scene_path(source_dir):
    return os.path.join(source_dir, "examples", "poq_drape.json")


@pytest.fixture(scope="session")
def scene(scene_path):
    with open(scene_path) as f:
        return json.load(f)


@pytest.fixture(scope="session")
def c_drape(cli, scene_path, tmp_path_factory):
    """`embra run examples/poq_drape.json --frames FRAMES`: the scene stepped by the C host; its final
    positions, its cut lists and its last metrics record."""
    out = tmp_path_factory.mktemp("c_poq")
    subprocess.run([cli, "run", scene_path, "--frames", str(FRAMES), "--out", str(out)], check=True,
                   stdout=subprocess.DEVNULL)
    with open(out / "metrics.jsonl") as f:
        records = [json.loads(line) for line in f]
    with open(out / "final.errors.json") as f:
        errors = json.load(f)
    return {"positions": read_obj_vertices(out / "final.obj"), "metrics": records[-1], "errors": errors,
            "json": (out / "panels_0.json").read_text(), "csv": (out / "panels_0.csv").read_text()}


def keyed(keys, frame):
    """A scene action's value at `frame`: linear between the keys around it, held outside them (the
    arithmetic of the scene player, in the same order)."""
    hi = 0
    while hi < len(keys) and keys[hi]["frame"] < frame:
        hi += 1
    if hi == 0:
        return [float(v) for v in keys[0]["value"]]
    if hi == len(keys):
        return [float(v) for v in keys[-1]["value"]]
    a, b = keys[hi - 1], keys[hi]
    t = float(frame - a["frame"]) / float(b["frame"] - a["frame"])
    return [(1.0 - t) * float(x) + t * float(y) for x, y in zip(a["value"], b["value"])]


class Drape:
    """The drape scene rebuilt through World methods from the scene file's numbers, stepped with its
    actions applied before each frame, as the scene player does."""

    def __init__(self, scene):
        s, p, ball = scene["solver"], scene["panel_meshes"][0], scene["colliders"][0]
        self.scene = scene
        self.world = embra.World(dt=s["dt"], substeps=s["substeps"], iterations=s["iterations"],
                                 gravity=s["gravity"], settle_speed=s["settle_speed"])
        assert p["generator"] == "grid"
        self.body = self.world.create_panel_mesh(
            grid_columns=p["columns"], grid_rows=p["rows"], panel_size=p["panel_size"], origin=p["origin"],
            thickness=p["thickness"], mass=p["mass"], damping=p["damping"], slide_compliance=p["slide_compliance"],
            pins=p["pins"])
        self.ball = self.world.create_collider(ball["shape"], position=ball["position"], radius=ball["radius"])
        self.world.tolerances = {k: v for k, v in scene["tolerances"].items() if k not in ("format", "version")}
        # The corner pins create_panel_mesh made are the world's first four: ids {k, 1} in creation order,
        # the order the scene names them poq.pin0..3 (checked against the actions' first keys below).
        self.pins = {f"{p['name']}.pin{k}": embra.PinId(k, 1) for k in range(4)}
        for a in scene["actions"]:
            if a["type"] == "pin_target":
                assert self.world.pin_target(self.pins[a["pin"]]) == tuple(keyed(a["keys"], 0))

    def step(self, frames):
        for _ in range(frames):
            frame = self.world.report().frame + 1
            for a in self.scene["actions"]:
                v = keyed(a["keys"], frame)
                if a["type"] == "pin_target":
                    self.world.set_pin_target(self.pins[a["pin"]], v)
                else:
                    assert a["type"] == "collider_pose"
                    self.world.set_collider_transform(self.ball, v)
            self.world.step()


def planarity(q):
    """1 - n1.n2 of a quad's two triangles, the larger over both diagonals (the paper's measure)."""
    def unit(v):
        n = math.sqrt(sum(c * c for c in v))
        return [c / n for c in v]

    def cross(a, b):
        return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]

    def sub(a, b):
        return [x - y for x, y in zip(a, b)]

    def split(a, b, c, d):
        n1, n2 = unit(cross(sub(b, a), sub(c, a))), unit(cross(sub(c, a), sub(d, a)))
        return 1.0 - sum(x * y for x, y in zip(n1, n2))

    return max(split(q[0], q[1], q[2], q[3]), split(q[1], q[2], q[3], q[0]))


def test_drape_built_in_python_matches_the_c_host_bit_for_bit(scene, c_drape):
    drape = Drape(scene)
    with drape.world as w:
        assert drape.body.count == 8 * 16 and w.panel_count(drape.body) == 16
        drape.step(FRAMES)
        python = flat(w.positions(drape.body.first, drape.body.count))
        assert bits(python) == bits(c_drape["positions"])
        assert min(python[2::3]) < -0.5  # folded down over the sphere: the comparison means something
        m = w.panel_metrics(drape.body)
        c = c_drape["metrics"]
        assert c["frame"] == FRAMES
        assert (m.planarity_top.max, m.planarity_bottom.max) == (c["planarity_top_max"], c["planarity_bottom_max"])
        assert max(m.corner_distance_top.max, m.corner_distance_bottom.max) == c["corner_distance_max"]
        assert max(m.diagonal_top.max, m.diagonal_bottom.max) == c["diagonal_max"]
        assert (m.thickness.max, m.miter.max, m.conical.max) == (c["thickness_error_max"], c["miter_error_max"],
                                                                 c["conical_defect_max"])
        assert bool(m.within_tolerance) == c["within_tolerance"]
        assert w.corner_gap(drape.body).max == c["corner_gap_max"]
        assert w.export_cuts(drape.body) == c_drape["json"]
        assert w.export_cuts(drape.body, "csv") == c_drape["csv"]
        assert json.loads(w.export_cuts(drape.body, "json"))["format"] == "embra-panel-cuts"


def test_drape_scene_loaded_in_python_steps_as_the_one_built(scene, scene_path):
    """The scene file loaded through the same library and the World built from its numbers agree bit
    for bit, metrics included; at frame 100 the drape meets the paper's bars, and the reported
    planarity is the planarity of the positions."""
    drape = Drape(scene)
    with drape.world as built, embra.World.load_file(scene_path) as loaded:
        body = embra.BodyId(0, 1)
        assert loaded.panel_count(body) == 16 and loaded.body_particles(body) == (0, 128)
        assert embra.as_dict(loaded.tolerances) == embra.as_dict(built.tolerances)
        assert loaded.tolerances.unit_scale == 1250.0
        drape.step(100)
        loaded.step(100)
        p = flat(loaded.positions())
        assert bits(flat(built.positions())) == bits(p)
        m = loaded.panel_metrics(body)
        assert embra.as_dict(m) == embra.as_dict(built.panel_metrics(drape.body))
        assert m.version == embra._capi.PANEL_METRICS_VERSION
        assert m.thickness.max <= 5e-5 and m.miter.max <= 1e-3
        assert m.planarity_top.max <= 1e-6 and m.planarity_bottom.max <= 1e-6
        assert m.planarity_top.count == m.thickness.count == 16 and m.miter.count == 2 * 4 * 5
        assert m.conical.count == 9  # interior vertices of valence 4
        own = max(planarity([p[3 * (8 * k + 4 * layer + c):3 * (8 * k + 4 * layer + c) + 3] for c in range(4)])
                  for k in range(16) for layer in range(2))
        assert abs(own - max(m.planarity_top.max, m.planarity_bottom.max)) <= 1e-15


def test_vertex_errors_are_one_value_per_particle_bounded_by_the_metrics(scene):
    drape = Drape(scene)
    with drape.world as w:
        drape.step(40)
        m = w.panel_metrics(drape.body)
        expected = {"planarity": max(m.planarity_top.max, m.planarity_bottom.max), "thickness": m.thickness.max,
                    "miter": m.miter.max,
                    "corner_distance": max(m.corner_distance_top.max, m.corner_distance_bottom.max),
                    "conical": m.conical.max}
        for name, top in expected.items():
            field = w.vertex_errors(drape.body, name)
            assert len(field) == 128
            assert max(flat(field)) == top, name
            assert list(flat(w.vertex_errors(drape.body, embra.PANEL_METRICS[name]))) == list(flat(field))
        assert expected["miter"] > 0.0  # folding: the fields are not all zero
        from array import array
        out = array("d", [7.0] * 130)  # the caller's buffer, larger than needed: written in place
        assert w.vertex_errors(drape.body, "miter", out=out) is out
        assert max(out[:128]) == m.miter.max and list(out[128:]) == [7.0, 7.0]


@pytest.mark.skipif(not embra.have_numpy(), reason="numpy not installed")
def test_vertex_errors_fill_a_numpy_array_in_place(scene):
    import numpy as np
    drape = Drape(scene)
    with drape.world as w:
        drape.step(40)
        field = w.vertex_errors(drape.body, "thickness")
        assert isinstance(field, np.ndarray) and field.shape == (128,) and field.dtype == np.float64
        out = np.full(128, -1.0)
        address = out.ctypes.data
        assert w.vertex_errors(drape.body, "thickness", out=out) is out and out.ctypes.data == address
        assert np.array_equal(out, field) and out.max() == w.panel_metrics(drape.body).thickness.max


def test_grid_builder_pins_tolerances_and_a_mesh_of_quads():
    with embra.World() as w:
        d = embra.default_panel_mesh_def()
        assert (d.version, d.grid_columns, d.grid_rows) == (embra._capi.PANEL_MESH_DEF_VERSION, 4, 4)
        assert (d.pins, d.corners) == (embra.PANEL_PINS["none"], embra.PANEL_CORNERS["welded"])
        assert d.precision == embra.PANEL_PRECISION["full"]
        assert (d.panel_size, d.thickness, d.density, d.slide_compliance) == (0.8, 0.01, 1.0, 1e-3)
        assert (d.friction_static, d.friction_dynamic, d.group) == (0.5, 0.3, embra.GroupId())
        # Corners shared: one top and one bottom particle per vertex of the 3 x 4 vertex grid, the
        # panels on a vertex on the same particles (panel 0's corner 1 is panel 1's corner 0).
        with embra.World() as ws:
            shared = ws.create_panel_mesh(grid_columns=2, grid_rows=3, corners="shared")
            assert (shared.first, shared.count) == (0, 24) and ws.panel_count(shared) == 6
            c = [int(v) for v in flat(ws.panel_corner_particles(shared))]
            assert len(c) == 48 and c[1] == c[8 + 0] and c[2] == c[8 + 3] and max(c) == 23
            assert embra.as_dict(ws.panel_metrics(shared))["within_tolerance"] == 1
        # Its rows in single precision: built and stepped like any other, the panels held.
        with embra.World() as wf:
            single = wf.create_panel_mesh(grid_columns=2, grid_rows=3, corners="shared", precision="single",
                                          pins="top_corners")
            wf.step(10)
            assert embra.as_dict(wf.panel_metrics(single))["within_tolerance"] == 1
        body = w.create_panel_mesh(grid_columns=2, grid_rows=3, pins="top_and_bottom_corners")
        assert (body.first, body.count) == (0, 48) and w.panel_count(body) == 6
        assert [int(v) for v in flat(w.panel_corner_particles(body))] == list(range(48))
        assert embra.as_dict(w.counts())["particles"] == 48 and w.counts().pins == 8
        m = embra.as_dict(w.panel_metrics(body))
        assert m["within_tolerance"] == 1 and m["miter"]["count"] == 2 * 4 + 3 * 3
        assert m["thickness"]["within_target"] == 6 and m["thickness"]["above_max"] == 0

        t = embra.default_tolerances()
        assert (t.version, t.unit_scale) == (1, 1000.0)
        assert embra.as_dict(t)["thickness"] == {"target": 5e-5, "max": 1e-3}
        assert w.tolerances.miter.target == 1e-3  # a world's tolerances start as the defaults
        w.set_tolerances(miter={"target": 0.5, "max": 1.0})
        assert (w.tolerances.miter.target, w.tolerances.miter.max, w.tolerances.unit_scale) == (0.5, 1.0, 1000.0)
        w.tolerances = t
        assert embra.as_dict(w.tolerances) == embra.as_dict(t)

        # Bent by hand out of tolerance: one corner 2 cm off its panel's plane. The world's tolerances
        # count it above the max; looser ones passed to the call count it within.
        p = w.positions(0, 1)
        w.set_positions([flat(p)[0], flat(p)[1], flat(p)[2] + 0.02], first=0)
        strict = w.panel_metrics(body)
        assert strict.within_tolerance == 0 and strict.planarity_top.above_max >= 1
        loose = w.panel_metrics(body, {"planarity": {"target": 1.0, "max": 1.0},
                                       "planarity_distance": {"target": 1.0, "max": 1.0},
                                       "thickness": {"target": 1.0, "max": 1.0}, "miter": {"target": 1.0, "max": 1.0}})
        assert loose.within_tolerance == 1 and loose.planarity_top.within_target == 6
        assert loose.planarity_top.max == strict.planarity_top.max

        # A mesh of two quads sharing an edge, given as vertices and quads.
        xyz = [(0, 0, 1), (1, 0, 1), (2, 0, 1), (0, 1, 1), (1, 1, 1), (2, 1, 1)]
        two = w.create_panel_mesh(xyz, [(0, 1, 4, 3), (1, 2, 5, 4)], thickness=0.05, group=w.default_group())
        assert (two.first, two.count) == (48, 16) and w.panel_count(two) == 2
        m = w.panel_metrics(two)
        assert m.miter.count == 7 and m.thickness.max < 1e-12 and m.within_tolerance == 1
        z = flat(w.positions(two.first, two.count))[2::3]
        assert z[:4] == [1.0] * 4 and all(abs(v - 0.95) < 1e-12 for v in z[4:8])  # bottom 0.05 below
        cuts = w.export_cuts(two, "csv").splitlines()
        assert len(cuts) == 3  # a header and one row per panel


def snapshot(w):
    return (bits(flat(w.positions())), bits(flat(w.velocities())), embra.as_dict(w.counts()),
            embra.as_dict(w.tolerances), w.save_json())


@pytest.fixture
def panels():
    with embra.World() as w:
        body = w.create_panel_mesh(grid_columns=2, grid_rows=2, pins="top_corners")
        plain = w.create_body([(0, 0, 0), (1, 0, 0), (0, 1, 0)], triangles=[(0, 1, 2)], mass=1.0)
        w.step(5)
        yield w, body, plain


def test_refused_panel_calls_raise_the_c_message_and_change_nothing(panels):
    w, body, plain = panels
    before = snapshot(w)
    with pytest.raises(embra.VersionError) as e:
        w.create_panel_mesh(version=99)
    assert isinstance(e.value, RuntimeError) and str(e.value).startswith("embra_panel_mesh_create: ")
    assert "99" in str(e.value) and str(e.value) == embra.last_error_message()
    with pytest.raises(ValueError) as e:
        w.create_panel_mesh(panel_size=math.nan)
    assert isinstance(e.value, embra.InvalidArgumentError)
    assert str(e.value).startswith("embra_panel_mesh_create: ") and "panel size must be finite" in str(e.value)
    with pytest.raises(embra.InvalidArgumentError, match="embra_panel_mesh_create: .*thickness"):
        w.create_panel_mesh(thickness=-1.0)
    with pytest.raises(embra.InvalidArgumentError, match="embra_panel_mesh_create"):
        w.create_panel_mesh([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], [(0, 1, 2, 9)])
    with pytest.raises(ValueError, match="4-tuples"):  # refused before C
        w.create_panel_mesh([(0, 0, 0), (1, 0, 0), (1, 1, 0)], [0, 1, 2])
    with pytest.raises(ValueError, match="unknown name 'bottom'"):
        w.create_panel_mesh(pins="bottom")
    with pytest.raises(ValueError, match="unknown name 'double'"):
        w.create_panel_mesh(precision="double")
    with pytest.raises(embra.InvalidArgumentError, match="embra_panel_mesh_create: .*precision"):
        w.create_panel_mesh(precision=2)
    assert snapshot(w) == before


def test_refused_panel_queries(panels):
    w, body, plain = panels
    before = snapshot(w)
    for call in (lambda b: w.panel_count(b), lambda b: w.panel_metrics(b), lambda b: w.vertex_errors(b, "miter"),
                 lambda b: w.export_cuts(b)):
        with pytest.raises(LookupError, match=r"embra_panel_mesh_\w+: ") as e:  # out of range: no such body
            call(embra.BodyId(7, 1))
        assert isinstance(e.value, embra.StaleIdError)
        with pytest.raises(embra.InvalidArgumentError, match="not a panel mesh"):
            call(plain)
    with pytest.raises(embra.InvalidArgumentError, match="embra_panel_mesh_get_vertex_errors: metric 9"):
        w.vertex_errors(body, 9)
    with pytest.raises(embra.InvalidArgumentError, match="embra_panel_mesh_export_cuts: format"):
        w.export_cuts(body, 7)
    with pytest.raises(ValueError, match="unknown name 'xml'"):
        w.export_cuts(body, "xml")
    with pytest.raises(embra.InvalidArgumentError, match="embra_world_set_tolerances: .*miter.target is above"):
        w.set_tolerances(miter={"target": 2.0, "max": 1.0})
    with pytest.raises(embra.InvalidArgumentError, match="embra_world_set_tolerances: .*unit_scale"):
        w.tolerances = {"unit_scale": math.nan}
    with pytest.raises(embra.VersionError, match="embra_panel_mesh_get_metrics"):
        w.panel_metrics(body, {"version": 2})
    from array import array
    out = array("d", [7.0] * 31)  # 4 panels: 32 values needed
    with pytest.raises(embra.BufferTooSmallError, match="embra_panel_mesh_get_vertex_errors: buffer holds 31"):
        w.vertex_errors(body, "planarity", out=out)
    assert list(out) == [7.0] * 31
    assert snapshot(w) == before
    w.close()
    with pytest.raises(embra.InvalidArgumentError, match="world is NULL.*closed"):
        w.panel_metrics(body)


def test_a_loaded_scene_names_its_objects_through_the_id_lists(scene_path):
    """The id lists pair with the saved scene's arrays entry by entry; the sphere read back follows
    the scene's path (frames 120 to 180: (0.3, 0.2, -1.45) to (-0.3, 0.2, -1.35))."""
    w = embra.World.load_file(scene_path)
    saved = json.loads(w.save_json())
    assert [w.pin_particle(p) for p in w.pins()] == [p["particle"] for p in saved["pins"]]
    assert [w.pin_target(p) for p in w.pins()] == [tuple(p["target"]) for p in saved["pins"]]
    assert len(w.bodies()) == len(saved["bodies"]) == 1
    assert w.groups() == [w.default_group(), w.contact_group()]
    (ball,) = w.colliders()
    assert w.collider_transform(ball) == ((0.3, 0.2, -1.45), (1.0, 0.0, 0.0, 0.0))
    w.step(150)
    position, rotation = w.collider_transform(ball)
    assert position == pytest.approx((0.0, 0.2, -1.4), abs=1e-12)
    assert rotation == (1.0, 0.0, 0.0, 0.0)
    w.destroy_pin(w.pins()[1])
    assert [w.pin_particle(p) for p in w.pins()] == [saved["pins"][k]["particle"] for k in (0, 2, 3)]
    with pytest.raises(embra.StaleIdError):
        w.collider_transform(embra.ColliderId(0, 7))
    w.close()


def test_the_c_hosts_error_fields_are_the_vertex_errors_of_its_final_state(scene_path, c_drape):
    """final.errors.json (the replay's colour maps): one value per particle per field, each the
    World's own vertex error after the same frames to its 9 printed digits, and the field's
    largest value the metrics record's max."""
    errors = c_drape["errors"]
    assert errors["format"] == "embra-vertex-errors" and errors["frame"] == FRAMES
    w = embra.World.load_file(scene_path)
    w.step(FRAMES)
    (body,) = w.bodies()
    record = c_drape["metrics"]
    keys = {"planarity": "planarity_max", "thickness": "thickness_error_max", "miter": "miter_error_max"}
    for name, key in keys.items():
        field = errors["fields"][name]
        assert len(field) == errors["particles"] == w.particle_count
        ours = list(w.vertex_errors(body, name))
        assert field == pytest.approx(ours, rel=1e-8, abs=0.0)
        assert max(field) == pytest.approx(record[key], rel=1e-8, abs=0.0)
    tol = w.tolerances
    assert errors["tolerances"]["thickness"] == {"target": tol.thickness.target, "max": tol.thickness.max}
    w.close()
