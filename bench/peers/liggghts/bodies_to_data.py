#!/usr/bin/env python3
"""Turns a polydem bodies file (`polydem bench initial SCENE --out FILE`) of spheres in an open
box of axis-aligned planes into a LIGGGHTS data file (atom_style granular), so that LIGGGHTS starts
from the very bodies polydem starts from.

    bodies_to_data.py BODIES DATA

The data file's box is the planes' box: its x and y faces and its floor are the side walls and the
floor (spheres.in puts its walls on the box faces); its top is the highest sphere plus half the
fill's height (the box is open at the top in polydem; nothing rises that far in a settling bed).
"""

import sys


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    bodies_file, data_file = sys.argv[1], sys.argv[2]
    spheres, lo, hi = [], [None] * 3, [None] * 3
    with open(bodies_file) as f:
        for line in f:
            fields = line.split()
            if not fields or fields[0].startswith("#"):
                continue
            if fields[0] == "plane":
                point = [float(v) for v in fields[1:4]]
                normal = [float(v) for v in fields[4:7]]
                axes = [a for a in range(3) if abs(normal[a]) > 1e-12]
                if len(axes) != 1:
                    sys.exit(f"{bodies_file}: only axis-aligned planes are supported: {line.strip()}")
                a = axes[0]
                if normal[a] > 0:
                    lo[a] = point[a]
                else:
                    hi[a] = point[a]
            elif fields[0] == "sphere":
                x, y, z, r, density = (float(v) for v in fields[1:6])
                spheres.append((x, y, z, r, density))
            else:
                sys.exit(f"{bodies_file}: LIGGGHTS takes spheres only, not '{fields[0]}'")
    if not spheres:
        sys.exit(f"{bodies_file}: no spheres")
    if None in lo[:3] or hi[0] is None or hi[1] is None or hi[2] is not None:
        sys.exit(f"{bodies_file}: expected an open box: a floor (+z) and four side walls")
    top = max(z + r for (_, _, z, r, _) in spheres)
    hi[2] = top + 0.5 * (top - lo[2])
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
