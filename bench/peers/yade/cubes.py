# Yade side of the cubes benchmark (scripts/bench_peers.sh): the bodies of bench/cubes_1k.toml
# settling in their open box with Yade's polyhedra (Polyhedra, Ig2_Polyhedra_Polyhedra_PolyhedraGeom,
# Law2_PolyhedraGeom_PolyhedraPhys_Volumetric), starting at rest from the bed polydem settled,
# as polydem does (`polydem bench scene --settle-steps 10000`):
#
#   polydem bench initial bench/cubes_1k.toml --settle-steps 10000 --out cubes_1k.bodies
#   yade -n -x -j 1 bench/peers/yade/cubes.py cubes_1k.bodies [STEPS [WINDOW_START]]
#
# Steps STEPS (default 300) of 50 us and times steps WINDOW_START..STEPS (default 100; Yade needs
# the first steps to take up the shear springs that polydem kept). Ends with one line
#   YADE_RESULT bodies=N threads=T window=A..B seconds=S particle_steps_per_s=P contacts_per_particle=C wall_contacts=W
# C = 2 x (touching body pairs: penetration volume > 0) / N, as polydem counts; W = body-wall
# contacts.
#
# Material: polydem's volume law pushes with k_v V, V the overlap volume and k_v = E*/R*
# (E* = E / (2 (1 - nu^2)) for one material; R* = r/2 between two bodies and r against a plane,
# r the radius of the sphere of equal volume). Yade's pushes with kn V, kn = 1 / (1/Y1 + 1/Y2)
# for the two materials' `young` Y1, Y2, so the bodies' and the walls' `young` are set to give
# the same kn as polydem's k_v, body on body and body on wall. Yade's shear spring is a constant
# ks = 1 / (1/(Y1 P1) + 1/(Y2 P2)) [N/m] where polydem's is 2/7 of the normal stiffness k_v A of
# the contact area A: `poisson` P is set for the ks of a contact over half a face. Yade's law has
# no dashpot; the restitution 0.5 is given by NewtonIntegrator's local damping 0.6, which gives a
# binary collision on a linear spring a restitution sqrt((1 - 0.6) / (1 + 0.6)) = 0.5.
# Keep in step with bench/cubes_1k.toml.

import math
import sys
import time

from yade import polyhedra_utils

E, NU, MU, RESTITUTION = 1.0e6, 0.25, 0.5, 0.5  # bench/cubes_1k.toml
DT = 5.0e-5
TANGENTIAL_RATIO = 2.0 / 7.0  # polydem's default k_t / k_n
DAMPING = (1.0 - RESTITUTION**2) / (1.0 + RESTITUTION**2)  # 0.6


def read_bodies(path):
    planes, polyhedra = [], []
    with open(path) as f:
        for line in f:
            fields = line.split()
            if not fields or fields[0].startswith("#"):
                continue
            if fields[0] == "plane":
                planes.append(([float(v) for v in fields[1:4]], [float(v) for v in fields[4:7]]))
            elif fields[0] == "polyhedron":
                centre = [float(v) for v in fields[1:4]]
                density = float(fields[4])
                n = int(fields[5])
                coords = [float(v) for v in fields[6 : 6 + 3 * n]]
                corners = [Vector3(*coords[3 * k : 3 * k + 3]) for k in range(n)]
                polyhedra.append((centre, density, corners))
            else:
                sys.exit(f"{path}: this script takes polyhedra only, not '{fields[0]}'")
    return planes, polyhedra


def main(argv):
    if not 2 <= len(argv) <= 4:
        sys.exit("usage: yade -n -x -j THREADS cubes.py BODIES [STEPS [WINDOW_START]]")
    steps = int(argv[2]) if len(argv) > 2 else 300
    window_start = int(argv[3]) if len(argv) > 3 else min(100, steps // 2)
    if not 0 <= window_start < steps:
        sys.exit("WINDOW_START must lie in [0, STEPS)")
    planes, polyhedra = read_bodies(argv[1])
    density = polyhedra[0][1]
    volume = polyhedra_utils.polyhedra(PolyhedraMat(), v=polyhedra[0][2]).shape.GetVolume()
    r_eq = (3.0 * volume / (4.0 * math.pi)) ** (1.0 / 3.0)
    e_star = E / (2.0 * (1.0 - NU**2))
    kv_bodies = e_star / (0.5 * r_eq)  # body on body [N/m^3]
    kv_wall = e_star / r_eq  # body on wall
    young_body = 2.0 * kv_bodies  # kn = young/2 between two bodies
    young_wall = 1.0 / (1.0 / kv_wall - 1.0 / young_body)
    half_face = 0.5 * volume ** (2.0 / 3.0)
    poisson = 2.0 * TANGENTIAL_RATIO * kv_bodies * half_face / young_body
    friction_angle = math.atan(MU)
    body_mat = PolyhedraMat(
        young=young_body, poisson=poisson, frictionAngle=friction_angle, density=density
    )
    wall_mat = PolyhedraMat(
        young=young_wall, poisson=poisson, frictionAngle=friction_angle, density=density
    )

    walls = []
    for point, normal in planes:
        axes = [a for a in range(3) if abs(normal[a]) > 1e-12]
        if len(axes) != 1:
            sys.exit("only axis-aligned planes are supported")
        a = axes[0]
        sense = 1 if normal[a] > 0 else -1
        walls.append(O.bodies.append(utils.wall(point[a], axis=a, sense=sense, material=wall_mat)))
    wall_ids = set(walls)
    bounding = 0.0
    for centre, _, corners in polyhedra:
        b = polyhedra_utils.polyhedra(body_mat, v=corners)
        if (b.state.pos - Vector3(*centre)).norm() > 1e-9:
            sys.exit(f"Yade puts a body at {b.state.pos}, polydem at {centre}")
        bounding = max(bounding, max((c - b.state.pos).norm() for c in corners))
        O.bodies.append(b)
    n = len(polyhedra)

    O.engines = [
        ForceResetter(),
        # Bounds enlarged by half polydem's skin (a fifth of the bounding radius).
        InsertionSortCollider([Bo1_Polyhedra_Aabb(), Bo1_Wall_Aabb()], verletDist=0.1 * bounding),
        InteractionLoop(
            [Ig2_Wall_Polyhedra_PolyhedraGeom(), Ig2_Polyhedra_Polyhedra_PolyhedraGeom()],
            [Ip2_PolyhedraMat_PolyhedraMat_PolyhedraPhys()],
            [Law2_PolyhedraGeom_PolyhedraPhys_Volumetric()],
        ),
        NewtonIntegrator(damping=DAMPING, gravity=(0, 0, -9.81)),
    ]
    O.dt = DT

    start = time.perf_counter()
    if window_start > 0:
        O.run(window_start, True)
    before = time.perf_counter() - start
    print(f"step {window_start} after {before:.2f} s", file=sys.stderr)
    start = time.perf_counter()
    O.run(steps - window_start, True)
    seconds = time.perf_counter() - start

    body_body = body_wall = 0
    for i in O.interactions:
        if not i.isReal or not i.geom.penetrationVolume > 0:
            continue
        if i.id1 in wall_ids or i.id2 in wall_ids:
            body_wall += 1
        else:
            body_body += 1
    window = steps - window_start
    print(
        f"YADE_RESULT bodies={n} threads={O.numThreads} window={window_start}..{steps} "
        f"seconds={seconds:.3f} particle_steps_per_s={n * window / seconds:.3e} "
        f"contacts_per_particle={2.0 * body_body / n:.3f} wall_contacts={body_wall}"
    )


main(sys.argv)
