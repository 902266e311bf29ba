"""Mass flow rate of the screw conveyor against screw speed, swept from Python (docs/python.md).

    python examples/python/screw_conveyor_sweep.py      # the full sweep: ~15 min per speed
    python examples/python/screw_conveyor_sweep.py --duration 0.15 --rpm 60 120  # a quick look

Writes each run's output to OUT/rpm_N/ and the plot to OUT/flow_against_rpm.png.
"""

import argparse
import pathlib

import matplotlib

matplotlib.use("Agg")  # write files; no window needed
import matplotlib.pyplot as plt
import numpy as np

import polydem

SCENE = pathlib.Path(__file__).resolve().parents[1] / "screw_conveyor.toml"


def conveyor_run(rpm, duration, out):
    """Runs the conveyor with its screw at `rpm`; returns times, outlet mass, drive torque."""
    sim = polydem.Simulation(SCENE, out / f"rpm_{rpm:g}", set={"simulation.duration": duration})
    # The scene turns the screw (mesh wall 0) at 120 rpm; this run's speed from the first step.
    sim.set_wall_rpm(0, rpm)
    times, mass, torque = [], [], []
    previous, then = sim.wall_loads()["angular_impulse"][0], sim.time
    piece = round(0.05 / sim.time_step)  # steps in 0.05 s
    while sim.steps < sim.end_step:
        # Outputs, insertions and checkpoints go on as in `polydem run`.
        sim.step(min(piece, sim.end_step - sim.steps))
        times.append(sim.time)
        mass.append(sim.flow()["outlet"]["mass"])
        # Drive torque: the mean torque of the cubes on the screw about x over the piece
        # (wall_forces.csv's tx), from the angular impulse since the start.
        now = sim.wall_loads()["angular_impulse"][0]
        torque.append((now - previous)[0] / (sim.time - then))
        previous, then = now, sim.time
    return np.array(times), np.array(mass), np.array(torque)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--rpm", type=float, nargs="+", default=[60, 120, 180, 240])
    parser.add_argument("--duration", type=float, default=2.5, help="simulated seconds per run")
    parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path("output/screw_sweep"))
    args = parser.parse_args()

    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    rates = []
    for rpm in args.rpm:
        t, mass, torque = conveyor_run(rpm, args.duration, args.out)
        # Steady flow: the mean rate over the second half of the run.
        half = t >= t[-1] / 2
        rate = (mass[-1] - mass[half][0]) / (t[-1] - t[half][0]) if half.sum() > 1 else 0.0
        rates.append(rate)
        left.plot(t, mass * 1e3, label=f"{rpm:g} rpm")
        print(f"{rpm:6g} rpm: {rate * 1e3:8.3f} g/s, mean drive torque {torque.mean():.3e} N m")

    left.set(xlabel="time [s]", ylabel="mass through the outlet [g]", title="Outlet")
    left.legend()
    right.plot(args.rpm, np.array(rates) * 1e3, "o-")
    right.set(xlabel="screw speed [rpm]", ylabel="mass flow rate [g/s]", title="Flow against speed")
    fig.tight_layout()
    args.out.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out / "flow_against_rpm.png", dpi=120)
    print(f"wrote {args.out / 'flow_against_rpm.png'}")


if __name__ == "__main__":
    main()
