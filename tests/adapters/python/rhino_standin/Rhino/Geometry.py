"""Rhino.Geometry's Point3d and Mesh, as far as the Grasshopper example uses them, with RhinoCommon's
names and meanings: a MeshFace with C == D is a triangle; Vertices.Add and Faces.AddFace return the
new index."""


class Point3d:
    def __init__(self, x, y, z):
        self.X, self.Y, self.Z = float(x), float(y), float(z)


class MeshFace:
    def __init__(self, a, b, c, d=None):
        self.A, self.B, self.C = a, b, c
        self.D = c if d is None else d

    @property
    def IsQuad(self):
        return self.C != self.D

    @property
    def IsTriangle(self):
        return self.C == self.D


class _Vertices(list):
    def Add(self, x, y, z):
        self.append(Point3d(x, y, z))
        return len(self) - 1

    @property
    def Count(self):
        return len(self)


class _Faces(list):
    def AddFace(self, a, b, c, d=None):
        self.append(MeshFace(a, b, c, d))
        return len(self) - 1

    @property
    def Count(self):
        return len(self)


class _Normals(list):
    def ComputeNormals(self):
        self.computed = True
        return True


class Mesh:
    def __init__(self):
        self.Vertices = _Vertices()
        self.Faces = _Faces()
        self.Normals = _Normals()
