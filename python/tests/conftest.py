"""Shared scenes of the pytest suite: small enough to run in seconds, each a dict with the keys
of a scene file (so a test can change a key, or write it out as TOML)."""

import copy
import pathlib

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]

GLASS = {
    "name": "glass",
    "density": 2500.0,
    "youngs_modulus": 5.0e6,
    "poisson_ratio": 0.25,
    "restitution": 0.5,
    "friction": 0.5,
    "rolling_friction": 0.02,
}

# 64 spheres on a 4×4×4 lattice falling into a box of planes.
BED = {
    "simulation": {
        "time_step": 2e-5,
        "duration": 0.06,
        "gravity": [0.0, 0.0, -9.81],
        "output_interval": 0.01,
        "threads": 1,
    },
    "material": [GLASS],
    "plane": [
        {"point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0], "material": "glass", "name": "floor"},
        {"point": [-0.012, 0.0, 0.0], "normal": [1.0, 0.0, 0.0], "material": "glass"},
        {"point": [0.012, 0.0, 0.0], "normal": [-1.0, 0.0, 0.0], "material": "glass"},
        {"point": [0.0, -0.012, 0.0], "normal": [0.0, 1.0, 0.0], "material": "glass"},
        {"point": [0.0, 0.012, 0.0], "normal": [0.0, -1.0, 0.0], "material": "glass"},
    ],
    "insert": [
        {
            "method": "lattice",
            "material": "glass",
            "region_min": [-0.0115, -0.0115, 0.0005],
            "region_max": [0.0115, 0.0115, 0.03],
            "count": 64,
            "radius": 0.0025,
        }
    ],
    "output": {"force_network": True, "flow_meter": [
        {"name": "low", "point": [0.0, 0.0, 0.008], "normal": [0.0, 0.0, -1.0]}
    ]},
}


def to_toml(scene, indent=""):
    """A scene dict as TOML text (enough of TOML for these scenes)."""

    def value(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, (int, float)):
            return repr(v)
        if isinstance(v, str):
            return '"' + v + '"'
        if isinstance(v, (list, tuple)):
            return "[" + ", ".join(value(x) for x in v) + "]"
        if isinstance(v, dict):
            return "{ " + ", ".join(f"{k} = {value(x)}" for k, x in v.items()) + " }"
        raise TypeError(v)

    lines = []
    for table, body in scene.items():
        if isinstance(body, list):
            for entry in body:
                lines.append(f"[[{table}]]")
                lines += [f"{k} = {value(v)}" for k, v in entry.items()]
        else:
            lines.append(f"[{table}]")
            for k, v in body.items():
                if isinstance(v, list) and v and isinstance(v[0], dict):
                    for entry in v:
                        lines.append(f"[[{table}.{k}]]")
                        lines += [f"{kk} = {value(vv)}" for kk, vv in entry.items()]
                else:
                    lines.append(f"{k} = {value(v)}")
    return "\n".join(lines) + "\n"


@pytest.fixture
def bed():
    return copy.deepcopy(BED)
