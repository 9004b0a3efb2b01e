"""The README's Grasshopper Python 3 example (host_adapters/python/examples/grasshopper_hanging_mesh.py)
run as a component runs it: its inputs as globals, its outputs read back, with a stand-in for the
few Rhino.Geometry calls it makes (rhino_standin/). A 1 m square net of 10 x 10 quads, 1 kg, hung
by its four corners from anchors 0.92 m apart: the corners end on the anchors (to 0.1 mm: a hard pin
is projected each iteration, then its neighbours' constraints pull on it), every other
vertex hangs below them, and at rest the anchors carry the net's weight (statics: the reactions sum
to m g)."""

import os
import runpy
import sys

import pytest

HERE = os.path.dirname(__file__)
EXAMPLE = os.path.join(os.environ.get("EMBRA_SOURCE_DIR", os.path.join(HERE, "..", "..", "..")),
                       "host_adapters", "python", "examples", "grasshopper_hanging_mesh.py")


@pytest.fixture
def rhino(monkeypatch):
    monkeypatch.syspath_prepend(os.path.join(HERE, "rhino_standin"))
    for name in ("Rhino", "Rhino.Geometry"):
        monkeypatch.delitem(sys.modules, name, raising=False)
    import Rhino.Geometry as rg
    return rg


def square_net(rg, n=10, side=1.0):
    m = rg.Mesh()
    for j in range(n + 1):
        for i in range(n + 1):
            m.Vertices.Add(side * i / n, side * j / n, 0.0)
    for j in range(n):
        for i in range(n):
            v = j * (n + 1) + i
            m.Faces.AddFace(v, v + 1, v + n + 2, v + n + 1)
    return m


def test_the_net_hangs_from_its_corners_and_the_anchors_carry_its_weight(rhino):
    n = 10
    mesh = square_net(rhino, n)
    anchors = [rhino.Point3d(x, y, 0.0) for y in (0.04, 0.96) for x in (0.04, 0.96)]
    out = runpy.run_path(EXAMPLE, init_globals={"mesh": mesh, "anchors": anchors, "frames": 600, "embra_path": None})
    result = out["result"]
    assert result.Vertices.Count == mesh.Vertices.Count
    assert [(f.A, f.B, f.C, f.D) for f in result.Faces] == [(f.A, f.B, f.C, f.D) for f in mesh.Faces]
    assert result.Normals.computed
    corners = [0, n, n * (n + 1), (n + 1) ** 2 - 1]  # nearest to the anchors, in the same order
    for i, p in zip(corners, anchors):
        v = result.Vertices[i]
        assert ((v.X - p.X) ** 2 + (v.Y - p.Y) ** 2 + (v.Z - p.Z) ** 2) ** 0.5 < 1e-4
    for i, v in enumerate(result.Vertices):
        if i not in corners:
            assert v.Z < -1e-3
    # At rest the four anchors hold the whole weight: 1 kg x 9.81 m/s^2, to 0.01 %. (Measured
    # 2026-11-26: 9.80977 N, 2.3e-5 short, where embra.h's statics promise the balance to rounding
    # with realign_passes >= 1: an open question for the statics, not for this example.)
    assert out["settled"]
    assert out["support"] == pytest.approx(9.81, rel=1e-4)
