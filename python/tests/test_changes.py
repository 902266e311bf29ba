"""Changes between steps (gravity, bodies in and out, velocities, wall motion) and checkpoints
from Python: each keeps the energy ledger closing, and a resumed run continues bit for bit."""

import numpy as np
import pytest

import polydem
from conftest import REPO


def ledger_total(sim):
    return sim.energy()["total"]


def test_gravity_set_from_python_acts_and_is_booked(bed, tmp_path):
    sim = polydem.Simulation(bed, tmp_path / "out")
    sim.step(10)
    total = ledger_total(sim)
    sim.gravity = (3.0, 0.0, -9.81)
    assert sim.gravity == (3.0, 0.0, -9.81)
    assert ledger_total(sim) == pytest.approx(total, rel=1e-12)
    sim.step(100)
    assert sim.velocities[:, 0].mean() > 0.0  # pushed along +x


def test_velocities_set_insertions_and_removals_keep_the_ledger(bed, tmp_path):
    sim = polydem.Simulation(bed, tmp_path / "out")
    sim.step(10)
    total = ledger_total(sim)
    ids = sim.ids[:3]
    sim.set_velocities(ids, [[0.1, 0.0, 0.0]] * 3, angular_velocities=np.full((3, 3), 2.0))
    index = [list(sim.ids).index(i) for i in ids]
    assert np.array_equal(sim.velocities[index], [[0.1, 0.0, 0.0]] * 3)
    assert np.allclose(sim.angular_velocities[index], 2.0)
    new = sim.insert((0.0, 0.0, 0.05), material="glass", radius=0.002, velocity=(0.0, 0.0, -0.5))
    assert len(sim) == 65 and new in sim.ids
    sim.remove(sim.ids[-5:-2])
    assert len(sim) == 62
    assert ledger_total(sim) == pytest.approx(total, rel=1e-12)
    sim.step(500)
    e = sim.energy()
    assert e["inserted"] != 0.0 and e["removed"] != 0.0
    # Within what a sound run drifts (the kinetic energy given above is 0.2 % of the total).
    assert ledger_total(sim) == pytest.approx(total, rel=5e-4)


def test_bad_changes_raise_value_errors(bed, tmp_path):
    sim = polydem.Simulation(bed, tmp_path / "out")
    with pytest.raises(ValueError, match="no body with id 999"):
        sim.set_velocities([999], [[0.0, 0.0, 0.0]])
    with pytest.raises(ValueError, match="no material named"):
        sim.insert((0, 0, 0.05), material="steel", radius=0.001)
    with pytest.raises(ValueError, match="exactly one of radius"):
        sim.insert((0, 0, 0.05), material="glass")
    with pytest.raises(ValueError, match="no mesh wall 0"):
        sim.set_wall_velocity(0, (0, 0, 1))
    with pytest.raises(ValueError, match="three"):
        sim.gravity = (1.0, 2.0)


def drum(glass):
    """A closed drum (axis y, radius 3 cm) without motion, 20 spheres resting at its bottom."""
    return {
        "simulation": {"time_step": 2e-5, "duration": 0.1, "threads": 1},
        "material": [glass],
        "mesh_wall": [
            {
                "material": "glass",
                "name": "drum",
                "generator": {"type": "cylinder", "radius": 0.03, "height": 0.02, "segments": 32, "closed": True},
                "rotation": [1.5707963267948966, 0.0, 0.0],
                "translation": [0.0, 0.01, 0.0],
            }
        ],
        "insert": [
            {
                "method": "lattice",
                "material": "glass",
                "region_min": [-0.015, -0.008, -0.028],
                "region_max": [0.015, 0.008, -0.018],
                "count": 20,
                "radius": 0.002,
            }
        ],
    }


def test_wall_rpm_from_python(tmp_path):
    from conftest import GLASS

    sim = polydem.Simulation(drum(GLASS), tmp_path / "out")
    sim.run(0.03)
    assert sim.energy()["wall_work"] == 0.0
    with pytest.raises(ValueError, match="no rotation axis"):
        sim.set_wall_rpm("drum", 60.0)
    sim.set_wall_rpm("drum", 60.0, axis=(0.0, 1.0, 0.0), axis_point=(0.0, 0.0, 0.0), ramp=0.01)
    sim.step(10)
    with pytest.raises(ValueError, match="axis cannot change"):
        sim.set_wall_rpm("drum", 60.0, axis=(1.0, 0.0, 0.0))
    sim.run()
    # The turning drum drags the spheres along: it works on them, they move along its wall.
    assert sim.energy()["wall_work"] > 0.0
    assert np.abs(sim.velocities[:, 0]).max() > 0.01


def test_checkpoint_and_resume_continue_bit_for_bit(bed, tmp_path):
    whole = polydem.Simulation(bed, tmp_path / "whole")
    whole.run()
    stopped = polydem.Simulation(bed, tmp_path / "stopped")
    stopped.step(1234)
    path = stopped.checkpoint()
    assert path.endswith(".ckpt")
    del stopped
    resumed = polydem.Simulation.resume(tmp_path / "stopped")
    assert resumed.steps == 1234
    resumed.run()
    assert resumed.steps == whole.steps
    assert np.array_equal(resumed.positions, whole.positions)
    assert np.array_equal(resumed.velocities, whole.velocities)
    energy = [(tmp_path / d / "energy.csv").read_text() for d in ("whole", "stopped")]
    assert energy[0] == energy[1]


def test_resume_of_a_folder_without_checkpoints_raises(tmp_path):
    with pytest.raises(polydem.RunError, match="checkpoint"):
        polydem.Simulation.resume(tmp_path)


def test_ctrl_c_stops_a_run_with_a_checkpoint_that_resumes_bit_for_bit(bed, tmp_path):
    import _thread
    import signal
    import threading

    # Python handles Ctrl-C only where SIGINT was not ignored when it started (a job started in
    # the background by a non-interactive shell, as some CI runners do, ignores it): ask for
    # Python's own handler for this test.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)

    # 200,000 steps of 64 spheres: long enough on any machine that a Ctrl-C 20 ms in lands early
    # in the run, which looks for it every 0.1 s.
    bed["simulation"]["duration"] = 4.0
    whole = polydem.Simulation(bed, tmp_path / "whole")
    whole.run()
    stopped = polydem.Simulation(bed, tmp_path / "stopped")
    # Ctrl-C as the interpreter sees it, while the run steps with the GIL released.
    threading.Timer(0.02, _thread.interrupt_main).start()
    try:
        with pytest.raises(KeyboardInterrupt, match="checkpoint written"):
            stopped.run()
    finally:
        signal.signal(signal.SIGINT, previous)
    assert 0 < stopped.steps < whole.steps
    resumed = polydem.Simulation.resume(tmp_path / "stopped")
    assert resumed.steps == stopped.steps
    resumed.run()
    assert np.array_equal(resumed.positions, whole.positions)
