"""Bags of a driver's ``joint_states`` as ``ros2 bag record`` would hold them (rosbags, MCAP and
sqlite3), from a 1-DOF record."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from rosbags.rosbag2 import StoragePlugin, Writer

from haptic_dob.identification.one_dof import JointRecord
from haptic_msgs_py import wire


def write_bag(
    path: Path,
    rec: JointRecord,
    storage: str,
    effort: bool = True,
    topic: str = "/joint_states",
    stamped: bool = True,
) -> Path:
    """A bag as ``ros2 bag record /joint_states`` of a driver would hold it."""
    plugin = {"mcap": StoragePlugin.MCAP, "sqlite3": StoragePlugin.SQLITE3}[storage]
    writer = Writer(path, version=9, storage_plugin=plugin)
    writer.open()
    try:
        conn = writer.add_connection(topic, "sensor_msgs/msg/JointState", typestore=wire.TYPESTORE)
        msg = wire.joint_state(["slide"], "base_link")
        for st, q, u in zip(rec.stamps_ns.tolist(), rec.position, rec.effort, strict=True):
            msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(int(st) * stamped, 10**9)
            msg.position = np.array([q])
            msg.velocity = np.array([0.0])
            msg.effort = np.array([u]) if effort else np.array([], np.float64)
            writer.write(conn, int(st) + 1, wire.encode(msg))
    finally:
        writer.close()
    return path
