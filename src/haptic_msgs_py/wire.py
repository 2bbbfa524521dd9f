"""Messages on the wire: the ``rosbags`` CDR codec and message classes, for nodes and bags alike.

The loop's nodes publish and subscribe raw (serialized) messages and use the ``rosbags``
type store (ROS 2 Jazzy definitions) to encode and decode them: its generated codec is several
times faster than rclpy's Python message conversion of each received message (BENCHMARKS.md has
the figures). The bytes are the same CDR rclpy produces,
so any ROS 2 node (``ros2 topic echo``, a C++ driver) talks to these nodes as usual, and the
same message classes come out of recorded bags.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from rosbags.typesys import Stores, get_typestore

TYPESTORE = get_typestore(Stores.ROS2_JAZZY)
_types = TYPESTORE.types

Time = _types["builtin_interfaces/msg/Time"]
Header = _types["std_msgs/msg/Header"]
Vector3 = _types["geometry_msgs/msg/Vector3"]
Point = _types["geometry_msgs/msg/Point"]
Quaternion = _types["geometry_msgs/msg/Quaternion"]
Pose = _types["geometry_msgs/msg/Pose"]
Twist = _types["geometry_msgs/msg/Twist"]
Wrench = _types["geometry_msgs/msg/Wrench"]
PoseStamped = _types["geometry_msgs/msg/PoseStamped"]
TwistStamped = _types["geometry_msgs/msg/TwistStamped"]
WrenchStamped = _types["geometry_msgs/msg/WrenchStamped"]
JointState = _types["sensor_msgs/msg/JointState"]
Float64MultiArray = _types["std_msgs/msg/Float64MultiArray"]
MultiArrayLayout = _types["std_msgs/msg/MultiArrayLayout"]
MultiArrayDimension = _types["std_msgs/msg/MultiArrayDimension"]
Clock = _types["rosgraph_msgs/msg/Clock"]

_serialize = TYPESTORE.serialize_cdr
_deserialize = TYPESTORE.deserialize_cdr


def encode(msg: Any) -> bytes:
    """CDR bytes of a rosbags message (what rclpy's ``publish`` of raw bytes sends)."""
    return bytes(_serialize(msg, msg.__msgtype__))


def decoder(typename: str) -> Callable[[bytes | memoryview], Any]:
    """A one-argument function turning CDR bytes of ``typename`` into a rosbags message."""

    def decode(data: bytes | memoryview) -> Any:
        return _deserialize(data, typename)

    return decode


def _vec() -> Any:
    return Vector3(x=0.0, y=0.0, z=0.0)


def header(frame_id: str = "") -> Any:
    """A Header at time zero."""
    return Header(stamp=Time(sec=0, nanosec=0), frame_id=frame_id)


def wrench_stamped(frame_id: str = "") -> Any:
    """A zero WrenchStamped."""
    return WrenchStamped(header=header(frame_id), wrench=Wrench(force=_vec(), torque=_vec()))


def pose_stamped(frame_id: str = "") -> Any:
    """A PoseStamped at the origin with identity orientation."""
    return PoseStamped(
        header=header(frame_id),
        pose=Pose(
            position=Point(x=0.0, y=0.0, z=0.0), orientation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0)
        ),
    )


def twist_stamped(frame_id: str = "") -> Any:
    """A zero TwistStamped."""
    return TwistStamped(header=header(frame_id), twist=Twist(linear=_vec(), angular=_vec()))


def joint_state(names: Sequence[str], frame_id: str = "") -> Any:
    """A JointState for ``names`` with empty position, velocity and effort."""
    empty = np.zeros(0)
    return JointState(
        header=header(frame_id), name=list(names), position=empty, velocity=empty, effort=empty
    )


def float64_multi_array(label: str, data: Sequence[float]) -> Any:
    """A Float64MultiArray with one labelled dimension."""
    n = len(data)
    return Float64MultiArray(
        layout=MultiArrayLayout(
            dim=[MultiArrayDimension(label=label, size=n, stride=n)], data_offset=0
        ),
        data=np.asarray(data, dtype=np.float64),
    )


def clock() -> Any:
    """A Clock at time zero."""
    return Clock(clock=Time(sec=0, nanosec=0))
