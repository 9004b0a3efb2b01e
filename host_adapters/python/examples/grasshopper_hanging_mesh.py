"""embra in Rhino 8: a Grasshopper Python 3 component (or, with the inputs set at the top, a script in
Rhino 8's Python 3 editor) that hangs a mesh from anchor points under gravity, the way the paper's
hanging models find a vault upside down.

Inputs (the component's parameters; Item access unless noted):
  mesh        Mesh: the net at rest (quads and triangles; its edges become stretch constraints)
  anchors     Point3d, List access: each pins the mesh vertex nearest to it to the point itself
              (anchors closer together than the mesh is wide leave it slack, so it sags)
  frames      int: frames of 1/60 s to step (60 when not given)
  embra_path  str: the folder holding the `embra` package with embra.dll inside it (the Windows
              zip's python folder); not needed when embra is already importable
Outputs:
  result      Mesh: the same faces on the vertices where they hang
  support     float: the anchors' vertical reactions summed (N); at rest they carry the weight
  settled     bool: the world came to rest

It calls only these RhinoCommon members: Mesh(), Mesh.Vertices (iterated for X, Y, Z; Add(x, y, z)),
Mesh.Faces (iterated for A, B, C, D, IsQuad; AddFace), Mesh.Normals.ComputeNormals(), Point3d's
X, Y, Z.
"""
import sys

import Rhino.Geometry as rg

if globals().get("embra_path") and embra_path not in sys.path:  # noqa: F821 - a component input
    sys.path.insert(0, embra_path)  # noqa: F821
import embra  # noqa: E402

MASS = 1.0  # kg, the whole net


def mesh_arrays(m):
    """The mesh's vertices (x, y, z) and faces as vertex-index tuples (3 or 4)."""
    xyz = [(v.X, v.Y, v.Z) for v in m.Vertices]
    faces = [(f.A, f.B, f.C, f.D) if f.IsQuad else (f.A, f.B, f.C) for f in m.Faces]
    return xyz, faces


def face_edges(faces):
    """Every edge of the faces once: a quad's four sides, not its diagonal (a net, not a sheet)."""
    edges = set()
    for f in faces:
        for k in range(len(f)):
            a, b = f[k], f[(k + 1) % len(f)]
            edges.add((min(a, b), max(a, b)))
    return sorted(edges)


def nearest(xyz, p):
    return min(range(len(xyz)), key=lambda i: (xyz[i][0] - p.X) ** 2 + (xyz[i][1] - p.Y) ** 2 + (xyz[i][2] - p.Z) ** 2)


xyz, faces = mesh_arrays(mesh)  # noqa: F821 - a component input
with embra.World(gravity=(0.0, 0.0, -9.81)) as world:
    # damping brings the net to rest; realign_passes evaluates the reactions (support) where each
    # substep ends, so that at rest they balance the weight
    world.set_solver(damping=2.0, substeps=20, realign_passes=3)
    net = world.create_body(xyz, edges=face_edges(faces), generate=["stretch"], mass=MASS)
    for p in anchors:  # noqa: F821 - a component input
        world.create_pin(net.first + nearest(xyz, p), (p.X, p.Y, p.Z))
    world.step(int(globals().get("frames") or 60))
    hung = world.positions(net.first, net.count)  # numpy (n, 3) when numpy is there, else flat
    hung = hung.reshape(-1).tolist() if hasattr(hung, "reshape") else list(hung)
    support = sum(r["force"][2] for r in world.reactions())
    settled = bool(world.report().settled)

result = rg.Mesh()
for k in range(0, len(hung), 3):
    result.Vertices.Add(hung[k], hung[k + 1], hung[k + 2])
for f in faces:
    result.Faces.AddFace(*f)
result.Normals.ComputeNormals()
