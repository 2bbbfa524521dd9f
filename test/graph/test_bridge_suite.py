"""The suite's own contract through the bridge (profile ``suite``): a simulated device in real
time in a namespace of its own is the driver, the loop in another; the bridge passes its
``joint_states`` (effort included) and the loop's ``effort_command`` through unchanged."""

from __future__ import annotations

import json

import pytest
import yaml

from haptic_dob.runtime.params import load_sections
from support.paths import BIN, ROOT
from support.rosgraph import Process, isolated_env, launch

pytestmark = [pytest.mark.multiprocess]


def test_a_suite_device_elsewhere_closes_the_loop_through_the_bridge(tmp_path) -> None:
    sections = load_sections(ROOT / "config" / "slide_sim.yaml")
    device = {**sections["/**"], **sections["/**/device_node"]}
    device.update(clock_mode="realtime", duration_s=0.0, wait_for=[])
    device["stats_file"] = str(tmp_path / "device.json")
    bridge = {
        "profile": "suite",
        "state": {"topic": "/dev/joint_states"},
        "command": {"topic": "/dev/effort_command"},
        "safety": {"command_limits": [4.0]},
        "duration_s": 3.0,
        "stats_file": str(tmp_path / "bridge.json"),
    }
    config = {
        "/**": {"ros__parameters": sections["/**"]},
        "/**/bridge_node": {"ros__parameters": bridge},
        **{
            f"/**/{n}": {"ros__parameters": sections[f"/**/{n}"]}
            for n in ("environment_node", "observer_node", "controller_node")
        },
    }
    cfg = tmp_path / "suite.yaml"
    cfg.write_text(yaml.safe_dump(config))
    dev_params = tmp_path / "device.yaml"
    dev_params.write_text(yaml.safe_dump({"/**/device_node": {"ros__parameters": device}}))
    env = isolated_env()
    argv = [str(BIN / "haptic-device-node"), "--ros-args", "--params-file", str(dev_params)]
    dev = Process([*argv, "-r", "__ns:=/dev"], env, tmp_path / "device.log")
    graph = launch(str(cfg), env, [], tmp_path / "launch.log", extra=["--namespace", "/haptic"])
    try:
        assert graph.wait(120) == 0, graph.output()
    finally:
        graph.stop()
        dev.stop()
    b = json.loads((tmp_path / "bridge.json").read_text())
    d = json.loads((tmp_path / "device.json").read_text())
    assert b["handed_on"] >= 300 and b["refused_commands"] == 0, b
    assert b["commands_on_time"] + b["commands_late"] >= 0.9 * b["handed_on"], b
    assert d["commands_on_time"] >= 300 and d["refused_commands"] == 0, d
