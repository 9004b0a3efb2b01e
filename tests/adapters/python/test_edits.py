"""Edits without a rebuild through Python: a particle of mass m hanging on a link of compliance c
rests stretched m g c, and after each edit (compliance, rest, material) where the new values put it;
the saved scene differs from the one before an edit at that one value only (a JSON diff); a disabled
group steps to the bits of a world without it; a vortex edited between steps pushes at
s exp(-r^2 / R^2) r / R; refusals change nothing."""

import json
import math

import pytest

import embra

G = 9.81


def hanging(m=2.0, **settings):
    w = embra.World(settle_speed=1e-7, **settings)
    b = w.create_body([[0, 0, 0], [0, 0, -1]], masses=[0, m])
    return w, b


def flat(values):
    """Positions or velocities as a flat list of floats (numpy (n, 3) or, without numpy, flat)."""
    return [float(c) for p in values for c in (p if hasattr(p, "__len__") else [p])]


def drop(w, b):
    """How far below 1 m the hanging particle rests."""
    assert w.solve(until="settled", max_frames=3000).outcome == "settled_within_tolerance"
    return -flat(w.positions())[3 * (b.first + 1) + 2] - 1.0


def differences(a, b, at=""):
    """The JSON pointers where two documents differ."""
    if isinstance(a, dict) and isinstance(b, dict) and a.keys() == b.keys():
        return [p for k in a for p in differences(a[k], b[k], f"{at}/{k}")]
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        return [p for i, (x, y) in enumerate(zip(a, b)) for p in differences(x, y, f"{at}/{i}")]
    return [] if a == b else [at]


def test_compliance_and_rest_edits_move_the_rest_state():
    w, b = hanging(damping=6.0)
    w.add_constraint("distance", [b.first, b.first + 1], rest=1.0, compliance=1e-3)
    assert w.constraint_count(None, "distance") == (1, 0)
    assert drop(w, b) == pytest.approx(2.0 * G * 1e-3, abs=1e-6)
    before, xyz = json.loads(w.save_json()), flat(w.positions())
    w.set_constraint_compliance(None, "distance", 0, 4e-3)
    assert flat(w.positions()) == xyz
    assert differences(before, json.loads(w.save_json())) == ["/constraints/0/compliance/0"]
    c = w.constraint(None, "distance", 0)
    assert c["compliance"] == 4e-3 and c["rest"] == 1.0 and c["particles"] == (b.first, b.first + 1)
    assert drop(w, b) == pytest.approx(2.0 * G * 4e-3, abs=1e-6)
    before = json.loads(w.save_json())
    w.set_constraint_rest(None, "distance", 0, 1.5)
    assert differences(before, json.loads(w.save_json())) == ["/constraints/0/rest/0"]
    assert drop(w, b) - 0.5 == pytest.approx(2.0 * G * 4e-3, abs=1e-6)


def test_a_disabled_group_steps_like_no_constraint():
    w, b = hanging()
    free, _ = hanging()
    g = w.create_group()
    w.add_constraint("distance", [b.first, b.first + 1], group=g)
    w.set_group_enabled(g, False)
    assert not w.group_enabled(g)
    w.step(20)
    free.step(20)
    assert flat(w.positions()) == flat(free.positions()) and flat(w.velocities()) == flat(free.velocities())
    saved = json.loads(w.save_json())
    assert [x["enabled"] for x in saved["groups"]] == [True, True, False]
    w.set_group_enabled(g, True)
    w.step()
    x = flat(w.positions())
    assert math.dist(x[0:3], x[3:6]) == pytest.approx(1.0, abs=1e-9)
    with pytest.raises(embra.InvalidArgumentError, match="contact"):
        w.set_group_enabled(w.contact_group(), False)
    with pytest.raises(TypeError):
        w.set_group_enabled(g, 1)


def test_move_and_remove_renumber_the_group():
    w, b = hanging()
    for rest in (1.0, 2.0, 3.0):
        w.add_constraint("distance", [b.first, b.first + 1], rest=rest)
    g = w.create_group()
    assert w.set_constraint_group(None, "distance", 1, g) == 0
    assert w.constraint(g, "distance", 0)["rest"] == 2.0
    w.remove_constraint(None, "distance", 0)
    assert w.constraint_count(None, "distance") == (1, 0)
    assert w.constraint(None, "distance", 0)["rest"] == 3.0
    with pytest.raises(embra.InvalidArgumentError, match=r"outside \[0, 1\)"):
        w.remove_constraint(None, "distance", 1)


def test_a_material_edit_moves_the_generated_stretch():
    w = embra.World(settle_speed=1e-7, damping=6.0, tethers=0)
    b = w.create_body([[0, 0, 0], [0, 0, -1]], edges=[[0, 1]], masses=[0, 2], stretch_compliance=1e-3)
    assert w.constraint_count(None, "distance") == (1, 1)
    assert drop(w, b) == pytest.approx(2.0 * G * 1e-3, abs=1e-6)
    with pytest.raises(embra.InvalidArgumentError, match="embra_body_set_material"):
        w.set_constraint_compliance(None, "distance", 0, 0.0)
    before = json.loads(w.save_json())
    w.set_material(b, stretch_compliance=3e-3)
    assert differences(before, json.loads(w.save_json())) == ["/bodies/0/material/stretch_compliance"]
    assert w.material(b).stretch_compliance == 3e-3
    assert drop(w, b) == pytest.approx(2.0 * G * 3e-3, abs=1e-6)
    with pytest.raises(embra.InvalidArgumentError, match="mass"):
        w.set_material(b, mass=5.0)
    with pytest.raises(TypeError):
        w.set_material(b, stiffness=1.0)


def test_a_vortex_edited_between_steps():
    w = embra.World(gravity=[0, 0, 0])
    w.create_body([[0.5, 0, 0]])
    f = w.create_vortex()
    w.step()
    assert flat(w.positions())[1] == 0.0
    w.set_vortex(f, strength=2.0)
    assert w.vortex(f).strength == 2.0 and w.vortex(f).radius == 1.0
    w.step()
    a = 2.0 * math.exp(-0.25) * 0.5
    assert flat(w.velocities())[1] == pytest.approx(a / 60, rel=1e-3)
    before = w.save_json()
    with pytest.raises(embra.InvalidArgumentError):
        w.set_wind(f, speed=1.0)
    with pytest.raises(embra.InvalidArgumentError):
        w.set_vortex(f, radius=0.0)
    assert w.save_json() == before


def test_masses_set_without_a_rebuild():
    """A particle hung on a link of compliance c rests m g c lower for each mass set on the running
    world; the saved scene differs at that mass only, and the world loaded from it steps on to the
    same bits; a uniform scale of every mass changes no motion; refusals change nothing."""
    w = embra.World(settle_speed=1e-7, damping=6.0, tethers=0)
    b = w.create_body([[0, 0, 0], [0, 0, -1]], edges=[[0, 1]], masses=[0, 1], stretch_compliance=2e-3)
    assert drop(w, b) == pytest.approx(1.0 * G * 2e-3, abs=1e-6)
    assert list(w.body_masses(b)) == [0.0, 1.0]
    before = json.loads(w.save_json())
    w.set_body_masses(b, [0.0, 3.5])
    saved = w.save_json()
    assert differences(before, json.loads(saved)) == ["/bodies/0/mesh/masses/1"]
    assert list(w.body_masses(b)) == [0.0, 3.5]
    loaded = embra.World.load_json(saved)
    for _ in range(40):
        w.step()
        loaded.step()
    assert flat(w.positions()) == flat(loaded.positions())
    assert flat(w.velocities()) == flat(loaded.velocities())
    assert drop(w, b) == pytest.approx(3.5 * G * 2e-3, abs=1e-6)

    text = w.save_json()
    for bad, error in [([0.0], embra.InvalidArgumentError), ([0.0, 1.0, 1.0], embra.InvalidArgumentError),
                       ([0.0, -1.0], embra.InvalidArgumentError), ([0.0, float("nan")], embra.InvalidArgumentError),
                       ([0.0, float("inf")], embra.InvalidArgumentError), ([0.0, 1e-310], embra.InvalidArgumentError),
                       (None, embra.InvalidArgumentError), (["a", 1.0], TypeError)]:
        with pytest.raises(error):
            w.set_body_masses(b, bad)
    if embra.have_numpy():
        import numpy as np
        with pytest.raises(ValueError, match="1-D"):
            w.set_body_masses(b, np.zeros((2, 1)))
        w.set_body_masses(b, np.array([0.0, 3.5]))  # the same masses: a numpy array is taken as is
    assert w.save_json() == text


def test_a_uniform_mass_scale_changes_no_motion():
    """A pendulum (a bob on a hard 1 m link from an immovable pivot, started level) and a free
    particle, their masses times 7 after 10 frames, follow the unscaled world's paths to 1e-9 m."""
    worlds = []
    for _ in range(2):
        w = embra.World(tethers=0)
        b = w.create_body([[0, 0, 0], [1, 0, 0], [3, 0, 0]], edges=[[0, 1]], masses=[0, 0.4, 0.25])
        worlds.append((w, b))
    worst = 0.0
    for frame in range(210):
        if frame == 10:
            worlds[1][0].set_body_masses(worlds[1][1], [0.0, 2.8, 1.75])
        for w, _ in worlds:
            w.step()
        a, c = flat(worlds[0][0].positions()), flat(worlds[1][0].positions())
        worst = max(worst, max(abs(x - y) for x, y in zip(a, c)))
    assert worst < 1e-9
    assert math.hypot(c[3], c[5]) == pytest.approx(1.0, abs=1e-6)


def test_plasticity_keeps_a_set_and_rupture_breaks_with_an_event():
    # Elastic strain under the weight: m g c / L = 0.0196, past a yield of 0.01: at rest the rest has
    # grown to m g c / 0.01 (approached from below, by 1 / (1 + yield) a frame), the elastic part m g c.
    w, b = hanging(damping=6.0)
    w.add_constraint("distance", [b.first, b.first + 1], rest=1.0, compliance=1e-3)
    assert w.constraint_plasticity(None, "distance", 0) == (0.0, 0.0)
    w.set_constraint_plasticity(None, "distance", 0, 0.01, 0.0)
    assert w.constraint_plasticity(None, "distance", 0) == (0.01, 0.0)
    assert drop(w, b) > 0.9
    rest = w.constraint(None, "distance", 0)["rest"]
    assert rest == pytest.approx(2.0 * G * 1e-3 / 0.01, rel=1e-5)
    assert 1.0 + drop(w, b) - rest == pytest.approx(2.0 * G * 1e-3, abs=1e-6)
    assert w.broken() == []
    with pytest.raises(embra.InvalidArgumentError, match="distance and dihedral"):
        w.set_constraint_plasticity(None, "tether", 0, 0.01, 0.0)
    with pytest.raises(embra.InvalidArgumentError):
        w.set_constraint_plasticity(None, "distance", 0, -1.0, 0.0)
    # Past a rupture of 0.015 the link breaks: one event names it, then the list is empty.
    w, b = hanging(damping=6.0)
    w.add_constraint("distance", [b.first, b.first + 1], rest=1.0, compliance=1e-3)
    w.set_constraint_plasticity(None, "distance", 0, 0.0, 0.015)
    w.step(60)
    events = w.broken()
    assert len(events) == 1
    e = events[0]
    assert (e["kind"], e["index"], e["particles"]) == ("distance", 0, [b.first, b.first + 1])
    assert e["strain"] > 0.015 and 0 < e["frame"] <= 60
    assert w.broken() == [] and w.constraint_count(None, "distance") == (0, 0)
