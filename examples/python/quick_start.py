"""The first steps of docs/python.md: load, run, read arrays, change, checkpoint and resume."""

import pathlib
import sys

import numpy as np

import polydem

REPO = pathlib.Path(__file__).resolve().parents[2]
OUT = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "output/python_quick_start")

# Load a scene file and start its run (writes the first frame into OUT/bounce).
sim = polydem.Simulation(REPO / "examples" / "bouncing_sphere.toml", OUT / "bounce")
print(sim)  # <polydem.Simulation: 1 bodies, t = 0.000000 s of 1 s, step 0, output '…'>
sim.run(0.2)                 # 0.2 s of simulated time
sim.step(100)                # 100 more time steps
print(sim.time, sim.positions[0], sim.velocities[0])
print(sim.energy()["total"], sim.energy()["dissipated"])

# The same keys as a dict; `set` changes keys as `polydem run --set` does.
scene = {
    "simulation": {"time_step": 2e-5, "duration": 0.05, "gravity": [0.0, 0.0, -9.81]},
    "material": [
        {"name": "glass", "density": 2500.0, "youngs_modulus": 5e6, "poisson_ratio": 0.25,
         "restitution": 0.5, "friction": 0.5},
    ],
    "plane": [{"point": [0, 0, 0], "normal": [0, 0, 1], "material": "glass", "name": "floor"}],
    "insert": [{"method": "lattice", "material": "glass", "region_min": [-0.01, -0.01, 0.001],
                "region_max": [0.01, 0.01, 0.01], "count": 27, "radius": 0.002}],
    "output": {"force_network": True},
}
bed = polydem.Simulation(scene, OUT / "bed", set={"material[0].friction": 0.3})
bed.run()

# State as NumPy arrays (copies, in the order of `ids`).
ids, x, f = bed.ids, bed.positions, bed.forces
contacts = bed.contacts()
print(len(ids), x.shape, contacts["normal_force"].sum(), bed.wall_loads()["force"][0])

# Change things between steps: gravity, velocities, bodies in and out.
bed.gravity = (2.0, 0.0, -9.81)
bed.set_velocities(ids[:2], np.zeros((2, 3)))
new_id = bed.insert((0.0, 0.0, 0.02), material="glass", radius=0.002)
bed.remove([new_id])
bed.run(0.01)

# A bad scene raises polydem.SceneError naming the key.
scene["material"][0]["poisson_ratio"] = 0.7
try:
    polydem.Simulation(scene, OUT / "bad")
except polydem.SceneError as e:
    print(e.key, "->", e)

# Checkpoint, and resume in a new Simulation (as `polydem resume` does).
bed.checkpoint()
again = polydem.Simulation.resume(OUT / "bed")
again.run(0.01)
print(again.time)
