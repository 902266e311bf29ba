#!/usr/bin/env python3
"""Turns a polydem bodies file (`polydem bench initial SCENE --out FILE`) of spheres in an open
box into a LIGGGHTS data file (atom_style granular) and the box's walls as LIGGGHTS commands, so
that LIGGGHTS starts from the very bodies and walls polydem starts from.

    bodies_to_data.py BODIES DATA

writes DATA and DATA.walls (commands spheres.in includes), and for mesh walls DATA.stl.

- Plane walls (`plane` lines, axis-aligned): one `wall/gran ... primitive` per plane. The data
  file's box is the planes' box: its x and y faces and its floor are the side walls and the floor.
- Mesh walls (`triangle` lines): the triangles, as polydem placed them, go to DATA.stl, and one
  `mesh/surface` with a `wall/gran ... mesh` holds them. The data file's box is the triangles'
  box, 1 mm wider on every side, so that no triangle lies on the box's boundary.

In both, the box's top is the highest sphere plus half the fill's height (the box is open at the
top in polydem; nothing rises that far in a settling bed). DATA.walls also defines the per-sphere
variable `on_wall` (1 for each wall the sphere's centre is closer to than its radius), found from
the axis-aligned planes, or from the axis-aligned planes the mesh's triangles lie in: spheres.in
counts the wall contacts with it. It uses the rolling model `${rolling_model}` and the per-sphere
radius `c_rad` that spheres.in defines before including DATA.walls.
"""

import sys

MODEL = "model hertz tangential history rolling_friction ${rolling_model}"
MARGIN = 0.001


def axis_aligned(normal):
    """(axis, sign) of a normal along a coordinate axis, or None."""
    axes = [a for a in range(3) if abs(normal[a]) > 1e-12]
    if len(axes) != 1:
        return None
    return axes[0], (1 if normal[axes[0]] > 0 else -1)


def sub(p, q):
    return [p[k] - q[k] for k in range(3)]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def read(bodies_file):
    spheres, planes, triangles = [], [], []
    with open(bodies_file) as f:
        for line in f:
            fields = line.split()
            if not fields or fields[0].startswith("#"):
                continue
            if fields[0] == "plane":
                point = [float(v) for v in fields[1:4]]
                normal = [float(v) for v in fields[4:7]]
                aligned = axis_aligned(normal)
                if aligned is None:
                    sys.exit(f"{bodies_file}: only axis-aligned planes are supported: {line.strip()}")
                planes.append((aligned[0], aligned[1], point[aligned[0]]))
            elif fields[0] == "triangle":
                v = [float(x) for x in fields[2:11]]
                triangles.append((v[0:3], v[3:6], v[6:9]))
            elif fields[0] == "sphere":
                x, y, z, r, density = (float(v) for v in fields[1:6])
                spheres.append((x, y, z, r, density))
            else:
                sys.exit(f"{bodies_file}: LIGGGHTS takes spheres only, not '{fields[0]}'")
    if not spheres:
        sys.exit(f"{bodies_file}: no spheres")
    if planes and triangles:
        sys.exit(f"{bodies_file}: planes and mesh walls together are not supported")
    return spheres, planes, triangles


def mesh_planes(triangles):
    """The distinct axis-aligned planes (axis, sign, coordinate) the triangles lie in."""
    found = set()
    for a, b, c in triangles:
        aligned = axis_aligned(cross(sub(b, a), sub(c, a)))
        if aligned is not None:
            found.add((aligned[0], aligned[1], a[aligned[0]]))
    return sorted(found)


def write_stl(path, triangles):
    with open(path, "w") as out:
        out.write("solid polydem\n")
        for a, b, c in triangles:
            n = cross(sub(b, a), sub(c, a))
            length = sum(x * x for x in n) ** 0.5
            out.write("  facet normal {!r} {!r} {!r}\n    outer loop\n".format(*(x / length for x in n)))
            for p in (a, b, c):
                out.write("      vertex {!r} {!r} {!r}\n".format(*p))
            out.write("    endloop\n  endfacet\n")
        out.write("endsolid polydem\n")


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    bodies_file, data_file = sys.argv[1], sys.argv[2]
    spheres, planes, triangles = read(bodies_file)
    walls = []
    lo, hi = [None] * 3, [None] * 3
    if planes:
        for axis, sign, at in planes:
            (lo if sign > 0 else hi)[axis] = at
        if None in lo or hi[0] is None or hi[1] is None or hi[2] is not None:
            sys.exit(f"{bodies_file}: expected an open box: a floor (+z) and four side walls")
        for k, (axis, sign, at) in enumerate(planes):
            walls.append(f"fix wall{k} all wall/gran {MODEL} primitive type 1 {'xyz'[axis]}plane {at!r}")
        counted = planes
    elif triangles:
        for axis in range(3):
            values = [p[axis] for t in triangles for p in t]
            lo[axis], hi[axis] = min(values) - MARGIN, max(values) + MARGIN
        stl = data_file + ".stl"
        write_stl(stl, triangles)
        walls.append(f"fix cad all mesh/surface file {stl} type 1")
        walls.append(f"fix walls all wall/gran {MODEL} mesh n_meshes 1 meshes cad")
        counted = mesh_planes(triangles)
    else:
        sys.exit(f"{bodies_file}: no walls")
    top = max(z + r for (_, _, z, r, _) in spheres)
    hi[2] = max(hi[2] if triangles else top, top + 0.5 * (top - lo[2]))
    terms = [
        f"({'xyz'[axis]}-({at!r})<c_rad)" if sign > 0 else f"(({at!r})-{'xyz'[axis]}<c_rad)"
        for axis, sign, at in counted
    ]
    walls.append(f'variable on_wall atom "{"+".join(terms) if terms else "0"}"')
    with open(data_file + ".walls", "w") as out:
        out.write(f"# The walls of {bodies_file} (bodies_to_data.py)\n")
        out.write("\n".join(walls) + "\n")
    with open(data_file, "w") as out:
        out.write(f"LIGGGHTS data file from {bodies_file} (polydem bench initial)\n\n")
        out.write(f"{len(spheres)} atoms\n1 atom types\n\n")
        for a, name in enumerate("xyz"):
            out.write(f"{lo[a]!r} {hi[a]!r} {name}lo {name}hi\n")
        out.write("\nAtoms\n\n")
        # atom_style granular: atom-ID atom-type diameter density x y z
        for i, (x, y, z, r, density) in enumerate(spheres, start=1):
            out.write(f"{i} 1 {2.0 * r!r} {density!r} {x!r} {y!r} {z!r}\n")


if __name__ == "__main__":
    main()
