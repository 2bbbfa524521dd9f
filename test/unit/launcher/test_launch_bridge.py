"""haptic-launch of a config with a bridge to a real driver: the bridge composed with the loop in
the device's place, a teleoperation side with a bridge, a URDF beside the config or from the
driver's topic."""

from __future__ import annotations

from pathlib import Path

import pytest

from haptic_dob.errors import InputError
from haptic_dob.launcher.node_params import add_recorder, resolved_params
from haptic_dob.launcher.process_plan import groups_for
from haptic_dob.launcher.robot_description import fill
from haptic_dob.launcher.teleop import add_teleop_recorder, teleop_params
from haptic_dob.nodes.registry import START_ORDER
from haptic_dob.teleop.graph import RECORDER, load_teleop_sections


def test_the_bridge_is_composed_with_the_loop_and_starts_last(root: Path) -> None:
    params = resolved_params(root / "config" / "bridge_forcedimension.yaml", {})
    names = [n for n in START_ORDER if n in params]
    assert names[-1] == "bridge_node"
    assert groups_for(names, False, False, ()) == [
        ["bridge_node", "environment_node", "observer_node", "controller_node"]
    ]
    # a relative urdf_path is the config's neighbour, whatever the working directory
    assert params["/**"]["urdf_path"] == str(root / "config" / "urdf" / "fd_cartesian.urdf")
    add_recorder(params, str(root / "no-such-bag"), "mcap")
    assert params["bridge_node"]["wait_for"][-1] == "recorder_node"
    assert "device_node" not in params


def test_a_teleoperation_side_with_a_bridge_in_its_devices_place(root: Path) -> None:
    sections = load_teleop_sections(root / "config" / "bridge_arm_teleop.yaml")
    params = teleop_params(sections, ["slave/bridge_node:duration_s=2"])
    assert list(params)[-2:] == ["master/device_node", "slave/bridge_node"]
    assert params["slave/bridge_node"]["duration_s"] == 2
    assert params["slave/channel_node"]["wait_for_peer"] is False  # a driver is real time
    assert params["slave/bridge_node"]["command_source"] == "slave_controller_node"
    add_teleop_recorder(params, str(root / "no-such-bag"), "mcap")
    assert params["slave/bridge_node"]["wait_for"][-1] == RECORDER


def test_the_robot_description_goes_to_every_urdf_model() -> None:
    params = {"/**": {"model": "urdf", "urdf_path": "a.urdf"}, "controller_node": {"kf": 1.0}}
    assert fill(params, "<robot/>") == 1
    assert params["/**"]["robot_description"] == "<robot/>"
    with pytest.raises(InputError, match="no node of the config has model: urdf"):
        fill({"/**": {"model": "slide"}}, "<robot/>")
