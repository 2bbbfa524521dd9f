"""A config's relative ``urdf_path``: beside the config where the file is, else as given."""

from __future__ import annotations

from pathlib import Path

from haptic_dob.launcher import resolved_params
from haptic_sim.arm.session import ArmSessionConfig
from haptic_sim.device.batch import load_session
from support.paths import ROOT

YAML = """/**:
  ros__parameters:
    model: urdf
    urdf_path: {path}
    tip_frame: tip
"""


def test_a_urdf_beside_the_config_is_found_from_anywhere(tmp_path: Path, monkeypatch) -> None:
    (tmp_path / "urdf").mkdir()
    urdf = tmp_path / "urdf" / "touch.urdf"
    urdf.write_text((ROOT / "config" / "urdf" / "phantom_omni.urdf").read_text())
    config = tmp_path / "touch.yaml"
    config.write_text(YAML.format(path="urdf/touch.urdf"))
    monkeypatch.chdir(ROOT)  # elsewhere than the config
    assert resolved_params(config, {})["/**"]["urdf_path"] == str(urdf)
    assert load_session(config)["/**"]["urdf_path"] == str(urdf)
    assert ArmSessionConfig.from_yaml(config).plant.joint_names == ("waist", "shoulder", "elbow")


def test_a_path_not_beside_the_config_stays_relative_to_the_working_directory(
    tmp_path: Path,
) -> None:
    config = tmp_path / "arm.yaml"
    config.write_text(YAML.format(path="config/urdf/arm3.urdf"))
    assert resolved_params(config, {})["/**"]["urdf_path"] == "config/urdf/arm3.urdf"
