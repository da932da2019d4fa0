"""Writes bottle_body.obj, the body of the shipped `bottle` object (models/objects/bottle.xml):
a solid of revolution, 35 mm radius up to 140 mm, a shoulder narrowing to the 12 mm neck at
185 mm, closed at both ends. The profile narrows monotonically, so the solid is convex (MuJoCo and
rapier collide it as its convex hull, which is then exact). Metres, z up, origin at the foot.

usage: python3 make_bottle.py   (rewrites bottle_body.obj beside this script)
"""
import math
import os

# (height, radius) of the profile, bottom to top [m].
PROFILE = [(0.0, 0.033), (0.002, 0.035), (0.14, 0.035), (0.16, 0.031), (0.175, 0.022), (0.185, 0.012)]
SIDES = 32


def main():
    vertices, faces = [], []
    for z, r in PROFILE:
        for k in range(SIDES):
            a = 2 * math.pi * k / SIDES
            vertices.append((r * math.cos(a), r * math.sin(a), z))
    ring = lambda i, k: i * SIDES + (k % SIDES) + 1  # OBJ indices start at 1
    for i in range(len(PROFILE) - 1):
        for k in range(SIDES):
            a, b, c, d = ring(i, k), ring(i, k + 1), ring(i + 1, k + 1), ring(i + 1, k)
            faces += [(a, b, c), (a, c, d)]
    bottom, top = len(vertices) + 1, len(vertices) + 2
    vertices += [(0.0, 0.0, PROFILE[0][0]), (0.0, 0.0, PROFILE[-1][0])]
    last = len(PROFILE) - 1
    for k in range(SIDES):
        faces.append((bottom, ring(0, k + 1), ring(0, k)))
        faces.append((top, ring(last, k), ring(last, k + 1)))
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "bottle_body.obj")
    with open(path, "w") as f:
        f.write("# bottle body, written by make_bottle.py\n")
        for v in vertices:
            f.write("v %.6f %.6f %.6f\n" % v)
        for t in faces:
            f.write("f %d %d %d\n" % t)
    print(path)


if __name__ == "__main__":
    main()
