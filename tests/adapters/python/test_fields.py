"""Fields through Python: the section 3 scenes with their fields made by the World methods instead of
the scene file give the bits the C host gives (`embra run`), or for a scene with actions the bits of
the whole scene loaded through the same library; pressure on a closed surface inflates it and
keep_volume holds its volume; every refusal is the usual exception with the C message and changes
nothing."""

import json
import math
import os
import struct
import subprocess

import pytest

import embra
from conftest import read_obj_vertices

FRAMES = 40


def bits(values):
    return struct.pack(f"<{len(values)}d", *values)


def flat(xyz):
    return [float(v) for v in (xyz.ravel() if hasattr(xyz, "ravel") else xyz)]


def load_scene(source_dir, name):
    with open(os.path.join(source_dir, "examples", name + ".json")) as f:
        return json.load(f)


def without_fields(scene):
    return {k: v for k, v in scene.items() if k != "fields"}


def add_fields(world, scene):
    """Creates the scene's fields through the World methods; body names become the ids the loader
    gave the bodies (in file order, first generation)."""
    bodies = {b["name"]: embra.BodyId(k, 1) for k, b in enumerate(scene["bodies"])}
    create = {"wind": world.create_wind, "pressure": world.create_pressure,
              "surface_tension": world.create_surface_tension, "vortex": world.create_vortex}
    ids = []
    for field in scene["fields"]:
        fields = {k: v for k, v in field.items() if k not in ("type", "name")}
        if "body" in fields:
            fields["body"] = bodies[fields["body"]]
        ids.append(create[field["type"]](**fields))
    return ids


def c_host_positions(cli, source_dir, name, tmp_path):
    subprocess.run([cli, "run", os.path.join(source_dir, "examples", name + ".json"), "--frames", str(FRAMES),
                    "--out", str(tmp_path)], check=True, stdout=subprocess.DEVNULL)
    return read_obj_vertices(tmp_path / "final.obj")


@pytest.mark.parametrize("name", ["flag_wind", "minimal_surface", "interacting_elements"])
def test_fields_made_in_python_match_the_c_host_bit_for_bit(name, cli, source_dir, tmp_path):
    scene = load_scene(source_dir, name)
    assert "actions" not in scene  # `embra run` steps exactly what World.step steps
    expected = c_host_positions(cli, source_dir, name, tmp_path)
    with embra.World.load_json(json.dumps(without_fields(scene))) as w:
        assert w.field_count == 0
        ids = add_fields(w, scene)
        assert w.field_count == len(ids) == 1
        w.step(FRAMES)
        got = flat(w.positions())
    assert len(got) == len(expected) > 0
    assert bits(got) == bits(expected)
    with embra.World.load_json(json.dumps(without_fields(scene))) as w:  # the field is what moved them
        w.step(FRAMES)
        assert bits(flat(w.positions())) != bits(expected)


def test_shrink_wrap_pressure_made_in_python_steps_as_the_scene_loaded(source_dir):
    scene = load_scene(source_dir, "shrink_wrap")
    frames = 10
    with embra.World.load_json(json.dumps(scene)) as w:
        assert w.field_count == 1
        w.step(frames)
        expected = flat(w.positions())
    with embra.World.load_json(json.dumps(without_fields(scene))) as w:
        add_fields(w, scene)
        w.step(frames)
        assert bits(flat(w.positions())) == bits(expected)
        saved = json.loads(w.save_json())
    assert [f["type"] for f in saved["fields"]] == ["pressure"]
    assert saved["fields"][0]["outside_pressure"] == 30.0


OCTAHEDRON = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
OCTAHEDRON_TRIANGLES = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]


def enclosed_volume(xyz, triangles):
    p = [xyz[3 * k:3 * k + 3] for k in range(len(xyz) // 3)]
    v = 0.0
    for a, b, c in triangles:
        pa, pb, pc = p[a], p[b], p[c]
        v += (pa[0] * (pb[1] * pc[2] - pb[2] * pc[1]) - pa[1] * (pb[0] * pc[2] - pb[2] * pc[0])
              + pa[2] * (pb[0] * pc[1] - pb[1] * pc[0])) / 6.0
    return v


def octahedron_world():
    w = embra.World(gravity=(0, 0, 0), substeps=4)
    body = w.create_body(OCTAHEDRON, triangles=OCTAHEDRON_TRIANGLES, mass=1.0, stretch_compliance=1e-2,
                         generate=["stretch"])
    return w, body


def test_pressure_inflates_a_closed_surface_and_keep_volume_holds_it():
    rest = 4.0 / 3.0  # the unit octahedron
    w, body = octahedron_world()
    with w:
        assert enclosed_volume(flat(w.positions()), OCTAHEDRON_TRIANGLES) == pytest.approx(rest, rel=1e-15)
        w.create_pressure(body=body, inside_pressure=50.0, outside_pressure=10.0)
        w.step(30)
        inflated = enclosed_volume(flat(w.positions()), OCTAHEDRON_TRIANGLES)
        assert inflated > 1.05 * rest
    w, body = octahedron_world()
    with w:
        w.create_pressure(body=body, inside_pressure=50.0, outside_pressure=10.0, keep_volume=1)
        w.step(30)  # the same pressures grew the free one by over 5%
        assert enclosed_volume(flat(w.positions()), OCTAHEDRON_TRIANGLES) == pytest.approx(rest, rel=1e-4)


def test_defaults_are_the_documented_ones():
    wind = embra.default_wind_def()
    assert (wind.version, tuple(wind.direction), wind.speed, wind.air_density, wind.drag, wind.lift) == (
        embra._capi.WIND_DEF_VERSION, (1.0, 0.0, 0.0), 0.0, 1.2, 1.0, 1.0)
    assert wind.body == embra.BodyId()
    pressure = embra.default_pressure_def()
    assert embra.as_dict(pressure) == {"version": 1, "keep_volume": 0, "body": embra.BodyId(), "inside_pressure": 0.0,
                                       "outside_pressure": 0.0, "volume_compliance": 0.0, "rest_volume": 0.0}
    tension = embra.default_surface_tension_def()
    assert (tension.tension, tension.regularisation) == (0.0, 1.0)
    vortex = embra.default_vortex_def()
    assert (tuple(vortex.center), tuple(vortex.axis), vortex.strength, vortex.radius, vortex.decay) == (
        (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), 0.0, 1.0, 0.0)


def test_destroyed_field_stops_acting_and_its_id_is_stale():
    w, body = octahedron_world()
    with w:
        field = w.create_vortex(strength=3.0, axis=(0, 0, 1))
        other = w.create_wind(body=body, speed=2.0)
        assert w.field_count == 2 and field != other
        w.destroy_field(field)
        assert w.field_count == 1
        with pytest.raises(LookupError) as e:
            w.destroy_field(field)
        assert isinstance(e.value, embra.StaleIdError)
        assert str(e.value).startswith("embra_field_destroy: ") and str(e.value) == embra.last_error_message()
        assert w.field_count == 1
        w.destroy_field(other)
        assert w.field_count == 0
        before = bits(flat(w.positions()))
        w.step(5)  # no field, no gravity, at rest: nothing moves
        assert bits(flat(w.positions())) == before


@pytest.fixture
def fielded():
    w, body = octahedron_world()
    with w:
        w.create_wind(body=body, speed=1.0)
        w.step(3)
        yield w, body


def test_refused_field_calls_raise_the_c_message_and_change_nothing(fielded):
    w, body = fielded
    before = (w.field_count, w.save_json())
    with pytest.raises(embra.VersionError) as e:
        w.create_wind(version=99)
    assert isinstance(e.value, RuntimeError) and str(e.value).startswith("embra_wind_create: ")
    assert "99" in str(e.value) and str(e.value) == embra.last_error_message()
    with pytest.raises(ValueError) as e:
        w.create_wind(body=body, speed=math.nan)
    assert isinstance(e.value, embra.InvalidArgumentError) and str(e.value).startswith("embra_wind_create: ")
    with pytest.raises(embra.InvalidArgumentError, match="embra_wind_create: "):
        w.create_wind(direction=(0, 0, 0))
    with pytest.raises(embra.InvalidArgumentError, match="embra_pressure_create: "):
        w.create_pressure(body=body, inside_pressure=math.nan)
    with pytest.raises(embra.InvalidArgumentError, match="embra_pressure_create: "):
        w.create_pressure(body=body, keep_volume=2)
    with pytest.raises(embra.InvalidArgumentError, match="embra_pressure_create: "):
        w.create_pressure()  # the body is required
    with pytest.raises(embra.VersionError, match="embra_surface_tension_create: "):
        w.create_surface_tension(body=body, tension=1.0, version=0)
    with pytest.raises(embra.InvalidArgumentError, match="embra_surface_tension_create: "):
        w.create_surface_tension(body=body, tension=-1.0)
    with pytest.raises(embra.InvalidArgumentError, match="embra_vortex_create: "):
        w.create_vortex(radius=0.0)
    with pytest.raises(embra.InvalidArgumentError, match="embra_vortex_create: "):
        w.create_vortex(strength=math.inf)
    for create in (w.create_wind, w.create_pressure, w.create_surface_tension, w.create_vortex):
        with pytest.raises(embra.StaleIdError, match=r"embra_\w+_create: "):  # out of range: no such body
            create(body=embra.BodyId(7, 1))
    with pytest.raises(embra.StaleIdError, match="embra_field_destroy: "):
        w.destroy_field(embra.FieldId(5, 1))
    with pytest.raises(TypeError, match="WindDef has no field 'velocity'"):  # refused before C
        w.create_wind(velocity=3.0)
    with pytest.raises(TypeError, match="expected FieldId"):
        w.destroy_field(body)
    assert (w.field_count, w.save_json()) == before
    w.close()
    with pytest.raises(embra.InvalidArgumentError, match="world is NULL.*closed"):
        w.field_count
