"""A foreign driver's topics as the bridge meets them: raw bytes, the driver's QoS, and a QoS
mismatch said out loud (ROS drops traffic between incompatible endpoints without a word, the
complaint of lbr_fri_ros2_stack #115)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
from rclpy.node import Node

from haptic_msgs_py.ros import qos
from haptic_msgs_py.ros.raw import rclpy_type

Say = Callable[[str], None]


def _mismatch(topic: str, say: Say) -> Callable[[Any], None]:
    def tell(event: Any) -> None:
        say(
            f"{topic}: a peer's QoS is incompatible ({event.last_policy_kind.name}), nothing "
            "passes between them: check state.reliability / command.reliability"
        )

    return tell


def driver_publisher(
    node: Node, typename: str, topic: str, reliability: str, depth: int, say: Say
) -> Callable[[bytes], None]:
    """A publisher of ``typename`` CDR bytes on ``topic``; its ``publish``."""
    pub = node.create_publisher(
        rclpy_type(typename),
        topic,
        qos.driver(reliability, depth),
        event_callbacks=PublisherEventCallbacks(incompatible_qos=_mismatch(topic, say)),
    )
    send: Callable[[bytes], None] = pub.publish
    return send


def driver_subscription(
    node: Node,
    typename: str,
    topic: str,
    callback: Callable[[bytes], None],
    reliability: str,
    depth: int,
    say: Say,
) -> Any:
    """A subscription handing ``callback`` the CDR bytes of ``typename`` messages."""
    return node.create_subscription(
        rclpy_type(typename),
        topic,
        callback,
        qos.driver(reliability, depth),
        raw=True,
        event_callbacks=SubscriptionEventCallbacks(incompatible_qos=_mismatch(topic, say)),
    )
