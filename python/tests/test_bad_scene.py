"""A scene that cannot be run raises polydem.SceneError naming the file, line and key."""

import pytest

import polydem
from conftest import to_toml


def test_a_bad_value_in_a_file_names_file_line_and_key(bed, tmp_path):
    bed["material"][0]["poisson_ratio"] = 0.7
    scene = tmp_path / "bad.toml"
    scene.write_text(to_toml(bed))
    with pytest.raises(polydem.SceneError) as caught:
        polydem.Simulation(scene, tmp_path / "out")
    message = str(caught.value)
    assert "bad.toml:" in message
    assert "[[material]] #1 poisson_ratio" in message
    assert "must lie in (-1, 0.5)" in message
    assert caught.value.key == "[[material]] #1 poisson_ratio"
    assert caught.value.file.endswith("bad.toml")
    line = scene.read_text().splitlines()[caught.value.line - 1]
    assert line.startswith("poisson_ratio")
    # Nothing was written for a scene that cannot run.
    assert not (tmp_path / "out").exists()


def test_a_bad_value_in_a_dict_names_the_key(bed, tmp_path):
    bed["material"][0]["restitution"] = 1.5
    with pytest.raises(polydem.SceneError, match=r"<dict>:\d+: \[\[material\]\] #1 restitution"):
        polydem.Simulation(bed, tmp_path / "out")


def test_an_unknown_key_is_named_with_what_is_allowed(bed, tmp_path):
    bed["material"][0]["densty"] = 1.0
    with pytest.raises(polydem.SceneError, match="unknown field `densty`"):
        polydem.Simulation(bed, tmp_path / "out")


def test_a_missing_material_is_named(bed, tmp_path):
    bed["plane"][0]["material"] = "steel"
    with pytest.raises(polydem.SceneError) as caught:
        polydem.Simulation(bed, tmp_path / "out")
    assert "[[plane]] #1 material" in str(caught.value)
    assert "no material named 'steel'" in str(caught.value)


def test_a_bad_override_names_itself(bed, tmp_path):
    with pytest.raises(polydem.SceneError, match="material"):
        polydem.Simulation(bed, tmp_path / "out", set={"material[5].friction": 0.3})


def test_a_missing_file_is_named(tmp_path):
    with pytest.raises(polydem.SceneError, match="nowhere.toml"):
        polydem.Simulation(tmp_path / "nowhere.toml")


def test_values_that_are_no_scene_values_are_refused(bed, tmp_path):
    bed["simulation"]["duration"] = object()
    with pytest.raises(ValueError, match="simulation.duration"):
        polydem.Simulation(bed, tmp_path / "out")
