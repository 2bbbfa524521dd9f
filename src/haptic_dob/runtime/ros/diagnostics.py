"""``/diagnostics`` from every node: one DiagnosticStatus per node, once a second.

A node gives a callback returning (level, message, values); this helper counts its cycles for the
loop rate and publishes ``diagnostic_msgs/DiagnosticArray`` the way ROS tools (rqt_robot_monitor,
the aggregator) expect.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from typing import Any

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from rclpy.node import Node

from haptic_dob.runtime.status import Status
from haptic_msgs_py.topics import DIAGNOSTICS

OK, WARN, ERROR = DiagnosticStatus.OK, DiagnosticStatus.WARN, DiagnosticStatus.ERROR
Report = tuple[bytes, str, Mapping[str, Any]]


def report_of(status: Status) -> Report:
    """A ROS-free ``Status`` as a report (WARN or OK)."""
    return (WARN if status.warning else OK), status.message, status.values


class Diagnostics:
    """Publishes the node's status every ``period_s``; ``tick()`` counts one loop cycle."""

    def __init__(self, node: Node, report: Callable[[], Report], period_s: float = 1.0) -> None:
        self.node = node
        self._report = report
        self.cycles = 0
        self._last_cycles = 0
        self._last_t = time.monotonic()
        self.rate_hz = 0.0
        self._pub = node.create_publisher(DiagnosticArray, DIAGNOSTICS, 10)
        self._status = DiagnosticStatus(
            name=f"{node.get_namespace().rstrip('/')}/{node.get_name()}",
            hardware_id=node.get_fully_qualified_name(),
        )
        node.create_timer(period_s, self.publish)

    def tick(self) -> None:
        """One loop cycle done."""
        self.cycles += 1

    def publish(self) -> None:
        """Compute the rate and publish the node's status now."""
        now = time.monotonic()
        self.rate_hz = (self.cycles - self._last_cycles) / max(now - self._last_t, 1e-9)
        self._last_cycles, self._last_t = self.cycles, now
        level, message, values = self._report()
        st = self._status
        st.level, st.message = level, message
        st.values = [KeyValue(key="loop_rate_hz", value=f"{self.rate_hz:.1f}")] + [
            KeyValue(key=k, value=str(v)) for k, v in values.items()
        ]
        msg = DiagnosticArray(status=[st])
        msg.header.stamp = self.node.get_clock().now().to_msg()
        self._pub.publish(msg)
