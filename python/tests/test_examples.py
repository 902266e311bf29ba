"""docs/python.md shows code that runs: each of its Python snippets is part of an example
script, and the scripts run (the conveyor sweep shortened)."""

import re
import subprocess
import sys
import textwrap

from conftest import REPO

SCRIPTS = [REPO / "examples" / "python" / name for name in ("quick_start.py", "screw_conveyor_sweep.py")]


def test_every_snippet_of_the_tutorial_is_in_an_example_script():
    doc = (REPO / "docs" / "python.md").read_text()
    snippets = re.findall(r"```python\n(.*?)```", doc, flags=re.S)
    assert len(snippets) >= 8
    scripts = [path.read_text() for path in SCRIPTS]
    for snippet in snippets:
        assert any(snippet in s or textwrap.dedent(snippet) in s for s in scripts), snippet


def test_the_quick_start_runs(tmp_path):
    subprocess.run([sys.executable, str(SCRIPTS[0]), str(tmp_path)], check=True)
    assert (tmp_path / "bed" / "energy.csv").exists()


def test_the_conveyor_sweep_runs_and_plots(tmp_path):
    result = subprocess.run(
        [sys.executable, str(SCRIPTS[1]), "--duration", "0.1", "--rpm", "60", "120", "--out", str(tmp_path)],
        check=True,
        capture_output=True,
        text=True,
    )
    assert "120 rpm" in result.stdout
    assert (tmp_path / "flow_against_rpm.png").stat().st_size > 10_000
    assert (tmp_path / "rpm_60" / "flow.csv").exists()
