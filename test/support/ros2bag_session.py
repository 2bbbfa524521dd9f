"""A simulated session as ``ros2 bag record -a`` receives it: topics, offered QoS, messages.

The recorder runs beside a real-time session: every loop topic per sample (the device's first,
the nodes' answers a little later), ``/clock`` (it reads it, so the device publishes it),
``/diagnostics`` once a second per node, a few ``/rosout`` lines, and ``/parameter_events``: the
nodes' declarations when they start (stamped with their own wall clock; only when the recorder
was up before them) and live changes (stamped by the loop nodes with the first sample the change
applies to). Receive times are wall-clock, each a transport delay after its send time; the bag
holds them in the order they came. The signals follow ``haptic_dob.bag.write.write_session_bag``
(``all_topics``), so a bag of ours of the same arrays is the reference.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from haptic_dob.bag.write import (
    CommandTemplate,
    ParamChange,
    joint_template,
    parameter_event,
    vector_template,
)
from haptic_msgs_py import wire
from haptic_msgs_py.stamps import NS_PER_S
from haptic_msgs_py.topics import SESSION_TOPICS
from support.ros2bag import Received, Topic, qos

WALL0_NS = 1_767_225_600 * NS_PER_S + 123_456_789  # the session's first sample, wall clock
NODES = ("device_node", "environment_node", "observer_node", "controller_node")
DEVICE = ("ee_pose", "ee_twist", "wrench_measured", "joint_states", "sim/hand_wrench")
ANSWERS = ("wrench_desired", "wrench_estimate", "effort_estimate", "effort_command")
_T = wire.TYPESTORE.types


def _topics() -> list[Topic]:
    loop = (qos(2000),)
    rclpy_nodes = len(NODES) + 1  # and the recorder's own node
    events = tuple(qos(1000) for _ in range(rclpy_nodes))
    rosout = {**qos(1000, durability="transient_local"), "lifespan": {"sec": 10, "nsec": 0}}
    return [
        *(Topic(f"/{t}", SESSION_TOPICS[t], loop) for t in (*DEVICE, *ANSWERS)),
        Topic("/clock", "rosgraph_msgs/msg/Clock", (qos(1),)),
        Topic("/parameter_events", "rcl_interfaces/msg/ParameterEvent", events),
        Topic("/rosout", "rcl_interfaces/msg/Log", tuple(rosout for _ in range(rclpy_nodes))),
        Topic(
            "/diagnostics",
            "diagnostic_msgs/msg/DiagnosticArray",
            tuple(qos(10) for _ in NODES),
        ),
    ]


def _time(ns: int) -> Any:
    sec, nsec = divmod(ns, NS_PER_S)
    return wire.Time(sec=sec, nanosec=nsec)


def _diagnostics(node: str, wall_ns: int) -> bytes:
    status = _T["diagnostic_msgs/msg/DiagnosticStatus"](
        level=0,
        name=f"{node}: loop",
        message="running",
        hardware_id="",
        values=[_T["diagnostic_msgs/msg/KeyValue"](key="cycle", value="0")],
    )
    header = _T["std_msgs/msg/Header"](stamp=_time(wall_ns), frame_id="")
    return wire.encode(_T["diagnostic_msgs/msg/DiagnosticArray"](header=header, status=[status]))


def _log(node: str, wall_ns: int, text: str) -> bytes:
    return wire.encode(
        _T["rcl_interfaces/msg/Log"](
            stamp=_time(wall_ns), level=20, name=node, msg=text, file="", function="", line=0
        )
    )


def session_as_recorded(
    x: np.ndarray,
    force: np.ndarray,
    velocity: np.ndarray,
    rate_hz: float,
    params: Mapping[str, Mapping[str, Any]],
    changes: Sequence[ParamChange] = (),
    declarations: bool = True,
    seed: int = 0,
) -> tuple[list[Topic], list[Received]]:
    """(topics, messages) of the session ``x, force, velocity`` (per sample) with the node
    parameters ``params`` at the start and ``changes`` made live; ``declarations``: the recorder
    was up before the nodes declared their parameters."""
    rng = np.random.default_rng(seed)
    period = round(NS_PER_S / rate_hz)
    out: list[Received] = []

    def got(topic: str, send_ns: int, data: bytes) -> None:
        delay = int(rng.integers(50_000, 400_000))  # transport and the recorder's turn, ns
        out.append(Received(topic, send_ns + delay, send_ns, data))

    start = WALL0_NS - 2 * NS_PER_S  # the nodes start 2 s before the first sample
    for i, node in enumerate(NODES):
        wall = start + i * 10_000_000
        got("/rosout", wall, _log(node, wall, "started"))
        if declarations and node in params:
            sim_time = {"use_sim_time": False}
            got("/parameter_events", wall, parameter_event(f"/{node}", sim_time, wall, True))
            got(
                "/parameter_events",
                wall + 1_000_000,
                parameter_event(f"/{node}", params[node], wall + 1_000_000, True),
            )
    pose, wrench, twist = (vector_template(SESSION_TOPICS[t]) for t in DEVICE[:3])
    joints, command = joint_template(), CommandTemplate()
    clock = _T["rosgraph_msgs/msg/Clock"]
    pending = sorted(changes, key=lambda c: c.index)
    xs, fs, vs = (np.asarray(a, np.float64).tolist() for a in (x, force, velocity))
    for k in range(len(xs)):
        stamp = k * period
        wall = WALL0_NS + stamp
        while pending and pending[0].index <= k:  # ros2 param set: stamped with sample k
            ch = pending.pop(0)
            event = parameter_event(f"/{ch.node}", ch.values, stamp, False)
            got("/parameter_events", wall - period // 2, event)
        xk, fk, vk = xs[k], fs[k], vs[k]
        device = (
            pose.fill(stamp, (xk, 0.0, 0.0)),
            twist.fill(stamp, (vk, 0.0, 0.0)),
            wrench.fill(stamp, (fk, 0.0, 0.0)),
            joints.fill(stamp, (xk, vk, fk)),
            wrench.fill(stamp, (-fk, 0.0, 0.0)),
        )
        for j, (topic, data) in enumerate(zip(DEVICE, device, strict=True)):
            got(f"/{topic}", wall + 5_000 * j, data)
        got("/clock", wall + 30_000, wire.encode(clock(clock=_time(stamp))))
        answers = (
            wrench.fill(stamp, (-fk, 0.0, 0.0)),
            wrench.fill(stamp, (-fk, 0.0, 0.0)),
            joints.fill(stamp, (xk, vk, fk)),
            command.fill(stamp, fk),
        )
        for j, (topic, data) in enumerate(zip(ANSWERS, answers, strict=True)):
            got(f"/{topic}", wall + 150_000 + 50_000 * j, data)
        if k % round(rate_hz) == 0:
            for i, node in enumerate(NODES):
                got("/diagnostics", wall + 200_000 + i, _diagnostics(node, wall + 200_000))
    return _topics(), out
