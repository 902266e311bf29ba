"""polydem: a Discrete Element Method engine for spheres and polyhedra, driven from Python.

Load a scene (a TOML file, or a dict with the same keys), run it, read its state as NumPy
arrays and change it between steps::

    import polydem
    sim = polydem.Simulation("examples/bouncing_sphere.toml", out="output/bounce")
    sim.run(0.1)                 # 0.1 s of simulated time; outputs as `polydem run` writes them
    print(sim.time, sim.positions[0], sim.energy()["total"])

See docs/python.md for a tutorial.
"""

from ._polydem import RunError, SceneError, Simulation, __version__, read_vtp

__all__ = ["RunError", "SceneError", "Simulation", "__version__", "read_vtp"]
