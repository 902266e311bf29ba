"""Type hints of the extension module `polydem._polydem` (written in Rust with PyO3)."""

import os
from typing import Any, Mapping, Sequence, TypedDict, Union

import numpy as np
import numpy.typing as npt

__version__: str

Vector = Union[Sequence[float], npt.NDArray[np.float64]]
Vectors = Union[Sequence[Sequence[float]], npt.NDArray[np.float64]]
Ids = Union[Sequence[int], npt.NDArray[np.integer[Any]]]
WallRef = Union[int, str]
Scene = Union[str, os.PathLike[str], Mapping[str, Any]]

class SceneError(ValueError):
    """A scene that cannot be run; the message names the file, line and key and what is allowed."""

    file: str | None
    line: int | None
    key: str | None

class RunError(RuntimeError):
    """A run that stopped before its end (blew up, output or checkpoint failed)."""

class Contacts(TypedDict):
    bodies: npt.NDArray[np.int64]
    """(M, 2) body ids; the second is -1 for a wall."""
    wall: npt.NDArray[np.int64]
    """(M,) the wall's number as in `wall_names`, -1 between bodies."""
    points: npt.NDArray[np.float64]
    """(M, 3) contact points [m]."""
    normals: npt.NDArray[np.float64]
    """(M, 3) unit normals from the partner towards the first body."""
    forces: npt.NDArray[np.float64]
    """(M, 3) contact force on the first body [N]."""
    normal_force: npt.NDArray[np.float64]
    """(M,) normal force [N]."""
    overlap: npt.NDArray[np.float64]
    """(M,) overlap depth [m]."""

class WallLoads(TypedDict):
    names: list[str]
    force: npt.NDArray[np.float64]
    """(W, 3) the bodies' contact force on each wall now [N]."""
    impulse: npt.NDArray[np.float64]
    """(W, 3) time integral of the force since the start [N s]."""
    angular_impulse: npt.NDArray[np.float64]
    """(W, 3) time integral of the torque about each wall's reference point [N m s]."""
    work: float
    """Work of the moving walls on the bodies since the start [J]."""

class FlowMeter(TypedDict):
    mass: float
    bodies: int

class Frame(TypedDict):
    time: float | None
    points: npt.NDArray[np.float64]
    point_data: dict[str, npt.NDArray[np.float64]]
    cell_data: dict[str, npt.NDArray[np.float64]]

def read_vtp(path: str | os.PathLike[str]) -> Frame:
    """Reads a `.vtp` frame written by polydem (points, point and cell data as arrays)."""

class Simulation:
    """A scene loaded and its run started into an output folder, driven with `run` and `step`.

    Every per-body array is a copy in the order of `ids` (which changes as the run sorts its
    bodies in space; ids do not).
    """

    def __init__(
        self,
        scene: Scene,
        out: str | os.PathLike[str] | None = None,
        *,
        threads: int | None = None,
        set: Mapping[str, Any] | None = None,
        checkpoints: bool = True,
    ) -> None:
        """Loads and checks `scene` (a TOML file or a dict of its keys) and starts its run into
        `out` (default output/<scene name>). `threads` overrides simulation.threads; `set`
        overrides keys as `polydem run --set` does. Raises SceneError for a bad scene."""

    @staticmethod
    def resume(
        out: str | os.PathLike[str],
        *,
        duration: float | None = None,
        threads: int | None = None,
        scene: str | os.PathLike[str] | None = None,
        stored_scene: bool = False,
    ) -> Simulation:
        """Continues the run in `out` from its newest checkpoint, as `polydem resume` does."""

    def run(self, duration: float | None = None, *, progress: bool = False) -> None:
        """Runs on for `duration` seconds, or to the scene's end; releases the GIL meanwhile."""

    def step(self, n: int = 1, *, progress: bool = False) -> None:
        """Takes `n` time steps."""

    def checkpoint(self) -> str:
        """Writes a checkpoint now; returns its path."""

    @property
    def time(self) -> float:
        """Simulated time [s]."""
    @property
    def steps(self) -> int:
        """Time steps taken since the run started."""
    @property
    def time_step(self) -> float:
        """The time step [s]."""
    @property
    def end_time(self) -> float:
        """The time the run ends at [s]."""
    @property
    def end_step(self) -> int:
        """The step at which the run ends."""
    @property
    def out(self) -> str:
        """The output folder."""
    @property
    def notes(self) -> list[str]:
        """What loading and running reported that the user should know."""
    @property
    def threads(self) -> int:
        """Worker threads of the run's parallel loops."""
    @property
    def gravity(self) -> tuple[float, float, float]:
        """Gravity [m/s²]; setting it replaces the scene's gravity (and table) from now on."""
    @gravity.setter
    def gravity(self, value: Vector) -> None: ...
    @property
    def material_names(self) -> list[str]:
        """Material names by number (`material_ids`)."""
    @property
    def shape_names(self) -> list[str]:
        """The scene's [shape.NAME]s."""
    @property
    def wall_names(self) -> list[str]:
        """Walls: planes first, then mesh walls, as in wall_forces.csv."""
    def __len__(self) -> int:
        """Number of bodies."""
    @property
    def ids(self) -> npt.NDArray[np.uint64]:
        """(N,) body ids."""
    @property
    def positions(self) -> npt.NDArray[np.float64]:
        """(N, 3) centres of mass [m]."""
    @property
    def orientations(self) -> npt.NDArray[np.float64]:
        """(N, 4) quaternions (w, x, y, z) of the principal frames."""
    @property
    def velocities(self) -> npt.NDArray[np.float64]:
        """(N, 3) [m/s]."""
    @property
    def angular_velocities(self) -> npt.NDArray[np.float64]:
        """(N, 3) [rad/s]."""
    @property
    def forces(self) -> npt.NDArray[np.float64]:
        """(N, 3) contact forces [N]."""
    @property
    def torques(self) -> npt.NDArray[np.float64]:
        """(N, 3) contact torques [N m]."""
    @property
    def radii(self) -> npt.NDArray[np.float64]:
        """(N,) bounding radii [m] (the VTK output's `radius`)."""
    @property
    def equivalent_radii(self) -> npt.NDArray[np.float64]:
        """(N,) radii of the spheres of equal volume [m]."""
    @property
    def masses(self) -> npt.NDArray[np.float64]:
        """(N,) [kg]."""
    @property
    def shape_ids(self) -> npt.NDArray[np.uint32]:
        """(N,) entries of the run's shape table."""
    @property
    def material_ids(self) -> npt.NDArray[np.uint32]:
        """(N,) indices into `material_names`."""
    def contacts(self) -> Contacts:
        """The contacts that touch now."""
    def energy(self) -> dict[str, float]:
        """The energy ledger now, under the column names of energy.csv."""
    def wall_loads(self) -> WallLoads:
        """Forces on the walls now, impulses and work since the start."""
    def flow(self) -> dict[str, FlowMeter]:
        """The flow meters by name."""
    def set_wall_velocity(self, wall: WallRef, velocity: Vector, *, ramp: float | None = None) -> None:
        """Mesh wall `wall` translates at `velocity` [m/s] from now on (reached over `ramp` s)."""
    def set_wall_rpm(
        self,
        wall: WallRef,
        rpm: float,
        *,
        axis: Vector | None = None,
        axis_point: Vector | None = None,
        ramp: float | None = None,
    ) -> None:
        """Mesh wall `wall` turns at `rpm` from now on (reached over `ramp` s)."""
    def set_velocities(
        self, ids: Ids, velocities: Vectors, angular_velocities: Vectors | None = None
    ) -> None:
        """Sets the velocities (and angular velocities) of the bodies with these ids."""
    def insert(
        self,
        position: Vector,
        *,
        material: str,
        radius: float | None = None,
        shape: str | None = None,
        velocity: Vector | None = None,
        angular_velocity: Vector | None = None,
        orientation: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0),
    ) -> int:
        """Inserts a sphere (`radius`) or a scene shape (`shape`); returns its id."""
    def remove(self, ids: Ids) -> None:
        """Removes the bodies with these ids."""
