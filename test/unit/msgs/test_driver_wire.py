"""The bridge's commands to drivers, byte for byte what the rosbags serializer writes."""

from __future__ import annotations

import numpy as np
import pytest

from haptic_msgs_py import wire
from haptic_msgs_py.driver_wire import command_encoder, deadman_reader

T = wire.TYPESTORE.types
STAMP = 1_795_000_123_456_789


def vec(x: float, y: float, z: float) -> object:
    return wire.Vector3(x=x, y=y, z=z)


def test_a_forward_command_controllers_array_labelled_with_the_sample() -> None:
    got = command_encoder("float64_multi_array")(STAMP, (1.5, -2.0, 0.25))
    assert got == wire.encode(wire.float64_multi_array(f"effort@{STAMP}", [1.5, -2.0, 0.25]))


@pytest.mark.parametrize("frame", ["", "fd_base", "touch_base_link"])
def test_a_wrench_stamped_with_the_force_and_zero_torque(frame: str) -> None:
    got = command_encoder("wrench_stamped", frame)(STAMP, (1.0, 2.0, -3.0))
    msg = wire.wrench_stamped(frame)
    msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(STAMP, 1_000_000_000)
    msg.wrench.force = vec(1.0, 2.0, -3.0)
    assert got == wire.encode(msg)


def test_a_wrench_and_a_vector3() -> None:
    wrench = T["geometry_msgs/msg/Wrench"](force=vec(1.0, 2.0, 3.0), torque=vec(0.0, 0.0, 0.0))
    assert command_encoder("wrench")(STAMP, (1.0, 2.0, 3.0)) == wire.encode(wrench)
    assert command_encoder("vector3")(STAMP, (1.0, 2.0, 3.0)) == wire.encode(vec(1.0, 2.0, 3.0))
    with pytest.raises(ValueError, match="no command type"):
        command_encoder("twist")


def test_the_deadman_as_a_bool_or_a_joy_button() -> None:
    held = deadman_reader("bool", 0)
    assert held(wire.encode(T["std_msgs/msg/Bool"](data=True)))
    assert not held(wire.encode(T["std_msgs/msg/Bool"](data=False)))
    white = deadman_reader("joy", 1)

    def joy(*buttons: int) -> bytes:
        return wire.encode(
            T["sensor_msgs/msg/Joy"](
                header=wire.header(""),
                axes=np.zeros(0, dtype=np.float32),
                buttons=np.array(buttons, dtype=np.int32),
            )
        )

    assert white(joy(0, 1)) and not white(joy(1, 0)) and not white(joy(1))
