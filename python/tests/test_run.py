"""Loading a scene (file or dict), running and stepping it, and the outputs it writes."""

import threading
import time

import numpy as np
import pytest

import polydem
from conftest import REPO, to_toml


def test_a_file_and_the_same_dict_give_the_same_run(bed, tmp_path):
    scene = tmp_path / "bed.toml"
    scene.write_text(to_toml(bed))
    from_file = polydem.Simulation(scene, tmp_path / "file")
    from_dict = polydem.Simulation(bed, tmp_path / "dict")
    assert len(from_file) == len(from_dict) == 64
    from_file.step(500)
    from_dict.step(500)
    assert from_file.steps == from_dict.steps == 500
    assert np.array_equal(from_file.positions, from_dict.positions)
    assert np.array_equal(from_file.velocities, from_dict.velocities)


def test_run_and_step_advance_time_and_write_the_cli_outputs(bed, tmp_path):
    sim = polydem.Simulation(bed, tmp_path / "out")
    dt = sim.time_step
    assert dt == 2e-5 and sim.end_time == pytest.approx(0.06)
    sim.step()
    assert sim.steps == 1
    sim.step(99)
    assert sim.steps == 100 and sim.time == pytest.approx(100 * dt)
    sim.run(0.01)
    assert sim.steps == 600
    sim.run()  # to the scene's end
    assert sim.steps == sim.end_step == 3000 and sim.time == pytest.approx(0.06)
    out = tmp_path / "out"
    frames = sorted(out.glob("particles_*.vtp"))
    assert len(frames) == 7  # t = 0, 0.01, …, 0.06
    energy = np.loadtxt(out / "energy.csv", delimiter=",", skiprows=1)
    assert energy[-1, 0] == pytest.approx(0.06)
    assert (out / "wall_forces.csv").exists() and (out / "flow.csv").exists()
    assert list((out / "checkpoints").glob("step_*.ckpt"))
    # Run past the end: the end moves.
    sim.run(0.002)
    assert sim.end_time == pytest.approx(0.062) and sim.steps == 3100
    # Once the bed has settled, the floor carries its weight (less what friction hangs on the
    # side walls): the mean force over a window, from the impulses.
    sim.run(0.2)
    before = sim.wall_loads()["impulse"][0]
    sim.run(0.05)
    mean = (sim.wall_loads()["impulse"][0] - before) / 0.05
    weight = sim.masses.sum() * 9.81
    assert mean[2] == pytest.approx(-weight, rel=0.1)
    assert sim.wall_loads()["force"][0, 2] == pytest.approx(-weight, rel=0.1)


def test_a_run_in_python_pieces_writes_what_one_run_writes(bed, tmp_path):
    whole = polydem.Simulation(bed, tmp_path / "whole")
    whole.run()
    pieces = polydem.Simulation(bed, tmp_path / "pieces")
    for n in [1, 333, 17, 1000, 649, 1000]:
        pieces.step(n)
    assert pieces.steps == whole.steps
    for name in ["energy.csv", "wall_forces.csv", "flow.csv", "particles_000006.vtp"]:
        assert (tmp_path / "whole" / name).read_bytes() == (tmp_path / "pieces" / name).read_bytes(), name


def test_the_thread_count_does_not_change_the_result(bed, tmp_path):
    one = polydem.Simulation(bed, tmp_path / "one", threads=1)
    two = polydem.Simulation(bed, tmp_path / "two", threads=2)
    assert one.threads == 1 and two.threads == 2
    one.step(800)
    two.step(800)
    assert np.array_equal(one.positions, two.positions)


def test_the_gil_is_released_while_stepping(bed, tmp_path):
    sim = polydem.Simulation(bed, tmp_path / "out")
    ticks = 0
    done = threading.Event()

    def run():
        sim.step(2500)
        done.set()

    worker = threading.Thread(target=run)
    worker.start()
    # Python code runs in this thread while the other steps the simulation.
    while not done.is_set():
        ticks += 1
        time.sleep(0.001)
    worker.join()
    assert sim.steps == 2500
    assert ticks > 5, "the main thread was blocked while stepping"


def test_set_overrides_scene_keys(tmp_path):
    scene = REPO / "examples" / "bouncing_sphere.toml"
    sim = polydem.Simulation(scene, tmp_path / "out", set={"simulation.duration": 0.01, "material[0].friction": 0.1})
    assert sim.end_time == 0.01
    sim.run()
    assert sim.time == pytest.approx(0.01, rel=1e-3)


def test_progress_bar_is_optional(bed, tmp_path, capfd):
    sim = polydem.Simulation(bed, tmp_path / "out")
    sim.step(200, progress=True)
    sim.run(0.001)
    assert sim.steps == 250
