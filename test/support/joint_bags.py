"""Bags of a driver's ``joint_states`` as ``ros2 bag record`` would hold them (rosbags, MCAP and
sqlite3), from a 1-DOF record, an arm's record, or several joints' arrays."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

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


def write_arm_bag(
    path: Path,
    record: Any,
    effort: bool = True,
    names: Sequence[str] | None = None,
    storage: str = "mcap",
) -> Path:
    """An arm's record (``stamps_ns``, ``position``, ``effort``, ``names``) as a driver's
    ``/joint_states`` bag: every joint in one message, no velocity (a driver that sends none),
    the joints named ``names`` instead when given."""
    given = np.asarray(record.effort, np.float64) if effort else None
    names = list(names or record.names)
    return write_joint_states(path, record.stamps_ns, names, record.position, given, storage)


def write_joint_states(
    path: Path,
    stamps_ns: np.ndarray,
    names: Sequence[str],
    position: np.ndarray,
    effort: np.ndarray | None,
    storage: str = "mcap",
    topic: str = "/joint_states",
) -> Path:
    """A bag of ``topic`` holding position and effort (None: none) of ``names`` (arrays (N, n))
    and no velocity, as a position-only driver's ``joint_states``."""
    plugin = {"mcap": StoragePlugin.MCAP, "sqlite3": StoragePlugin.SQLITE3}[storage]
    writer = Writer(path, version=9, storage_plugin=plugin)
    writer.open()
    try:
        conn = writer.add_connection(topic, "sensor_msgs/msg/JointState", typestore=wire.TYPESTORE)
        msg = wire.joint_state(list(names), "base_link")
        msg.velocity = np.array([], np.float64)
        efforts = effort if effort is not None else [None] * len(stamps_ns)
        for st, q, u in zip(stamps_ns.tolist(), position, efforts, strict=True):
            msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(int(st), 10**9)
            msg.position = np.asarray(q, np.float64)
            msg.effort = np.array([], np.float64) if u is None else np.asarray(u, np.float64)
            writer.write(conn, int(st) + 1, wire.encode(msg))
    finally:
        writer.close()
    return path
