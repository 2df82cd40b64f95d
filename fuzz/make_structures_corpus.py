#!/usr/bin/python3
"""Writes the seed corpus of the structures fuzz target (fuzz/structures_fuzz.cpp)
into fuzz/corpus/structures/: a few scenes spelled out in the target's byte
encoding (a closed tetrahedron hit at its vertices and edges, coincident and
flipped duplicates, slivers and tiny triangles far from the origin, a huge
triangle with spheres, rays lying in face planes and starting on surfaces),
then pseudo-random inputs from fixed seeds. Deterministic: the same files on
every run.

    /usr/bin/python3 fuzz/make_structures_corpus.py
"""
import os
import random

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus", "structures")

# make_scene's opcodes (the byte's value modulo 8) and make_rays' choices.
TRIANGLE, COPY, SLIVER, COLLINEAR, HUGE, TINY, STRIP_OR_SPHERE = 0, 2, 3, 4, 5, 6, 7
VERTEX, EDGE, INTERIOR, SILHOUETTE, ANYWHERE = 0, 1, 2, 3, 4
AXIS, NORMAL, IN_PLANE, COMPONENTS, ANY_DIRECTION = 0, 1, 2, 3, 4
ON_TARGET = 0x20  # the direction byte's flag: the origin on the target
FULL, ENDS_AT, STARTS_AT, ONLY_AT = 7, 0, 1, 2


def i8(value):
    """A lattice coordinate (value in [-16, 16), steps of 1/8) as its byte."""
    return int(round(value * 8)) & 0xFF


def scene(points, ops, scale_exponent=0, offset=None):
    out = [scale_exponent + 20]
    if offset is None:
        out.append(1)  # odd: no offset
    else:
        far, frac = offset
        out += [0, far] + list(frac)
    out.append(len(points) - 3)
    for p in points:
        out += [i8(c) for c in p]
    out.append(len(ops) - 1)
    for op in ops:
        out += op
    return out


def rays(specs):
    out = [len(specs) - 1]
    for spec in specs:
        out += spec
    return out


def write(name, data):
    with open(os.path.join(OUT, name), "wb") as f:
        f.write(bytes(data))


def main():
    os.makedirs(OUT, exist_ok=True)
    tetra = [(0, 0, 0), (4, 0, 0), (0, 4, 0), (0, 0, 4)]
    closed = [[TRIANGLE, 0, 2, 1], [TRIANGLE, 0, 1, 3], [TRIANGLE, 0, 3, 2], [TRIANGLE, 1, 2, 3]]
    # Vertices and edge points, axis-parallel with -0 / +0 components, from far and from the surface.
    at_corners = []
    for tri in range(4):
        for corner in range(3):
            at_corners.append([tri, VERTEX, corner, AXIS, corner, 0, 1, 0, tri & 1, 200, FULL])
            at_corners.append([tri, EDGE, corner, 128, NORMAL, 1, 90, FULL])
            at_corners.append([tri, EDGE, corner, 0, AXIS | ON_TARGET, corner, 1, 1, 1, 0, FULL])
    # Interior points from far away, along the normal and in any direction: clear hits.
    at_corners += [[tri, INTERIOR, 1 + tri, 2, 3, NORMAL, tri & 1, 255, FULL] for tri in range(4)]
    at_corners += [[tri, INTERIOR, 5, 5, 5, ANY_DIRECTION, 10 * tri, 90, 200, 180, FULL] for tri in range(4)]
    write("tetrahedron_vertices_edges", scene(tetra, closed) + rays(at_corners))
    # Coincident duplicates, one with the other winding: ties of t.
    pair = [(0, 0, 0), (4, 0, 0), (0, 4, 0), (4, 4, 0)]
    dup = [[TRIANGLE, 0, 1, 2], [COPY, 0, 1], [TRIANGLE, 1, 3, 2], [COPY, 0, 0]]
    tie_rays = [[t, INTERIOR, 1, 1, 1, NORMAL, 0, 50, FULL] for t in range(4)]
    tie_rays += [[t, EDGE, 1, 128, COMPONENTS, 3, 40, 1, 8, 0, 120, FULL] for t in range(4)]
    write("coincident_duplicates", scene(pair, dup) + rays(tie_rays))
    # Slivers, collinear and tiny triangles, 2^-20 scale, far from the origin.
    small = scene(tetra, [[SLIVER, 0, 1, 100, 30], [COLLINEAR, 1, 2, 60], [TINY, 3, 22, 8, 8, 8, 8, 248, 8],
                          [SLIVER, 2, 3, 255, 5], [TRIANGLE, 0, 1, 2]],
                  scale_exponent=-20, offset=(23, (200, 10, 128)))
    write("slivers_tiny_far", small + rays([[t, VERTEX, 2, ANY_DIRECTION, 30, 200, 99, 140, FULL] for t in range(5)] +
                                           [[t, EDGE, 2, 77, ANY_DIRECTION, 30, 200, 99, 140, FULL] for t in range(5)]))
    # A huge triangle and spheres, 2^20 scale: sphere silhouettes.
    big = scene(tetra, [[HUGE, 0, 1, 2, 12], [STRIP_OR_SPHERE, 0, 3, 100, 3], [STRIP_OR_SPHERE, 0, 1, 0, 10],
                        [TRIANGLE, 1, 2, 3]], scale_exponent=20)
    write("huge_and_spheres", big + rays([[t, SILHOUETTE, s, 10, 200, 128, IN_PLANE, 0, 60, FULL]
                                          for t in range(2) for s in range(2)] +
                                         [[1, VERTEX, 0, AXIS, 2, 1, 0, 1, 1, 10, ENDS_AT]]))
    # A strip sharing edges; rays lying in its plane and rays that start or end on it.
    strip = scene([(0, 0, 0), (4, 0, 0), (0, 4, 0), (4, 4, 0), (8, 0, 0), (8, 4, 0)],
                  [[TRIANGLE, 0, 1, 2], [STRIP_OR_SPHERE, 1, 0, 3], [STRIP_OR_SPHERE, 1, 1, 4],
                   [STRIP_OR_SPHERE, 1, 2, 5]])
    plane_rays = [[t, EDGE, e, 128, IN_PLANE, e & 1, 150, FULL] for t in range(4) for e in range(3)]
    plane_rays += [[t, INTERIOR, 3, 5, 9, NORMAL | ON_TARGET, 0, interval] for t in range(4)
                   for interval in (STARTS_AT, ONLY_AT)]
    write("strip_in_plane_and_on_surface", strip + rays(plane_rays))
    # Pseudo-random inputs of several sizes.
    rng = random.Random(51)
    for i in range(20):
        write("random_%02d" % i, [rng.randrange(256) for _ in range(rng.choice((48, 96, 200, 400, 800)))])


if __name__ == "__main__":
    main()
