"""A loading protocol written in Python — a piston lowered onto a bed of spheres until it feels a
given force, then held — gives the same run, bit for bit, as the scene file that prescribes the
same motion."""

import copy

import numpy as np
import pytest

import polydem
from conftest import to_toml

PISTON = {
    "material": "glass",
    "name": "piston",
    # Facing down (u × v = −z), over the whole box.
    "generator": {
        "type": "rectangle",
        "origin": [-0.012, -0.012, 0.03],
        "u": [0.0, 0.024, 0.0],
        "v": [0.024, 0.0, 0.0],
    },
}
SPEED = 0.1  # m/s, downwards
TARGET = 0.5  # N: the piston stops when the bed pushes back this hard
SETTLE = 0.1  # s


def piston_bed(bed):
    scene = copy.deepcopy(bed)
    scene["simulation"]["duration"] = 0.3
    scene["mesh_wall"] = [copy.deepcopy(PISTON)]
    return scene


def python_protocol(scene, out):
    """Settle, lower the piston until the bed pushes back with TARGET, hold it there."""
    sim = polydem.Simulation(scene, out)
    piston = sim.wall_names.index("piston")
    sim.run(SETTLE)
    start = sim.time
    sim.set_wall_velocity("piston", (0.0, 0.0, -SPEED))
    while sim.wall_loads()["force"][piston, 2] < TARGET:
        sim.step(20)
        assert sim.time < sim.end_time, "the piston never reached the target force"
    stop = sim.time
    sim.set_wall_velocity("piston", (0.0, 0.0, 0.0))
    sim.run()
    return sim, start, stop


def test_a_python_protocol_gives_the_run_of_the_equivalent_scene_file(bed, tmp_path):
    scene = piston_bed(bed)
    protocol, start, stop = python_protocol(scene, tmp_path / "python")
    dt = protocol.time_step
    assert start < stop < protocol.end_time

    # The same motion written in the scene: each change reached over one time step, as
    # set_wall_velocity makes it by default.
    file_scene = copy.deepcopy(scene)
    file_scene["mesh_wall"][0]["motion"] = {
        "velocity_table": [
            [0.0, 0.0, 0.0, 0.0],
            [start, 0.0, 0.0, 0.0],
            [start + dt, 0.0, 0.0, -SPEED],
            [stop, 0.0, 0.0, -SPEED],
            [stop + dt, 0.0, 0.0, 0.0],
        ]
    }
    path = tmp_path / "piston.toml"
    path.write_text(to_toml(file_scene))
    from_file = polydem.Simulation(path, tmp_path / "file")
    from_file.run()

    piston = protocol.wall_names.index("piston")
    ours = protocol.wall_loads()["force"][piston]
    theirs = from_file.wall_loads()["force"][piston]
    # The piston, held where it stopped, still presses on the bed (which has relaxed since).
    assert ours[2] > 0.0
    assert np.array_equal(ours, theirs)
    assert np.array_equal(protocol.positions, from_file.positions)
    forces = [
        np.loadtxt(run / "wall_forces.csv", delimiter=",", skiprows=1)
        for run in (tmp_path / "python", tmp_path / "file")
    ]
    assert forces[0].shape == forces[1].shape
    assert np.array_equal(forces[0], forces[1])
    # The piston force was zero until the piston came down onto the bed.
    column = 1 + 6 * piston + 2
    assert forces[0][0, column] == 0.0
    assert forces[0][-1, column] > 0.0
