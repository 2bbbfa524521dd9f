"""``haptic-launch --robot-description TOPIC``: the model's URDF from a running driver's topic.

A ros2_control arm's bringup latches its URDF on a topic (``robot_state_publisher``'s
``robot_description``: ``std_msgs/String``, transient local). The launcher reads it once,
before any node starts, and hands it to every node whose model is ``urdf`` as its
``robot_description`` parameter (which wins over ``urdf_path``), so the loop's model is the
driver's own.
"""

from __future__ import annotations

import os
import time
from collections.abc import Mapping
from typing import Any

from haptic_dob.errors import InputError

WAIT_S = 10.0  # how long the launcher waits for the latched description


def fetch(topic: str, env: Mapping[str, str], wait_s: float = WAIT_S) -> str:
    """The URDF text latched on ``topic``, discovered with the nodes' environment ``env``;
    ``InputError`` when none comes within ``wait_s``."""
    import rclpy  # lazy: only this option needs the launcher itself on the graph
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from rclpy.utilities import try_shutdown
    from std_msgs.msg import String

    saved = {k: os.environ.get(k) for k in env}
    os.environ.update(env)
    context = Context()
    try:
        rclpy.init(context=context, args=[])
        node = rclpy.create_node(
            "haptic_launch_robot_description", context=context, start_parameter_services=False
        )
        got: list[str] = []
        latched = QoSProfile(
            depth=1,
            reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.TRANSIENT_LOCAL,
        )

        def take(msg: Any) -> None:
            got.append(str(msg.data))

        node.create_subscription(String, topic, take, latched)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        end = time.monotonic() + wait_s
        while not got and time.monotonic() < end:
            executor.spin_once(timeout_sec=0.05)
        executor.shutdown()
        node.destroy_node()
    finally:
        try_shutdown(context=context)
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
    if not got:
        raise InputError(
            f"--robot-description: nothing on {topic} within {wait_s:g} s (is the driver's "
            "robot_state_publisher up, and on this ROS_DOMAIN_ID?)"
        )
    return got[0]


def fill(params: Mapping[str, Any], urdf: str) -> int:
    """Give every parameter section whose ``model`` is ``urdf`` the URDF text; how many got it
    (``InputError`` when none names a urdf model)."""
    count = 0
    for values in params.values():
        if values.get("model") == "urdf":
            values["robot_description"] = urdf
            count += 1
    if not count:
        raise InputError("--robot-description: no node of the config has model: urdf")
    return count
