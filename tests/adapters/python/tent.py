"""The Gaudi tent of `embra demo tent` (host_adapters/cli/embra_cli.c), built through the Python
adapter with the same arithmetic in the same order, so it must give the same bits as the C host."""

import math

import embra


def triangle_mesh(rows, side):
    """An equilateral triangle of `side` (m) in z = 0, split into rows^2 triangles; its corners."""
    h = side * math.sqrt(3.0) / 2.0
    xyz = []
    for r in range(rows + 1):
        for c in range(rows - r + 1):
            xyz.append((side * (float(c) + 0.5 * r) / rows - side / 2, h * float(r) / rows - h / 3, 0.0))

    def idx(r, c):
        return r * (rows + 1) - (r * (r - 1)) // 2 + c

    tri = []
    for r in range(rows):
        for c in range(rows - r):
            tri.append((idx(r, c), idx(r, c + 1), idx(r + 1, c)))
            if c + 1 < rows - r:
                tri.append((idx(r, c + 1), idx(r + 1, c + 1), idx(r + 1, c)))
    return xyz, tri, (idx(0, 0), idx(0, rows), idx(rows, 0))


def run_tent(frames=100, rows=40):
    """Steps the tent `frames` frames; returns its positions as a flat list of floats."""
    xyz, tri, corners = triangle_mesh(rows, 1.0)
    with embra.World(gravity=(0.0, 0.0, 9.81), damping=2.0, substeps=20, iterations=4, settle_speed=1e-3) as w:
        stretch = w.create_group(order=0, weight=2)
        bend = w.create_group(order=1, weight=1)
        body = w.create_body(xyz, triangles=tri, mass=0.5, stretch_compliance=1e-2, bend_compliance=10.0,
                             stretch_group=stretch, bend_group=bend)
        pins = [w.create_pin(body.first + k, xyz[k]) for k in corners]
        for f in range(1, frames + 1):
            draw = f / 60.0 if f < 60 else 1.0  # corners travel inwards over 1 s
            for pin, k in zip(pins, corners):
                w.set_pin_target(pin, [x * (1.0 - 0.1 * draw) for x in xyz[k]])
            w.step()
        return flat(w.positions(body.first, body.count))


def flat(positions):
    """A flat list of floats from the adapter's positions (numpy (n, 3) or array('d'))."""
    return [float(v) for v in (positions.ravel() if hasattr(positions, "ravel") else positions)]
