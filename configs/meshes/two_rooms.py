#!/usr/bin/python3
"""Writes two_rooms.obj: two 6 x 5 m rooms joined by a 1.2 m doorway.

Room A (x < 0) has a flat 2.5 m ceiling; room B (x > 0) has a ceiling sloping down from 2.5 m at the
dividing wall to 1.6 m at its far wall, so the two rooms look alike to a 2-D scanner but not in 3-D.
Run: /usr/bin/python3 configs/meshes/two_rooms.py  (writes next to this script)
"""
import os

verts, faces = [], []


def quad(a, b, c, d):
    base = len(verts)
    verts.extend([a, b, c, d])
    faces.append((base, base + 1, base + 2))
    faces.append((base, base + 2, base + 3))


def box(x0, x1, y0, y1, z0, z1):
    c = [(x, y, z) for z in (z0, z1) for y in (y0, y1) for x in (x0, x1)]
    for f in ((0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)):
        quad(*(c[i] for i in f))


def ceiling_b(x):  # height of room B's ceiling at x in [0, 6]
    return 2.5 - 0.15 * x


# Floor and ceilings.
quad((-6, -2.5, 0), (6, -2.5, 0), (6, 2.5, 0), (-6, 2.5, 0))
quad((-6, -2.5, 2.5), (-6, 2.5, 2.5), (0, 2.5, 2.5), (0, -2.5, 2.5))
quad((0, -2.5, 2.5), (0, 2.5, 2.5), (6, 2.5, ceiling_b(6)), (6, -2.5, ceiling_b(6)))
# Outer walls (room B's follow its sloping ceiling).
quad((-6, -2.5, 0), (-6, 2.5, 0), (-6, 2.5, 2.5), (-6, -2.5, 2.5))
quad((-6, -2.5, 0), (0, -2.5, 0), (0, -2.5, 2.5), (-6, -2.5, 2.5))
quad((-6, 2.5, 0), (-6, 2.5, 2.5), (0, 2.5, 2.5), (0, 2.5, 0))
quad((6, -2.5, 0), (6, -2.5, ceiling_b(6)), (6, 2.5, ceiling_b(6)), (6, 2.5, 0))
quad((0, -2.5, 0), (6, -2.5, 0), (6, -2.5, ceiling_b(6)), (0, -2.5, 2.5))
quad((0, 2.5, 0), (0, 2.5, 2.5), (6, 2.5, ceiling_b(6)), (6, 2.5, 0))
# Dividing wall, 0.2 m thick, with a 1.2 m wide, 2 m high doorway.
box(-0.1, 0.1, -2.5, -0.6, 0, 2.5)
box(-0.1, 0.1, 0.6, 2.5, 0, 2.5)
box(-0.1, 0.1, -0.6, 0.6, 2.0, 2.5)

out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "two_rooms.obj")
with open(out, "w") as f:
    f.write("# two_rooms.obj, written by two_rooms.py: two 6 x 5 m rooms, one with a sloping ceiling\n")
    for v in verts:
        f.write("v %g %g %g\n" % v)
    for a, b, c in faces:
        f.write("f %d %d %d\n" % (a + 1, b + 1, c + 1))
