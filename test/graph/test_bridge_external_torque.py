"""The observer's external joint torque as other tools publish it: a ``sensor_msgs/JointState``
with names and efforts only, in the driver's joint names, beside the suite's ``effort_estimate``
(in the model's), to a best-effort reader (as ``ext_observer_ros`` subscribes) and a reliable one
(as franka_ros2's ``external_joint_torques`` readers do)."""

from __future__ import annotations

import time

import pytest

from support.drivers.run import SLIDE_HAND, Controls, start
from support.paths import ROOT
from support.rosgraph import Collector, isolated_env, launch

pytestmark = [pytest.mark.multiprocess]

TOPIC = "/touch/external_joint_torques"
JOINT_STATE = "sensor_msgs/msg/JointState"


def test_external_joint_torques_in_the_drivers_names(tmp_path) -> None:
    env = isolated_env()
    hand = {**SLIDE_HAND, "offset_m": 0.012}
    drv = start(
        {"kind": "touch", "rate_hz": 500.0, "hand": hand, "hand_direction": [0, 0, -1]},
        env,
        tmp_path / "driver",
    )
    controls = Controls(env, "/touch")
    reliable = Collector(
        env,
        {TOPIC: JOINT_STATE, "/haptic/effort_estimate": JOINT_STATE},
        name="reliable",
        back_pressure=False,
    )
    sensor_data = Collector(env, {TOPIC: JOINT_STATE}, name="sensor_data", best_effort=True)
    graph = launch(
        str(ROOT / "config" / "bridge_touch.yaml"),
        env,
        ["bridge_node:duration_s=3.0", f"bridge_node:external_torque_topic={TOPIC}"],
        tmp_path / "launch.log",
        extra=["--namespace", "/haptic"],
    )
    try:
        controls.hold(graph.output)
        assert graph.wait(120) == 0, graph.output()
        time.sleep(0.3)
    finally:
        graph.stop()
        controls.close()
        drv.stop()
        sensor_data.close()
        reliable.close()
    ext = reliable.messages(TOPIC)
    ours = {
        m.header.stamp.sec * 10**9 + m.header.stamp.nanosec: m
        for m in reliable.messages("/haptic/effort_estimate")
    }
    assert len(ext) >= 100 and len(sensor_data.messages(TOPIC)) >= 50  # it flows
    for m in ext[-200:]:
        assert list(m.name) == ["waist", "shoulder", "elbow"]
        assert len(m.position) == 0 and len(m.velocity) == 0 and len(m.effort) == 3
        same = ours.get(m.header.stamp.sec * 10**9 + m.header.stamp.nanosec)
        if same is not None:  # the same values (the URDF's names are the driver's, signs +1)
            assert list(same.name) == ["waist", "shoulder", "elbow"]
            assert list(m.effort) == pytest.approx(list(same.effort))
    assert any(abs(e) > 1e-3 for m in ext for e in m.effort)
