#!/usr/bin/env python3
"""Writes bench/open_box_60mm.stl, the walls of bench/spheres_10k_mesh.toml: the open box of
bench/spheres_10k.toml (floor and four side walls, 60 mm x 60 mm, 60 mm high) as one triangle mesh,
each face cut into 10 mm squares of two triangles (360 triangles), wound so that the normals point
into the box, where the spheres are. ASCII STL in metres.

    python3 bench/open_box_stl.py > bench/open_box_60mm.stl
"""

SIDE = 0.06
HEIGHT = 0.06
CELLS = 6


def quad_grid(origin, u, v, n):
    """Triangles of the rectangle origin + s u + t v (s, t in [0, 1]), n x n squares, wound
    counter-clockwise seen from u x v."""
    def at(i, j):
        return tuple(origin[k] + u[k] * i / n + v[k] * j / n for k in range(3))

    for i in range(n):
        for j in range(n):
            a, b, c, d = at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)
            yield (a, b, c)
            yield (a, c, d)


def faces():
    s, h = SIDE, HEIGHT
    # Each face as origin and two edges (main() turns them to face into the box).
    yield (0, 0, 0), (s, 0, 0), (0, s, 0)  # floor, z = 0
    yield (0, 0, 0), (0, s, 0), (0, 0, h)  # x = 0
    yield (s, 0, 0), (0, s, 0), (0, 0, h)  # x = 60 mm
    yield (0, 0, 0), (s, 0, 0), (0, 0, h)  # y = 0
    yield (0, s, 0), (s, 0, 0), (0, 0, h)  # y = 60 mm


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def main():
    print("solid open_box_60mm")
    for origin, u, v in faces():
        n = cross(u, v)
        length = sum(c * c for c in n) ** 0.5
        n = tuple(c / length + 0.0 for c in n)
        inward = (SIDE / 2 - origin[0], SIDE / 2 - origin[1], HEIGHT / 2 - origin[2])
        if sum(n[k] * inward[k] for k in range(3)) < 0:
            u, v, n = v, u, tuple(0.0 - c for c in n)
        for tri in quad_grid(origin, u, v, CELLS):
            print(f"  facet normal {n[0]:g} {n[1]:g} {n[2]:g}")
            print("    outer loop")
            for p in tri:
                print(f"      vertex {p[0]:.6g} {p[1]:.6g} {p[2]:.6g}")
            print("    endloop")
            print("  endfacet")
    print("endsolid open_box_60mm")


if __name__ == "__main__":
    main()
