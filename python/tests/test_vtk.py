"""The arrays of a simulation are the values its VTK output holds for the same state."""

import numpy as np
import pytest

import polydem
from conftest import REPO


def by_id(ids, values):
    return values[np.argsort(ids)]


@pytest.fixture
def settled(bed, tmp_path):
    sim = polydem.Simulation(bed, tmp_path / "out")
    sim.run()  # the last frame is written at the end, with the state the arrays show
    return sim, tmp_path / "out"


def test_body_arrays_match_the_last_particles_frame(settled):
    sim, out = settled
    frame = polydem.read_vtp(sorted(out.glob("particles_*.vtp"))[-1])
    assert frame["time"] == pytest.approx(sim.time)
    data = frame["point_data"]
    ids = sim.ids
    vtk_ids = data["id"]
    assert np.array_equal(np.sort(ids), np.sort(vtk_ids.astype(np.uint64)))
    pairs = [
        (frame["points"], sim.positions),
        (data["velocity"], sim.velocities),
        (data["angular_velocity"], sim.angular_velocities),
        (data["orientation"], sim.orientations),
        (data["force"], sim.forces),
        (data["torque"], sim.torques),
        (data["radius"], sim.radii),
        (data["material"], sim.material_ids.astype(float)),
    ]
    for vtk, ours in pairs:
        assert np.array_equal(by_id(vtk_ids, vtk), by_id(ids, ours))
    # The bed is resting: there is something to compare.
    assert np.abs(sim.forces[:, 2]).max() > 0.0


def test_contacts_match_the_force_network(settled):
    sim, out = settled
    frame = polydem.read_vtp(sorted(out.glob("contacts_*.vtp"))[-1])
    contacts = sim.contacts()
    n = len(contacts["wall"])
    assert n > 64  # every sphere rests on something
    cells = frame["cell_data"]
    assert np.array_equal(np.sort(cells["normal_force"]), np.sort(contacts["normal_force"]))
    assert np.array_equal(np.sort(cells["force"][:, 2]), np.sort(contacts["forces"][:, 2]))
    walls = contacts["wall"] >= 0
    assert int(walls.sum()) == int((cells["wall_contact"] == 1).sum())
    # A wall contact's second body is −1; a body pair's wall is −1.
    assert np.all(contacts["bodies"][walls, 1] == -1)
    assert np.all(contacts["bodies"][~walls, 1] >= 0)


def test_energy_and_flow_match_their_csv_files(settled):
    sim, out = settled
    header = (out / "energy.csv").read_text().splitlines()[0].split(",")
    last = np.loadtxt(out / "energy.csv", delimiter=",", skiprows=1)[-1]
    energy = sim.energy()
    assert list(energy) == header
    for name, value in zip(header, last):
        assert energy[name] == pytest.approx(value, rel=1e-12, abs=1e-300), name
    flow = np.loadtxt(out / "flow.csv", delimiter=",", skiprows=1)[-1]
    assert sim.flow()["low"]["mass"] == pytest.approx(flow[1], rel=1e-12)
    assert sim.flow()["low"]["bodies"] == flow[2]
    # Wall impulses since the start give the CSV's mean forces.
    loads = sim.wall_loads()
    assert loads["names"][0] == "floor"
    assert loads["impulse"].shape == (5, 3)
