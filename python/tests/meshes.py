"""Meshes for the tests: the shared scenes' OBJ files and closed procedural
meshes with shared vertices (every edge used by exactly two triangles,
counter-clockwise seen from outside)."""
import os
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]


def scenes_dir():
    """$RTCL_SCENES_DIR, else ../shared/scenes beside the repository."""
    return Path(os.environ.get("RTCL_SCENES_DIR", REPO.parent / "shared" / "scenes"))


def mesh_file(relative):
    """The path of a shared mesh under scenes_dir(). A missing mesh fails
    the test, as in the C++ suite (tests/support/fixtures.hpp: every test
    finds meshes there and fails when one is missing), never skips it."""
    path = scenes_dir() / relative
    if not path.is_file():
        pytest.fail(f"{path} not found: the tests need the shared meshes (set RTCL_SCENES_DIR; "
                    "docs/test-meshes.md)", pytrace=False)
    return path


def load_obj(path):
    """Vertices (N, 3) float32 and triangles (M, 3) uint32 of an OBJ file of
    `v x y z` and `f a b c ...` lines (polygons fanned, 1-based and negative
    indices, `a/b/c` references reduced to the vertex)."""
    vertices, faces = [], []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                vertices.append(line.split()[1:4])
            elif line.startswith("f "):
                refs = [int(r.split("/")[0]) for r in line.split()[1:]]
                refs = [r - 1 if r > 0 else len(vertices) + r for r in refs]
                for k in range(1, len(refs) - 1):
                    faces.append((refs[0], refs[k], refs[k + 1]))
    return np.array(vertices, np.float32), np.array(faces, np.uint32)


def cube_grid(n=2, half=1.0):
    """The cube [-half, half]^3, each face an n x n grid of quads split into
    two triangles with alternating diagonals; vertices shared between faces."""
    index = {}
    vertices, triangles = [], []

    def vertex(p):
        key = tuple(int(round(c)) for c in p)  # grid coordinates
        if key not in index:
            index[key] = len(vertices)
            vertices.append([c * 2.0 * half / n - half for c in key])
        return index[key]

    for axis in range(3):
        for side in (0, n):
            u, v = (axis + 1) % 3, (axis + 2) % 3
            for i in range(n):
                for j in range(n):
                    corners = []
                    for di, dj in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        p = [0, 0, 0]
                        p[axis], p[u], p[v] = side, i + di, j + dj
                        corners.append(vertex(p))
                    a, b, c, d = corners
                    # (u, v) is counter-clockwise seen from +axis.
                    quad = [(a, b, c), (a, c, d)] if (i + j) % 2 == 0 else [(a, b, d), (b, c, d)]
                    for t in quad:
                        triangles.append(t if side == n else (t[0], t[2], t[1]))
    return np.array(vertices, np.float32), np.array(triangles, np.uint32)


def icosphere(levels=2, radius=1.0):
    """The icosahedron subdivided `levels` times, vertices on the sphere."""
    p = (1.0 + 5.0 ** 0.5) / 2.0
    verts = [(-1, p, 0), (1, p, 0), (-1, -p, 0), (1, -p, 0), (0, -1, p), (0, 1, p),
             (0, -1, -p), (0, 1, -p), (p, 0, -1), (p, 0, 1), (-p, 0, -1), (-p, 0, 1)]
    verts = [np.array(v, float) / np.linalg.norm(v) for v in verts]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
             (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
             (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(levels):
        middle = {}

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in middle:
                m = verts[a] + verts[b]
                middle[key] = len(verts)
                verts.append(m / np.linalg.norm(m))
            return middle[key]

        faces = [t for a, b, c in faces
                 for ab, bc, ca in [(mid(a, b), mid(b, c), mid(c, a))]
                 for t in ((a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca))]
    return (np.array(verts) * radius).astype(np.float32), np.array(faces, np.uint32)


def open_edges(triangles):
    """Edges not used exactly once in each direction: 0 for a closed mesh."""
    directed = {}
    for a, b, c in triangles.tolist():
        for e in ((a, b), (b, c), (c, a)):
            directed[e] = directed.get(e, 0) + 1
    return sum(1 for (a, b), k in directed.items() if k != 1 or directed.get((b, a)) != 1)
