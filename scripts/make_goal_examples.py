#!/usr/bin/python3
"""Writes the goal-set examples (README, "The goal set: examples a designer recognises") from
their few parameters, so each JSON's hundreds of rows come from one place:

  examples/cable_net_roof.json       a hypar cable net on four edge rails under snow
  examples/gridshell_chebyshev.json  an equal-length grid pushed up into a dome
  examples/conical_dome.json         a quad grid on a dome form-found conical
  examples/plastic_hinge.json        a hinge loaded past its yield angle keeps its fold

usage: scripts/make_goal_examples.py [EXAMPLES_DIR]   (default: the repository's examples/)"""
import json
import math
import os
import sys


def dump(path, scene):
    """One row per vertex / operand list, so the files read and diff line by line."""
    def fmt(v, depth=0):
        pad = "  " * depth
        if isinstance(v, dict):
            items = [f'{pad}  {json.dumps(k)}: {fmt(x, depth + 1).lstrip()}' for k, x in v.items()]
            return pad + "{\n" + ",\n".join(items) + "\n" + pad + "}"
        if isinstance(v, list) and v and all(isinstance(x, list) for x in v):
            return pad + "[\n" + ",\n".join(pad + "  " + json.dumps(x) for x in v) + "\n" + pad + "]"
        if isinstance(v, list) and v and any(isinstance(x, dict) for x in v):
            return pad + "[\n" + ",\n".join(fmt(x, depth + 1) for x in v) + "\n" + pad + "]"
        return pad + json.dumps(v)
    with open(path, "w") as f:
        f.write(fmt(scene) + "\n")


def r(v):
    return round(v, 12)


def cable_net_roof():
    """A hyperbolic paraboloid cable net, 10 m x 10 m in plan, 11 x 11 nodes: two high corners
    (masts, 2.5 m) and two low ones (0 m), hard pinned; every other edge node clamped to the
    straight edge beam between two corners, free to slide along it (a line support). The cables
    run along the grid, shortened 1 % (prestress), no cable along an edge beam. Under the nodes'
    weight and 800 Pa of snow per plan area (projected_area on every triangle of the net's
    cells), the reactions of the masts and the rails balance the load."""
    n, L, h = 11, 10.0, 2.5
    a = L / (n - 1)

    def height(x, y):
        u, v = x / L, y / L
        return h * ((1 - u) * (1 - v) + u * v)

    idx = lambda i, j: j * n + i  # noqa: E731
    verts = []
    for j in range(n):
        for i in range(n):
            x, y = i * a, j * a
            verts.append([r(x), r(y), r(height(x, y))])
    side = lambda i, j: {s for s, on in (("x0", i == 0), ("x1", i == n - 1), ("y0", j == 0), ("y1", j == n - 1)) if on}  # noqa: E731
    edges, rests, beams = [], [], []  # beams: the edge beams, drawn (mesh edges), not constraints
    for j in range(n):
        for i in range(n):
            for (di, dj) in ((1, 0), (0, 1)):
                i2, j2 = i + di, j + dj
                if i2 >= n or j2 >= n:
                    continue
                if side(i, j) & side(i2, j2):  # along an edge beam
                    beams.append([idx(i, j), idx(i2, j2)])
                    continue
                p, q = verts[idx(i, j)], verts[idx(i2, j2)]
                edges.append([idx(i, j), idx(i2, j2)])
                rests.append(r(0.99 * math.dist(p, q)))
    triangles = []
    for j in range(n - 1):
        for i in range(n - 1):
            triangles.append([idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)])
            triangles.append([idx(i, j), idx(i + 1, j + 1), idx(i, j + 1)])
    corners = [(0, 0), (n - 1, 0), (n - 1, n - 1), (0, n - 1)]
    pins = []
    for c, (i, j) in enumerate(corners):
        pins.append({"name": f"mast{c}", "particle": {"body": "net", "vertex": idx(i, j)}})
    for j in range(n):
        for i in range(n):
            s = side(i, j)
            if len(s) != 1:
                continue
            s = s.pop()
            # The beam from corner to corner along this side.
            (ia, ja), (ib, jb) = {"y0": ((0, 0), (n - 1, 0)), "x1": ((n - 1, 0), (n - 1, n - 1)),
                                  "y1": ((0, n - 1), (n - 1, n - 1)), "x0": ((0, 0), (0, n - 1))}[s]
            pa, pb = verts[idx(ia, ja)], verts[idx(ib, jb)]
            axis = [r(pb[k] - pa[k]) for k in range(3)]
            pins.append({"name": f"rail_{s}_{i}_{j}", "particle": {"body": "net", "vertex": idx(i, j)},
                         "support": "line", "axis": axis})
    return {
        "format": "embra-scene",
        "version": 1,
        "name": "cable_net_roof",
        "description": cable_net_roof.__doc__.replace("\n    ", " ").strip(),
        "frames": 600,
        "solver": {"substeps": 10, "iterations": 40, "damping": 5.0, "realign_passes": 4, "tethers": 0},
        "bodies": [{
            "name": "net",
            "mesh": {"vertices": verts, "edges": edges + beams, "masses": [20.0] * len(verts)},
            "generate": [],
        }],
        "constraints": [{"kind": "distance", "particles": edges, "rest": rests, "compliance": 1e-6}],
        "pins": pins,
        "area_loads": [{"particles": t, "pressure": 800.0, "mode": "projected_area", "direction": [0, 0, -1]}
                       for t in triangles],
    }


def gridshell_chebyshev():
    """An equal-length gridshell erected from a flat grid: 13 x 13 nodes 0.5 m apart (6 m square,
    the four corners left out), every lath a distance of rest 0.5 m, hard (inextensible), pin
    jointed at the nodes (no shear or bending stiffness: a Chebyshev net). The 44 boundary nodes are
    hard pinned to the ground beam, no lath along it; over the first 120 frames the beam is drawn
    in to 80 % of its span about the centre, and the net, its weight reversed as in an inverted
    hanging model, rises into a dome: the laths keep their length and the grid shears."""
    n, a, s = 13, 0.5, 0.9
    c = 0.5 * (n - 1) * a
    corner = lambda i, j: i in (0, n - 1) and j in (0, n - 1)  # noqa: E731
    on_edge = lambda i, j: i in (0, n - 1) or j in (0, n - 1)  # noqa: E731
    index, verts = {}, []
    for j in range(n):
        for i in range(n):
            if corner(i, j):
                continue
            index[(i, j)] = len(verts)
            verts.append([r(i * a - c), r(j * a - c), 0.0])
    edges = []
    for (i, j) in sorted(index, key=lambda k: index[k]):
        for (di, dj) in ((1, 0), (0, 1)):
            q = (i + di, j + dj)
            if q not in index:
                continue
            same_side = (i == q[0] and i in (0, n - 1)) or (j == q[1] and j in (0, n - 1))
            if not same_side:
                edges.append([index[(i, j)], index[q]])
    pins, actions = [], []
    for (i, j), k in sorted(index.items(), key=lambda e: e[1]):
        if not on_edge(i, j):
            continue
        name = f"beam_{i}_{j}"
        x = verts[k]
        pins.append({"name": name, "particle": {"body": "grid", "vertex": k}})
        actions.append({"type": "pin_target", "pin": name,
                        "keys": [{"frame": 0, "value": x}, {"frame": 120, "value": [r(s * x[0]), r(s * x[1]), 0.0]}]})
    return {
        "format": "embra-scene",
        "version": 1,
        "name": "gridshell_chebyshev",
        "description": gridshell_chebyshev.__doc__.replace("\n    ", " ").strip(),
        "frames": 600,
        "solver": {"substeps": 10, "iterations": 100, "gravity": [0, 0, 9.81], "damping": 5.0, "realign_passes": 4,
                   "tethers": 0},
        "bodies": [{
            "name": "grid",
            "mesh": {"vertices": verts, "edges": edges, "masses": [2.0] * len(verts)},
            "generate": [],
        }],
        "constraints": [{"kind": "distance", "particles": edges, "rest": [a] * len(edges), "compliance": 0}],
        "pins": pins,
        "actions": actions,
    }


def conical_dome():
    """A quad grid on a dome form-found conical: 9 x 9 vertices 0.5 m apart in plan on the
    paraboloid z = 1.2 - 0.15 (x^2 + y^2) (4 m square, 1.2 m rise; its quads are planar, being a
    translational surface, but its vertices are not conical). Every quad held planar (planarity,
    hard) and every interior vertex conical (the angle criterion, hard), the four corners pinned,
    no gravity: the grid moves the least it must to become a conical mesh, whose panels have an
    exact face offset (examples/conical_panels.c builds them and measures them)."""
    n, a = 9, 0.5
    c = 0.5 * (n - 1) * a
    idx = lambda i, j: j * n + i  # noqa: E731
    verts = []
    for j in range(n):
        for i in range(n):
            x, y = i * a - c, j * a - c
            verts.append([r(x), r(y), r(1.2 - 0.15 * (x * x + y * y))])
    quads = [[idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)] for j in range(n - 1) for i in range(n - 1)]
    stars = [[idx(i, j), idx(i + 1, j), idx(i, j + 1), idx(i - 1, j), idx(i, j - 1)]
             for j in range(1, n - 1) for i in range(1, n - 1)]
    corners = [idx(0, 0), idx(n - 1, 0), idx(n - 1, n - 1), idx(0, n - 1)]
    edges = [[idx(i, j), idx(i + 1, j)] for j in range(n) for i in range(n - 1)]  # drawn, not constraints
    edges += [[idx(i, j), idx(i, j + 1)] for j in range(n - 1) for i in range(n)]
    return {
        "format": "embra-scene",
        "version": 1,
        "name": "conical_dome",
        "description": conical_dome.__doc__.replace("\n    ", " ").strip(),
        "frames": 300,
        "solver": {"substeps": 1, "iterations": 50, "gravity": [0, 0, 0], "damping": 30.0, "settle_speed": 1e-9,
                   "tethers": 0},
        "bodies": [{
            "name": "dome",
            "mesh": {"vertices": verts, "edges": edges, "masses": [1.0] * len(verts)},
            "generate": [],
        }],
        "constraints": [
            {"kind": "planarity", "particles": quads, "rest": [0.0] * len(quads)},
            {"kind": "conical", "particles": stars, "rest": [0.0] * len(stars)},
        ],
        "pins": [{"name": f"corner{k}", "particle": {"body": "dome", "vertex": v}} for k, v in enumerate(corners)],
    }


def plastic_hinge():
    """A plastic hinge that keeps its fold: a square plate 0.5 m wide, hinged along the y axis to
    a fixed plate, its free edge's mid point a particle of 1 kg 0.5 m from the hinge (held there by
    two hard distances to the hinge's ends). The hinge is a dihedral of rest 0 (flat), compliance
    0.2 rad/(N m), yielding past 0.4905 rad. Gravity grows from 0 to 9.81 m/s^2 over 300 frames
    (quasi-static), is held until frame 1200 and taken away by frame 1260: loaded, the flap folds
    down until its weight's moment m g r cos(phi) falls to the plastic moment yield / compliance
    (cos(phi) = 1/2: 60 degrees); unloaded, it springs back by the yield angle and keeps a fold of
    60 degrees less 0.4905 rad."""
    r, w = 0.5, 0.5
    verts = [[0.0, -w / 2, 0.0], [0.0, w / 2, 0.0], [-r, 0.0, 0.0], [r, 0.0, 0.0]]
    g = 9.81
    alpha, m = 0.2, 1.0
    yield_angle = r * m * g * alpha * 0.5  # the plastic moment m g r cos(60 deg), times the compliance
    return {
        "format": "embra-scene",
        "version": 1,
        "name": "plastic_hinge",
        "description": plastic_hinge.__doc__.replace("\n    ", " ").strip(),
        "frames": 1800,
        "solver": {"substeps": 10, "iterations": 20, "gravity": [0, 0, 0], "damping": 10.0, "realign_passes": 4,
                   "tethers": 0, "settle_speed": 1e-6},
        "bodies": [{
            "name": "plate",
            "mesh": {"vertices": verts, "triangles": [[0, 1, 2], [1, 0, 3]], "masses": [0.0, 0.0, 0.0, m]},
            "generate": [],
        }],
        "constraints": [
            {"kind": "distance", "particles": [[3, 0], [3, 1]]},
            {"kind": "dihedral", "particles": [[0, 1, 2, 3]], "rest": [0.0], "compliance": alpha,
             "yield": r_(yield_angle)},
        ],
        "actions": [{"type": "gravity", "keys": [{"frame": 0, "value": [0, 0, 0]}, {"frame": 300, "value": [0, 0, -g]},
                                                 {"frame": 1200, "value": [0, 0, -g]}, {"frame": 1260, "value": [0, 0, 0]}]}],
    }


def r_(v):
    return round(v, 15)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "examples")
    dump(os.path.join(out, "cable_net_roof.json"), cable_net_roof())
    dump(os.path.join(out, "gridshell_chebyshev.json"), gridshell_chebyshev())
    dump(os.path.join(out, "conical_dome.json"), conical_dome())
    dump(os.path.join(out, "plastic_hinge.json"), plastic_hinge())


if __name__ == "__main__":
    main()
