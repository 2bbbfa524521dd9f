"""Numbers out of the standard messages, for rclpy and rosbags message objects alike.

Readers only touch attributes, so they work on both rclpy's generated classes and the dataclasses
of ``rosbags`` (typed ``Any``: the two share no class).
"""

from __future__ import annotations

from typing import Any

Vec3 = tuple[float, float, float]


def read_force(msg: Any) -> Vec3:
    """Force (N) of a WrenchStamped."""
    f = msg.wrench.force
    return (f.x, f.y, f.z)
