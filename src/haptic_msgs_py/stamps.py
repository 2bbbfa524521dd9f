"""Stamps of the control cycle: sample k of a device at period T carries stamp ``k * T``.

Effort commands travel as ``std_msgs/Float64MultiArray`` (as ros2_control's forward command
controllers take them), which has no header; the command of cycle k names its cycle in the label
of its single layout dimension, ``"effort@<stamp_ns>"``, followed by ``"#<token>"`` when its
sender carries a command token (the device end takes commands from another process only with the
session's token: ``haptic_dob.core.command_authority``). Consumers that ignore the layout (a
forward command controller) still read the efforts; a command without the label counts as the
newest one.
"""

from __future__ import annotations

from typing import Any

NS_PER_S = 1_000_000_000
COMMAND_LABEL = "effort@"
TOKEN_MARK = "#"  # between a command label's stamp and its token


def stamp_ns(msg: Any) -> int:
    """Nanoseconds of ``msg.header.stamp`` (works for rclpy and rosbags messages)."""
    st = msg.header.stamp
    return int(st.sec) * NS_PER_S + int(st.nanosec)


def period_ns(rate_hz: float) -> int:
    """Control period of ``rate_hz`` in integer nanoseconds."""
    return round(NS_PER_S / rate_hz)


def command_label(stamp: int, token: str = "") -> str:
    """The layout label that ties an effort command to its cycle's stamp (ns), and to its
    sender's command token when it has one."""
    if token:
        return f"{COMMAND_LABEL}{stamp}{TOKEN_MARK}{token}"
    return f"{COMMAND_LABEL}{stamp}"


def command_parts(label: str) -> tuple[int | None, str]:
    """(stamp in ns or None, token or '') named by a command's layout label."""
    if not label.startswith(COMMAND_LABEL):
        return None, ""
    stamp, _, token = label[len(COMMAND_LABEL) :].partition(TOKEN_MARK)
    try:
        return int(stamp), token
    except ValueError:
        return None, token


def command_stamp(label: str) -> int | None:
    """The stamp (ns) named by a command's layout label, None if it names none."""
    return command_parts(label)[0]
