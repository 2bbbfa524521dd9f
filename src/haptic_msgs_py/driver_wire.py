"""What foreign drivers take and give, as CDR bytes: the bridge's commands and inputs.

Commands go out on the 1 kHz path, so they are packed with ``struct`` like the loop's own
messages (``cdr``): ``std_msgs/Float64MultiArray`` (a ros2_control forward command controller's
``commands``, labelled with the sample it answers, which such a controller ignores),
``geometry_msgs/WrenchStamped``, ``Wrench`` and ``Vector3`` (a force; torque zero). States come
in as ``sensor_msgs/JointState`` or ``geometry_msgs/PoseStamped`` (``codecs``); the dead-man as
``std_msgs/Bool`` or ``sensor_msgs/Joy`` (``wire``, rarely and off the command's path).
Tests check every layout byte for byte against the ``rosbags`` serializer.
"""

from __future__ import annotations

import struct
from collections.abc import Callable, Sequence

from haptic_msgs_py import cdr, wire
from haptic_msgs_py.stamps import command_label

Encoder = Callable[[int, Sequence[float]], bytes]

#: the ROS type of each command kind (``bridge.driver_settings.COMMAND_TYPES``)
COMMAND_TYPENAMES = {
    "float64_multi_array": "std_msgs/msg/Float64MultiArray",
    "wrench_stamped": "geometry_msgs/msg/WrenchStamped",
    "wrench": "geometry_msgs/msg/Wrench",
    "vector3": "geometry_msgs/msg/Vector3",
}
#: the ROS type of each state kind (``bridge.state_settings.STATE_TYPES``)
STATE_TYPENAMES = {
    "joint_states": "sensor_msgs/msg/JointState",
    "pose": "geometry_msgs/msg/PoseStamped",
}
#: the ROS type of each dead-man kind
DEADMAN_TYPENAMES = {"bool": "std_msgs/msg/Bool", "joy": "sensor_msgs/msg/Joy"}

_WRENCH = struct.Struct("<4s6d")
_VECTOR3 = struct.Struct("<4s3d")


def command_encoder(kind: str, frame_id: str = "") -> Encoder:
    """A function (stamp of the sample answered in ns, values) -> CDR bytes of command ``kind``:
    joint values for ``float64_multi_array``, the force (x, y, z) for the others."""
    if kind == "float64_multi_array":

        def array(stamp_ns: int, values: Sequence[float]) -> bytes:
            return cdr.pack_multi_array(command_label(stamp_ns), values)

        return array
    if kind == "wrench_stamped":
        pack = cdr.VectorLayout(frame_id, (0.0, 0.0, 0.0)).pack

        def stamped(stamp_ns: int, values: Sequence[float]) -> bytes:
            return pack(stamp_ns, values)

        return stamped
    if kind == "wrench":

        def wrench(_stamp_ns: int, values: Sequence[float]) -> bytes:
            return _WRENCH.pack(cdr.LE, *values, 0.0, 0.0, 0.0)

        return wrench
    if kind == "vector3":

        def vector3(_stamp_ns: int, values: Sequence[float]) -> bytes:
            return _VECTOR3.pack(cdr.LE, *values)

        return vector3
    raise ValueError(f"no command type {kind!r}; one of {', '.join(COMMAND_TYPENAMES)}")


def deadman_reader(kind: str, button: int) -> Callable[[bytes | memoryview], bool]:
    """A function CDR bytes -> whether the dead-man is held: a ``Bool``'s data, or a ``Joy``'s
    button ``button`` (a message without that button reads as released)."""
    decode = wire.decoder(DEADMAN_TYPENAMES[kind])
    if kind == "bool":
        return lambda data: bool(decode(data).data)

    def joy(data: bytes | memoryview) -> bool:
        buttons = decode(data).buttons
        return len(buttons) > button and bool(buttons[button])

    return joy
