"""The type stubs describe the extension as it is: every public name of the module and of
Simulation has a stub, and every stub a real name (so `py.typed` does not mislead checkers)."""

import ast
import pathlib

import polydem
from polydem import _polydem

STUB = pathlib.Path(polydem.__file__).with_name("_polydem.pyi")


def stub_names():
    tree = ast.parse(STUB.read_text())
    module, simulation = set(), set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            module.add(node.name)
        elif isinstance(node, ast.AnnAssign):
            module.add(node.target.id)
        if isinstance(node, ast.ClassDef) and node.name == "Simulation":
            simulation = {n.name for n in node.body if isinstance(n, ast.FunctionDef)}
    return module, simulation


def test_the_stubs_match_the_extension():
    module, simulation = stub_names()
    public = {n for n in dir(_polydem) if not n.startswith("_")} | {"__version__"}
    assert public <= module
    real = {n for n in dir(polydem.Simulation) if not n.startswith("_")} | {"__init__", "__len__"}
    assert simulation == real
    assert STUB.with_name("py.typed").exists()
