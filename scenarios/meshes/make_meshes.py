#!/usr/bin/env python3
"""Writes the example body meshes of scenarios/mesh-bodies.json (docs/rendering.md, "Meshes").

rock.obj:  a low-poly boulder, an icosphere (one subdivision) with each vertex pushed in or out by
           a deterministic hash, fitted to its collision sphere of radius 0.4 m (the mesh is looks
           only: the sphere stays the collision proxy). Flat faces: no normals, the renderer
           computes smooth ones.
crate.obj: a 0.7 m wooden crate (collision box, half extents 0.35) with a lid 2 cm wider, as
           quads with explicit face normals (v//vn).
Deterministic: rerunning gives the same bytes.
"""
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))


def icosphere():
    t = (1 + 5 ** 0.5) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
         (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    v = [tuple(c / math.sqrt(sum(x * x for x in p)) for c in p) for p in v]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6),
         (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10),
         (8, 6, 7), (9, 8, 1)]
    mid = {}

    def midpoint(a, b):
        key = (min(a, b), max(a, b))
        if key not in mid:
            p = [(v[a][k] + v[b][k]) / 2 for k in range(3)]
            n = math.sqrt(sum(x * x for x in p))
            v.append(tuple(x / n for x in p))
            mid[key] = len(v) - 1
        return mid[key]

    faces = []
    for a, b, c in f:
        ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
        faces += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
    return v, faces


def write_rock():
    v, faces = icosphere()
    lines = ["# Low-poly rock for scenarios/mesh-bodies.json (make_meshes.py). Metres, body frame.",
             "# Collision proxy: a sphere of radius 0.4 m.", "o rock"]
    for i, p in enumerate(v):
        h = (i * 2654435761 + 12345) % 4294967296 / 4294967296.0  # deterministic per vertex
        r = 0.4 * (0.86 + 0.22 * h)
        squash = 0.8 if p[1] > 0 else 1.0  # flatter on top
        lines.append("v %.4f %.4f %.4f" % (p[0] * r, p[1] * r * squash, p[2] * r))
    for a, b, c in faces:
        lines.append("f %d %d %d" % (a + 1, b + 1, c + 1))
    return lines


def box(lines, lo, hi, vbase):
    """Appends a box's 8 vertices and 6 quads (v//vn, normals 1..6 written first)."""
    for x in (lo[0], hi[0]):
        for y in (lo[1], hi[1]):
            for z in (lo[2], hi[2]):
                lines.append("v %.4f %.4f %.4f" % (x, y, z))
    idx = lambda x, y, z: vbase + x * 4 + y * 2 + z + 1
    quads = [((0, 0, 0), (0, 0, 1), (0, 1, 1), (0, 1, 0), 1), ((1, 0, 0), (1, 1, 0), (1, 1, 1), (1, 0, 1), 2),
             ((0, 0, 0), (1, 0, 0), (1, 0, 1), (0, 0, 1), 3), ((0, 1, 0), (0, 1, 1), (1, 1, 1), (1, 1, 0), 4),
             ((0, 0, 0), (0, 1, 0), (1, 1, 0), (1, 0, 0), 5), ((0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1), 6)]
    for a, b, c, d, n in quads:
        lines.append("f " + " ".join("%d//%d" % (idx(*p), n) for p in (a, b, c, d)))
    return vbase + 8


def write_crate():
    lines = ["# Wooden crate for scenarios/mesh-bodies.json (make_meshes.py). Metres, body frame.",
             "# Collision proxy: a box of half extents 0.35 m.", "o crate",
             "vn -1 0 0", "vn 1 0 0", "vn 0 -1 0", "vn 0 1 0", "vn 0 0 -1", "vn 0 0 1"]
    n = box(lines, (-0.35, -0.35, -0.35), (0.35, 0.27, 0.35), 0)
    box(lines, (-0.37, 0.27, -0.37), (0.37, 0.35, 0.37), n)
    return lines


for name, lines in (("rock.obj", write_rock()), ("crate.obj", write_crate())):
    with open(os.path.join(HERE, name), "w") as f:
        f.write("\n".join(lines) + "\n")
