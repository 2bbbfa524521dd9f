"""The suite's own contract through the bridge (``config/bridge_suite.yaml``, profile ``suite``):
a simulated device in real time in a namespace of its own is the driver, the loop in another;
the bridge passes its ``joint_states`` (effort included) and the loop's ``effort_command``
through, and the device applies the commands (the wall pushing back on its hand), on time or
not: real time is not this test's premise."""

from __future__ import annotations

import json

import pytest

from support.paths import ROOT
from support.rosgraph import Collector, isolated_env, launch

pytestmark = [pytest.mark.multiprocess]


def test_a_suite_device_elsewhere_closes_the_loop_through_the_bridge(tmp_path) -> None:
    env = isolated_env()
    states = {"/device/joint_states": "sensor_msgs/msg/JointState"}
    col = Collector(env, states, name="watch", back_pressure=False)
    device = launch(
        str(ROOT / "config" / "slide_sim.yaml"),
        env,
        [
            "device_node:clock_mode=realtime",
            "device_node:wait_for=[]",
            "device_node:duration_s=0",
            # its commands come from the bridge, which labels them with no command token
            "device_node:open_command_input=true",
            f"device_node:stats_file={tmp_path / 'device.json'}",
        ],
        tmp_path / "device.log",
        extra=["--only", "device_node", "--namespace", "/device"],
    )
    # the device ticks before the loop starts (its start-up may take seconds on a loaded machine)
    assert col.wait_for("/device/joint_states", 1, 120.0), device.output()
    graph = launch(
        str(ROOT / "config" / "bridge_suite.yaml"),
        env,
        ["bridge_node:duration_s=3.0", f"bridge_node:stats_file={tmp_path / 'bridge.json'}"],
        tmp_path / "launch.log",
        extra=["--namespace", "/haptic"],
    )
    try:
        assert graph.wait(120) == 0, graph.output()
    finally:
        graph.stop()
        device.stop()
        col.close()
    b = json.loads((tmp_path / "bridge.json").read_text())
    d = json.loads((tmp_path / "device.json").read_text())
    assert b["handed_on"] >= 300 and b["refused_commands"] == 0, b
    assert b["commands_on_time"] + b["commands_late"] >= 0.9 * b["handed_on"], b
    assert d["refused_commands"] == 0, d
    applied = [m.effort[0] for m in col.messages("/device/joint_states") if len(m.effort)]
    assert sum(abs(e) > 0.05 for e in applied) >= 50  # the wall's force, through the bridge
