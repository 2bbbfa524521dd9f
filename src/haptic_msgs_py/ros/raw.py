"""Raw (serialized) publishers and subscriptions that speak rosbags message objects.

rclpy needs its own message class for the type support; the payload is encoded and decoded by
``haptic_msgs_py.wire`` (the rosbags CDR codec), which is several times faster than rclpy's
per-message Python conversion on the receiving side.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import Any

from rclpy.node import Node
from rclpy.qos import QoSProfile

from haptic_msgs_py.wire import decoder, encode


def rclpy_type(typename: str) -> type:
    """The rclpy message class of ``pkg/msg/Name``."""
    pkg, _, name = typename.split("/")
    cls: type = getattr(importlib.import_module(f"{pkg}.msg"), name)
    return cls


class RawPublisher:
    """Publishes rosbags messages of one type as CDR bytes."""

    def __init__(self, node: Node, typename: str, topic: str, qos: QoSProfile) -> None:
        self.typename = typename
        self.pub = node.create_publisher(rclpy_type(typename), topic, qos)
        self._publish = self.pub.publish

    def publish(self, msg: Any) -> None:
        """Encode and send ``msg``."""
        self._publish(encode(msg))

    def get_subscription_count(self) -> int:
        """Matched subscriptions."""
        return self.pub.get_subscription_count()


def raw_subscription(
    node: Node, typename: str, topic: str, callback: Callable[[Any], None], qos: QoSProfile
) -> Any:
    """Subscribe to ``topic``; ``callback`` receives decoded rosbags messages."""
    decode = decoder(typename)

    def on_bytes(data: bytes) -> None:
        callback(decode(data))

    return node.create_subscription(rclpy_type(typename), topic, on_bytes, qos, raw=True)
