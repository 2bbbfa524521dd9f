"""What each test driver speaks on the wire, as the real drivers do (read from their sources).

- ``Ros2Control`` (forcedimension_ros2, a Franka or UR arm): ``<ns>/joint_states`` (position,
  velocity, effort; reliable) and ``<ns>/<controller>/commands`` (``Float64MultiArray`` in the
  controller's ``joints`` order). A non-finite command is dropped; one of the wrong size is held
  and fails every update; the newest command is written at the next update (cycle k+1) and held
  forever (ros2_controllers #95).
- ``Touch`` (AleBarte/Geomagic_Touch_ROS2_Drivers) at 500 Hz, ``SensorDataQoS``:
  ``<ns>/joint_states`` with positions only (phantom_omni.urdf's joints, named and signed as
  ``omni_state.cpp`` publishes them), the buttons as ``sensor_msgs/Joy`` on change (grey,
  white), and ``<ns>/force_feedback`` (``WrenchStamped``, reliable) applied on arrival only while
  the white button is held, clamped to the device's maximum, in the pose frame (the URDF's base
  frame, no axis map; docs/devices.md has the driver's lines).

Both take their commands through an ``Inbox``, by DDS reception time."""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from haptic_msgs_py import codecs, wire
from haptic_msgs_py.ros.inbox import Inbox
from haptic_msgs_py.ros.raw import rclpy_type
from haptic_msgs_py.values import JointSample

SYSTEM_DEFAULT = QoSProfile(
    history=HistoryPolicy.KEEP_LAST, depth=10, reliability=ReliabilityPolicy.RELIABLE
)
SENSOR_DATA = QoSProfile(
    history=HistoryPolicy.KEEP_LAST, depth=5, reliability=ReliabilityPolicy.BEST_EFFORT
)
LATCHED = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=1,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
)

#: a command taken: (stamp of the state it answers in ns or None, values, reception time in
#: system-clock ns)
Received = Callable[[int | None, tuple[float, ...], int], None]


def instant_ns(deadline: float) -> int:
    """Monotonic ``deadline`` (s) on the system clock (ns), as reception times are."""
    return time.time_ns() - round((time.monotonic() - deadline) * 1e9)


class Ros2Control:
    """A ros2_control driver's topics and its forward command controller's semantics.

    Args:
        node: the driver's node.
        ns: the controller manager's namespace (``/fd``).
        controller: the forward command controller's name.
        state_joints: the joint names ``joint_states`` carries, in its order.
        command_joints: the controller's ``joints`` parameter.
        received: told of every command taken (what it answers, its values).
    """

    def __init__(
        self,
        node: Any,
        ns: str,
        controller: str,
        state_joints: Sequence[str],
        command_joints: Sequence[str],
        received: Received,
    ) -> None:
        self.state_joints = tuple(state_joints)
        self.command_joints = tuple(command_joints)
        self._encode = codecs.JOINT_STATE.encoder("")
        self._pub = node.create_publisher(
            rclpy_type("sensor_msgs/msg/JointState"), f"{ns}/joint_states", SYSTEM_DEFAULT
        )
        self.inbox = Inbox(
            node, "std_msgs/msg/Float64MultiArray", f"{ns}/{controller}/commands", SYSTEM_DEFAULT
        )
        self._received = received
        self.held: tuple[float, ...] | None = None  # the newest message taken (never expires)
        self.written = (0.0,) * len(command_joints)  # the command interfaces' values
        self.nonfinite_dropped = 0
        self.size_errors = 0  # updates that failed on a held command of the wrong size

    def receive(self, before_ns: int | None) -> None:
        """Take the commands DDS received before ``before_ns`` (system ns; None: all)."""
        for received_ns, data in self.inbox.take(before_ns):
            cmd = codecs.EFFORT.decode(data)
            if not all(map(math.isfinite, cmd.effort)):
                self.nonfinite_dropped += 1  # "Non-finite value received. Dropping message"
                continue
            self.held = tuple(cmd.effort)
            self._received(cmd.stamp_ns, self.held, received_ns)

    def update(self) -> tuple[float, ...]:
        """The controller's update at a cycle (after ``receive``): the newest command written,
        or an error."""
        if self.held is not None:
            if len(self.held) == len(self.command_joints):
                self.written = self.held
            else:
                self.size_errors += 1  # "command size does not match number of interfaces"
        return self.written

    def publish(self, stamp_ns: int, names: Sequence[str], q: Any, qd: Any, effort: Any) -> None:
        """``joint_states`` of one cycle (every joint the broadcaster has, in its order)."""
        self._pub.publish(self._encode(JointSample(stamp_ns, tuple(names), q, qd, effort)))


class Touch:
    """A Touch driver's topics: position-only joint states, Joy buttons, a gated force input.

    Args:
        node: the driver's node.
        ns: the driver's namespace (``/touch``).
        received: told of every force taken (the state it answers, the force in driver axes).
    """

    JOINTS = ("waist", "shoulder", "elbow", "yaw", "pitch", "roll")
    WHITE = 1  # the button that gates the force (buttons[1])

    def __init__(self, node: Any, ns: str, received: Received) -> None:
        self._encode = codecs.JOINT_STATE.encoder("")
        self._pub = node.create_publisher(
            rclpy_type("sensor_msgs/msg/JointState"), f"{ns}/joint_states", SENSOR_DATA
        )
        self._buttons_pub = node.create_publisher(
            rclpy_type("sensor_msgs/msg/Joy"), f"{ns}/buttons", SYSTEM_DEFAULT
        )
        self.inbox = Inbox(
            node, "geometry_msgs/msg/WrenchStamped", f"{ns}/force_feedback", SYSTEM_DEFAULT
        )
        self._received = received
        self.force = (0.0, 0.0, 0.0)  # the newest force taken (driver axes)
        self.buttons = [0, 0]
        #: the white button's newest press went out to a matched reader (the bridge could hear
        #: it: the Joy is volatile, a press before the match is lost)
        self.press_heard = False
        self._joy(0)  # rosbags builds a type's serializer at its first use: 12 ms, not mid-run
        self.nonfinite_dropped = 0

    def receive(self, before_ns: int | None) -> None:
        """Take the forces DDS received before ``before_ns`` (system ns; None: all)."""
        for received_ns, data in self.inbox.take(before_ns):
            v = codecs.WRENCH.decode(data)
            if not all(map(math.isfinite, v.vector)):
                self.nonfinite_dropped += 1
                continue
            self.force = tuple(v.vector)  # type: ignore[assignment]  # three floats
            self._received(v.stamp_ns, self.force, received_ns)

    def press(self, held: bool, stamp_ns: int) -> None:
        """The white button held or let go: the Joy goes out on the change."""
        new = 1 if held else 0
        if new != self.buttons[self.WHITE]:
            self.buttons[self.WHITE] = new
            self.press_heard = bool(new) and self._buttons_pub.get_subscription_count() > 0
            self._buttons_pub.publish(self._joy(stamp_ns))

    def _joy(self, stamp_ns: int) -> bytes:
        """The buttons as a serialized ``sensor_msgs/Joy`` stamped ``stamp_ns``."""
        sec, nsec = divmod(stamp_ns, 1_000_000_000)
        msg = wire.TYPESTORE.types["sensor_msgs/msg/Joy"](
            header=wire.Header(stamp=wire.Time(sec=sec, nanosec=nsec), frame_id=""),
            axes=np.zeros(0, dtype=np.float32),
            buttons=np.array(self.buttons, dtype=np.int32),
        )
        return wire.encode(msg)

    @property
    def gated_force(self) -> tuple[float, float, float]:
        """The force the device applies now (driver axes): zero unless the white button is
        held."""
        return self.force if self.buttons[self.WHITE] else (0.0, 0.0, 0.0)

    def publish(self, stamp_ns: int, q3: Sequence[float]) -> None:
        """``joint_states``: positions only, the gimbal at rest."""
        q = (float(q3[0]), float(q3[1]), float(q3[2]), 0.0, 0.0, 0.0)
        self._pub.publish(self._encode(JointSample(stamp_ns, self.JOINTS, q, (), ())))
