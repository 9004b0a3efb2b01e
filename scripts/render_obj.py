#!/usr/bin/python3
"""Renders OBJ meshes written by `embra` to a PNG (Debian's python3-matplotlib, which
scripts/deps.sh installs): faces shaded, and `l` lines (a hanging net's links) drawn as lines.

usage: scripts/render_obj.py OUT.png MESH.obj [MESH.obj ...] [--title T] [--elev E] [--azim A]
Several meshes are drawn side by side (e.g. frames of a run)."""
import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection  # noqa: E402
import numpy as np  # noqa: E402


def read_obj(path):
    verts, faces, lines = [], [], []
    with open(path) as f:
        for line in f:
            p = line.split()
            if not p:
                continue
            if p[0] == "v":
                verts.append([float(c) for c in p[1:4]])
            elif p[0] == "f":
                faces.append([int(c.split("/")[0]) - 1 for c in p[1:]])
            elif p[0] == "l":
                ids = [int(c.split("/")[0]) - 1 for c in p[1:]]
                lines.extend(zip(ids, ids[1:]))
    return np.array(verts), faces, lines


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("meshes", nargs="+")
    ap.add_argument("--title", action="append", default=[])
    ap.add_argument("--elev", type=float, default=25)
    ap.add_argument("--azim", type=float, default=-60)
    a = ap.parse_args()
    n = len(a.meshes)
    fig = plt.figure(figsize=(4.2 * n, 4.2), dpi=110)
    light = np.array([0.3, -0.5, 1.0])
    light /= np.linalg.norm(light)
    for k, path in enumerate(a.meshes):
        v, faces, lines = read_obj(path)
        ax = fig.add_subplot(1, n, k + 1, projection="3d")
        polys = [v[f] for f in faces]
        shade = []
        for p in polys:
            nrm = np.cross(p[1] - p[0], p[2] - p[0])
            nrm /= max(np.linalg.norm(nrm), 1e-300)
            shade.append(0.35 + 0.6 * abs(nrm @ light))
        colors = [(0.85 * s, 0.78 * s, 0.62 * s) for s in shade]
        if polys:
            ax.add_collection3d(Poly3DCollection(polys, facecolors=colors, edgecolors=(0, 0, 0, 0.08), linewidths=0.2))
        if lines:
            ax.add_collection3d(Line3DCollection([v[[a, b]] for a, b in lines], colors=(0.25, 0.2, 0.12), linewidths=0.8))
        lo, hi = v.min(axis=0), v.max(axis=0)
        c, r = (lo + hi) / 2, (hi - lo).max() / 2
        ax.set_xlim(c[0] - r, c[0] + r)
        ax.set_ylim(c[1] - r, c[1] + r)
        ax.set_zlim(c[2] - r, c[2] + r)
        ax.set_box_aspect((1, 1, 1))
        ax.view_init(a.elev, a.azim)
        ax.set_axis_off()
        if k < len(a.title):
            ax.set_title(a.title[k])
    fig.tight_layout()
    fig.savefig(a.out)


if __name__ == "__main__":
    main()
