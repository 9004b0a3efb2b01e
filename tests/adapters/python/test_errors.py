"""Every refusal is Python's usual exception carrying the C message, and changes nothing."""

import math
import struct

import pytest

import embra
from tent import flat

SQUARE = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (1.0, 1.0, 0.0), (0.0, 1.0, 0.0)]
SQUARE_TRIS = [(0, 1, 2), (0, 2, 3)]


@pytest.fixture
def world():
    with embra.World() as w:
        w.create_body(SQUARE, triangles=SQUARE_TRIS, mass=1.0)
        w.step(3)
        yield w


def snapshot(w):
    """Everything a refused call must leave as it was: positions, velocities, counts, saved scene."""
    return (struct.pack("<12d", *flat(w.positions())), struct.pack("<12d", *flat(w.velocities())),
            embra.as_dict(w.counts()), w.save_json())


def test_out_of_range_particle_index(world):
    before = snapshot(world)
    with pytest.raises(ValueError) as e:
        world.create_pin(4, (0, 0, 0))
    assert isinstance(e.value, embra.InvalidArgumentError)
    assert e.value.status == -1 and e.value.status_name == "EMBRA_ERROR_INVALID_ARGUMENT"
    assert str(e.value).startswith("embra_pin_create: ")
    assert str(e.value) == e.value.message == embra.last_error_message()  # the C message, verbatim
    with pytest.raises(embra.InvalidArgumentError, match="embra_world_get_positions"):
        world.positions(first=2, count=5)
    with pytest.raises(embra.InvalidArgumentError, match="embra_constraints_add"):
        world.add_constraints("distance", [(0, 1), (2, 99)])
    with pytest.raises(embra.InvalidArgumentError, match="embra_body_create"):
        world.create_body(SQUARE, triangles=[(0, 1, 7)])
    with pytest.raises(OverflowError):  # does not fit the C int32 at all: refused before C
        world.create_pin(2**40, (0, 0, 0))
    assert snapshot(world) == before


def test_nan(world):
    before = snapshot(world)
    nan = math.nan
    with pytest.raises(ValueError, match="embra_world_set_gravity: .*finite"):
        world.set_gravity((0, nan, 0))
    with pytest.raises(embra.InvalidArgumentError, match="embra_world_set_positions"):
        world.set_positions([(nan, 0, 0)], first=1)
    with pytest.raises(embra.InvalidArgumentError, match="embra_body_create"):
        world.create_body([(0, 0, 0), (1, 0, 0), (0, nan, 0)], triangles=[(0, 1, 2)])
    with pytest.raises(embra.InvalidArgumentError, match="embra_pin_create"):
        world.create_pin(0, (0, 0, math.inf))
    assert snapshot(world) == before


def test_use_after_destroy(world):
    pin = world.create_pin(0, (0, 0, 0))
    world.destroy_pin(pin)
    before = snapshot(world)
    with pytest.raises(LookupError) as e:
        world.set_pin_target(pin, (1, 0, 0))
    assert isinstance(e.value, embra.StaleIdError)
    assert str(e.value).startswith("embra_pin_set_target: ")
    group = world.create_group()
    world.destroy_group(group)
    with pytest.raises(embra.StaleIdError, match="embra_group_set_weight"):
        world.set_group_weight(group, 3)
    sphere = world.create_collider("sphere", position=(0, 0, -2), radius=1.0)
    world.destroy_collider(sphere)
    with pytest.raises(embra.StaleIdError, match="embra_collider_set_transform"):
        world.set_collider_transform(sphere, (0, 0, -3))
    assert world.counts().pins == 0 and world.counts().colliders == 0


def test_use_of_a_closed_world():
    w = embra.World()
    w.close()
    w.close()  # idempotent
    assert w.closed
    for call in (w.step, w.counts, w.save_json, lambda: w.positions(0, 1)):
        with pytest.raises(ValueError) as e:
            call()
        assert isinstance(e.value, embra.InvalidArgumentError)
        assert "world is NULL" in str(e.value) and "closed" in str(e.value)
    with embra.World() as inner:
        pass
    with pytest.raises(embra.InvalidArgumentError, match="embra_world_step: world is NULL"):
        inner.step()


def test_bad_def_version_and_values():
    with pytest.raises(embra.VersionError, match="embra_world_create: embra_solver_def.version is 7"):
        embra.World(version=7)
    with pytest.raises(embra.InvalidArgumentError, match="embra_world_create"):
        embra.World(dt=-1.0)
    with pytest.raises(TypeError, match="no field 'gravty'"):
        embra.World(gravty=(0, 0, 1))


def test_bad_scene_json(source_dir):
    with pytest.raises(embra.SchemaError) as e:
        embra.World.load_json('{"format": "embra-scene", "version": 1, "solver": {"dt": 0}}')
    assert "/solver/dt" in str(e.value) and str(e.value).startswith("embra_world_load_json_with_options: ")
    with pytest.raises(embra.SchemaError):
        embra.World.load_json("{ not json")
    with pytest.raises(embra.InvalidArgumentError, match="embra_world_load_file"):
        embra.World.load_file("/nonexistent-embra-dir/scene.json")


def test_buffer_too_small_writes_nothing(world):
    from array import array
    out = array("d", [7.0] * 6)  # room for 2 particles, asked for 4
    with pytest.raises(embra.BufferTooSmallError, match="embra_world_get_positions"):
        world.positions(0, 4, out=out)
    assert list(out) == [7.0] * 6


def test_wrong_lengths_are_refused_before_c(world):
    before = snapshot(world)
    with pytest.raises(ValueError, match="whole number of xyz"):
        world.set_positions([0.0, 1.0])
    with pytest.raises(ValueError, match="masses"):
        world.create_body(SQUARE, triangles=SQUARE_TRIS, masses=[1.0, 1.0])
    with pytest.raises(ValueError, match="rest"):
        world.add_constraints("distance", [(0, 1), (1, 2)], rest=[1.0])
    with pytest.raises(ValueError, match="takes 2 particles"):
        world.add_constraint("distance", [0, 1, 2])
    assert snapshot(world) == before


def test_a_step_that_goes_non_finite(world):
    """A velocity of 1e300 m/s (the largest value a world accepts) overflows in the step: the
    stretch constraint squares lengths of 1e297 m. NumericalError (an ArithmeticError) with the C
    message, the world restored to the start of the frame, and a warning record saying where."""
    world.set_velocities([(embra.MAX_ABS_VALUE, 0.0, 0.0)], first=1)
    before = snapshot(world)
    frame = world.report().frame
    with pytest.raises(ArithmeticError) as e:
        world.step()
    assert isinstance(e.value, embra.NumericalError) and e.value.status_name == "EMBRA_ERROR_NUMERICAL"
    assert str(e.value).startswith("embra_world_step: non-finite")
    assert snapshot(world) == before and world.report().frame == frame
    assert world.warning().frame == frame and world.warning().particle >= 0
    world.set_velocities([(0.0, 0.0, 0.0)], first=1)  # the cause removed, the world steps on
    world.step()
    assert world.report().frame == frame + 1


def test_values_out_of_range_are_refused_and_change_nothing(world):
    """Finite values beyond embra.h's ranges (|v| > 1e300, positives and masses < 1e-300, dt > 1e6,
    substeps x iterations > 1e5, unit_scale > 1e12) are refused with the C message; nothing changes."""
    big, tiny = 1e308, embra.MIN_POSITIVE / 10
    pin = world.create_pin(0, (0.0, 0.0, 0.0))
    before = snapshot(world) + (embra.as_dict(world.solver), embra.as_dict(world.tolerances), world.pin_target(pin))
    refused = [
        ("embra_world_set_velocities", lambda: world.set_velocities([(big, 0.0, 0.0)], first=1)),
        ("embra_world_set_positions", lambda: world.set_positions([(0.0, -2 * embra.MAX_ABS_VALUE, 0.0)], first=2)),
        ("embra_world_set_gravity", lambda: world.set_gravity((0.0, 0.0, big))),
        ("embra_pin_set_target", lambda: world.set_pin_target(pin, (big, 0.0, 0.0))),
        ("embra_pin_create", lambda: world.create_pin(1, (0.0, big, 0.0))),
        ("embra_body_create", lambda: world.create_body(SQUARE, triangles=SQUARE_TRIS, masses=[1.0, 1.0, 1.0, tiny])),
        ("embra_world_set_solver", lambda: world.set_solver(dt=2 * embra.MAX_DT)),
        ("embra_world_set_solver", lambda: world.set_solver(dt=tiny)),
        ("embra_world_set_solver", lambda: world.set_solver(substeps=1000,
                                                            iterations=embra.MAX_PASSES_PER_STEP // 1000 + 1)),
        ("embra_world_set_tolerances", lambda: world.set_tolerances(unit_scale=10 * embra.MAX_UNIT_SCALE)),
        ("embra_collider_create", lambda: world.create_collider("sphere", position=(0.0, 0.0, big), radius=1.0)),
    ]
    for function, call in refused:
        with pytest.raises(embra.InvalidArgumentError) as e:
            call()
        assert str(e.value).startswith(function + ": "), str(e.value)
    after = snapshot(world) + (embra.as_dict(world.solver), embra.as_dict(world.tolerances), world.pin_target(pin))
    assert after == before


def test_values_at_the_limits_are_accepted_and_saved_scenes_load_back():
    """What the C API accepts, the saved scene reads back: a world holding the extreme accepted values."""
    top = embra.MAX_ABS_VALUE
    with embra.World(dt=embra.MAX_DT, substeps=1000, iterations=embra.MAX_PASSES_PER_STEP // 1000,
                     gravity=(top, -top, 0.0)) as w:
        w.create_body([(top, 0.0, -top)], masses=[embra.MIN_POSITIVE])  # one particle each: no element
        w.create_body([(0.0, top, 0.0)], masses=[top])                  # measure overflows
        w.create_pin(0, (-top, top, top))
        w.set_tolerances(unit_scale=embra.MAX_UNIT_SCALE)
        text = w.save_json()
        with embra.World.load_json(text) as back:
            assert back.save_json() == text
            assert struct.pack("<6d", *flat(back.positions())) == struct.pack("<6d", *flat(w.positions()))


def test_rows_of_the_wrong_width_are_refused_before_anything_is_built():
    """A transposed (3, n) positions array, quads passed as triangles and pairs passed as points are
    named, not read as other shapes; nothing is built."""
    w = embra.World()
    square = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    with pytest.raises(ValueError, match=r"triangles: expected rows of 3, row 0 has 4"):
        w.create_body(square, triangles=[[0, 1, 2, 3]])
    with pytest.raises(ValueError, match=r"positions: expected rows of 3, row 0 has 2"):
        w.create_body([[0, 0], [1, 0], [1, 1]])
    with pytest.raises(ValueError, match=r"particles: expected rows of 2"):
        w.add_constraints("distance", [[0, 1, 2]])
    if embra.have_numpy():
        import numpy as np
        with pytest.raises(ValueError, match=r"positions: expected an \(n, 3\) array, got shape \(3, 4\)"):
            w.create_body(np.array(square, dtype=float).T)
        with pytest.raises(ValueError, match=r"quads: expected an \(n, 4\) array, got shape \(1, 3\)"):
            w.create_panel_mesh(np.array(square, dtype=float), np.array([[0, 1, 2]]))
        with pytest.raises(ValueError, match=r"triangles: expected an \(n, 3\) array, got shape \(2, 4\)"):
            w.create_body(np.array(square, dtype=float), triangles=np.array([[0, 1, 2, 3], [0, 2, 3, 1]]))
        with pytest.raises(ValueError, match=r"positions: expected an \(n, 3\) or flat array, got shape \(3, 3, 1\)"):
            w.create_body(np.zeros((3, 3, 1)))
    assert w.counts().particles == 0 and w.counts().constraints == 0


def test_structs_print_as_their_fields():
    w = embra.World()
    w.create_body([[0, 0, 0]])
    w.step()
    text = repr(w.report())
    assert text.startswith("StepReport(frame=1, time=0.01666") and "settled=" in text
    assert "gravity=[0.0, 0.0, -9.81]" in repr(embra.default_solver_def())
