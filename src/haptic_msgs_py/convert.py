"""Numbers in and out of the standard messages, for rclpy and rosbags message objects alike.

Readers only touch attributes, so they work on both rclpy's generated classes and the dataclasses
of ``rosbags``; writers fill an existing message in place (no allocation per cycle).
"""

from __future__ import annotations

from collections.abc import Sequence

Vec3 = tuple[float, float, float]


def set_stamp(msg: object, sec: int, nanosec: int) -> None:
    """Set ``msg.header.stamp``."""
    st = msg.header.stamp  # type: ignore[attr-defined]
    st.sec = sec
    st.nanosec = nanosec


def read_force(msg: object) -> Vec3:
    """Force (N) of a WrenchStamped."""
    f = msg.wrench.force  # type: ignore[attr-defined]
    return (f.x, f.y, f.z)


def write_force(msg: object, force: Sequence[float]) -> None:
    """Set the force (N) of a WrenchStamped; the torque stays as it is."""
    f = msg.wrench.force  # type: ignore[attr-defined]
    f.x, f.y, f.z = float(force[0]), float(force[1]), float(force[2])


def read_position(msg: object) -> Vec3:
    """Position (m) of a PoseStamped."""
    p = msg.pose.position  # type: ignore[attr-defined]
    return (p.x, p.y, p.z)


def write_position(msg: object, p: Sequence[float]) -> None:
    """Set the position (m) of a PoseStamped."""
    pos = msg.pose.position  # type: ignore[attr-defined]
    pos.x, pos.y, pos.z = float(p[0]), float(p[1]), float(p[2])


def read_linear(msg: object) -> Vec3:
    """Linear velocity (m/s) of a TwistStamped."""
    v = msg.twist.linear  # type: ignore[attr-defined]
    return (v.x, v.y, v.z)


def write_linear(msg: object, v: Sequence[float]) -> None:
    """Set the linear velocity (m/s) of a TwistStamped."""
    lin = msg.twist.linear  # type: ignore[attr-defined]
    lin.x, lin.y, lin.z = float(v[0]), float(v[1]), float(v[2])
