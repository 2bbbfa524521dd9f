"""What the loop's topics carry, as plain immutable values (SI units, stamps in integer ns).

Nodes of one process hand these to each other directly (``haptic_msgs_py.bus``); only readers in
other processes get them as ROS messages (``haptic_msgs_py.codecs`` converts, after the command).
Being immutable, a value can wait in the outgoing queue while its publisher moves on.

- ``StampedVector``: ee_pose (PoseStamped position), ee_twist (TwistStamped linear), the
  wrenches (WrenchStamped force);
- ``JointSample``: joint_states, effort_estimate (sensor_msgs/JointState);
- ``EffortCommand``: effort_command (std_msgs/Float64MultiArray, its cycle in the layout label
  ``effort@<stamp_ns>``, its sender's token after a ``#``);
- ``Stamp``: /clock (rosgraph_msgs/Clock).
"""

from __future__ import annotations

from typing import NamedTuple

Vec3 = tuple[float, float, float]


class StampedVector(NamedTuple):
    """A 3-vector of sample ``stamp_ns``: a position (m), a velocity (m/s) or a force (N)."""

    stamp_ns: int
    vector: Vec3


class JointSample(NamedTuple):
    """Joint values of sample ``stamp_ns``; ``velocity`` or ``effort`` may be empty."""

    stamp_ns: int
    name: tuple[str, ...]
    position: tuple[float, ...]
    velocity: tuple[float, ...]
    effort: tuple[float, ...]


class EffortCommand(NamedTuple):
    """Joint efforts (N or N m) in joint order, for cycle ``stamp_ns`` (None: the newest), with
    its sender's command token ('' when it has none)."""

    stamp_ns: int | None
    effort: tuple[float, ...]
    token: str = ""


class Stamp(NamedTuple):
    """A bare sample stamp (``/clock``)."""

    stamp_ns: int
