"""World.residuals and World.solve through Python: residuals by kind in their own units (a hard
pendulum rod's residual is | |x1 - x0| - L | from the positions); a pendulum with no damping oscillates with period 2 pi sqrt(L / g)
(to 1 %); a panel whose top corners are pinned off one plane comes to rest out of tolerance, naming
that panel; bad arguments are refused before any step."""

import math

import pytest

import embra


def test_a_pendulum_oscillates_with_its_period():
    w = embra.World()
    theta = 0.1
    b = w.create_body([[0, 0, 0], [math.sin(theta), 0, -math.cos(theta)]], masses=[0, 1])
    w.add_constraint("distance", [b.first, b.first + 1])
    solved = w.solve(max_frames=900)
    expected = 2 * math.pi * math.sqrt(1 / 9.81) * (1 + theta ** 2 / 16)
    assert solved.outcome == "oscillating"
    assert solved.frames == 900 and not solved.settled
    assert solved.period == pytest.approx(expected, rel=0.01)
    assert solved.worst is None
    assert "oscillating" in repr(solved) and "period=" in repr(solved)


def test_a_panel_pinned_off_its_plane_settles_out_of_tolerance():
    w = embra.World(embra.form_finding_solver_def(), damping=2.0)
    body = w.create_panel_mesh(grid_columns=1, grid_rows=1, pins="top_corners")
    for pin in w.pins():
        if w.pin_particle(pin) == body.first + 2:
            x, y, z = w.pin_target(pin)
            w.set_pin_target(pin, [x, y, z + 0.05])
    solved = w.solve()
    assert solved.outcome == "settled_out_of_tolerance" and solved.settled
    assert solved.frames < 1000
    worst = solved.worst
    assert worst["metric"] in ("planarity", "corner_distance")
    assert worst["body"] == body.id and worst["element"] == 0 and worst["layer"] == "top"
    assert worst["value"] > 100 * worst["target"]


def test_refusals_change_nothing():
    w = embra.World()
    w.create_body([[0, 0, 0]])
    with pytest.raises(ValueError):
        w.solve(until="forever")
    with pytest.raises(embra.InvalidArgumentError):
        w.solve(max_frames=0)
    with pytest.raises(embra.InvalidArgumentError):
        w.solve(max_seconds=float("nan"))
    assert w.report().frame == 0


def test_residuals_by_kind_in_their_units():
    w = embra.World()
    b = w.create_body([[0, 0, 0], [0.6, 0, -0.8]], masses=[0, 1])
    w.add_constraint("distance", [b.first, b.first + 1])
    assert w.residuals() == {}
    w.step(10)
    res = w.residuals()
    assert list(res) == ["distance"]
    flat = [float(c) for p in w.positions() for c in (p if hasattr(p, "__len__") else [p])]
    length = math.dist(flat[0:3], flat[3:6])
    assert res["distance"]["unit"] == "m" and res["distance"]["count"] == 1
    assert res["distance"]["max"] == pytest.approx(abs(length - 1.0), abs=1e-15)
    assert res["distance"]["rms"] == res["distance"]["max"]


def test_two_groups_pulling_a_cable_apart_are_named_first():
    """A hanging cable's top held by two soft pins (1e-3 m/N) 0.5 m to either side, each in its own
    group: 500 N each way on one particle."""
    w = embra.World(damping=5.0)
    b = w.create_body([[0, 0, -0.1 * i] for i in range(11)], mass=1.0)
    w.add_constraints("distance", [[b.first + i, b.first + i + 1] for i in range(10)])
    left, right = w.create_group(order=1), w.create_group(order=2)
    pa = w.create_pin(b.first, [-0.5, 0, 0], compliance=1e-3, group=left)
    pb = w.create_pin(b.first, [0.5, 0, 0], compliance=1e-3, group=right)
    w.step(300)
    first = w.group_conflicts()[0]
    assert (first["a"], first["b"]) == (left, right)
    assert first["force"] == pytest.approx(500, abs=10) and first["particles"] == 1
    worst = w.worst_constraints(3)
    assert {worst[0]["pin"], worst[1]["pin"]} == {pa, pb}
    assert worst[0]["kind"] == "pins" and worst[0]["particles"] == [b.first] and worst[0]["unit"] == "m"
    assert worst[0]["violation"] == pytest.approx(0.5, abs=0.02) and worst[0]["force"] == pytest.approx(500, abs=10)
    assert worst[2]["kind"] == "distance" and len(worst[2]["particles"]) == 2 and worst[2]["force"] < 10
    links = w.group_residuals(w.default_group(), "distance")
    assert len(links) == 10 and max(links) < 2e-4
