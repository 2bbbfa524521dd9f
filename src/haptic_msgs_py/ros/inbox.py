"""A topic read the way a driver's update reads its commands: by DDS reception time."""

from __future__ import annotations

from collections import deque
from typing import Any

from rclpy.node import Node
from rclpy.qos import QoSProfile

from haptic_msgs_py.ros.raw import rclpy_type


class Inbox:
    """One command topic read the way a driver's update reads it: by reception time.

    A real driver's update runs on its own clock and takes what DDS received before it
    (ros2_control's realtime buffer, written by another thread), however late a Python test
    driver's tick runs. So the subscription sits on a node of its own that no executor spins: a
    message waits in DDS until ``take`` (the reader's ``qos`` depth bounds how many wait), and
    the driver takes at each tick those received before the tick's instant.
    """

    def __init__(self, node: Any, typename: str, topic: str, qos: QoSProfile) -> None:
        self._node = Node(f"{node.get_name()}_inbox", context=node.context)
        self._sub = self._node.create_subscription(
            rclpy_type(typename), topic, lambda _data: None, qos, raw=True
        )
        self._later: deque[tuple[int, bytes]] = deque()  # received after a tick's instant

    def take(self, before_ns: int | None = None) -> list[tuple[int, bytes]]:
        """Every message DDS received before ``before_ns`` (system clock; None: all), oldest
        first, as (reception ns, serialized message); later ones wait for the next take."""
        with self._sub.handle:
            while (got := self._sub.handle.take_message(self._sub.msg_type, True)) is not None:
                self._later.append((int(got[1]["received_timestamp"]), got[0]))
        out = []
        while self._later and (before_ns is None or self._later[0][0] < before_ns):
            out.append(self._later.popleft())
        return out

    def close(self) -> None:
        self._node.destroy_node()
