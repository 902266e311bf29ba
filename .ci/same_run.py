#!/usr/bin/env python3
"""Compares the outputs of one scene run in one process and on several MPI ranks (.ci/mpi).

usage: same_run.py ONE_DIR RANKS_DIR

- The same CSV files with the same rows: every value within 1e-9 of the largest magnitude in its
  row (the ranks add their shares' sums up in another order than one world does).
- The same particle frames, and in the last one every body (by id) with the same position,
  velocity, angular velocity, force and torque, to the bit, and the same contact counts.
"""
import csv
import re
import struct
import sys
from pathlib import Path

TYPES = {"Float64": "d", "UInt64": "Q", "Int64": "q", "UInt32": "I"}


def arrays(path):
    """Every appended DataArray of a .vtp written by polydem: name -> list of tuples."""
    data = path.read_bytes()
    start = data.index(b'<AppendedData encoding="raw">')
    header = data[:start].decode()
    raw = data[data.index(b"_", start) + 1:]
    out = {}
    for tag in re.findall(r"<DataArray [^>]*>", header):
        attr = dict(re.findall(r'(\w+)="([^"]*)"', tag))
        offset = int(attr["offset"])
        (size,) = struct.unpack_from("<Q", raw, offset)
        code = TYPES[attr["type"]]
        values = struct.unpack_from(f"<{size // struct.calcsize(code)}{code}", raw, offset + 8)
        width = int(attr.get("NumberOfComponents", "1"))
        out[attr["Name"]] = [values[k:k + width] for k in range(0, len(values), width)]
    return out


def bodies_by_id(path):
    a = arrays(path)
    fields = ["Points", "velocity", "angular_velocity", "force", "torque", "orientation",
              "coordination", "wall_contacts"]
    return {i[0]: tuple(a[f][k] for f in fields) for k, i in enumerate(a["id"])}


def main(one, ranks):
    one, ranks = Path(one), Path(ranks)
    failures = []
    for name in ["energy.csv", "wall_forces.csv", "flow.csv"]:
        if not (one / name).exists():
            continue
        a = list(csv.reader(open(one / name)))
        b = list(csv.reader(open(ranks / name)))
        if a[0] != b[0] or len(a) != len(b):
            failures.append(f"{name}: other columns or rows ({len(a)} and {len(b)} lines)")
            continue
        worst = 0.0
        for ra, rb in zip(a[1:], b[1:]):
            x, y = [float(v) for v in ra], [float(v) for v in rb]
            scale = max(abs(v) for v in x) or 1.0
            worst = max(worst, max(abs(p - q) / scale for p, q in zip(x, y)))
        print(f"{name}: {len(a) - 1} rows, largest difference {worst:.1e} of the row's scale")
        if worst > 1e-9:
            failures.append(f"{name}: values differ by {worst:.1e} of their row's scale")
    frames = sorted(p.name for p in one.glob("particles_*.vtp"))
    if frames != sorted(p.name for p in ranks.glob("particles_*.vtp")) or not frames:
        failures.append("the particle frames differ in number or name")
    else:
        a, b = bodies_by_id(one / frames[-1]), bodies_by_id(ranks / frames[-1])
        same = a == b
        print(f"{frames[-1]}: {len(a)} and {len(b)} bodies, the same to the bit: {same}")
        if not same:
            differ = sum(1 for i in a if a.get(i) != b.get(i))
            failures.append(f"{frames[-1]}: {differ} bodies differ")
    for f in failures:
        print("FAILED:", f, file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))
