"""Record (monotonic time, stamp, effort) of every joint_states into a CSV until SIGINT.

Run by test_lab_network.py inside a network namespace, next to the device.
"""

from __future__ import annotations

import signal
import sys
import time

import rclpy
from rclpy.qos import QoSProfile, ReliabilityPolicy

from haptic_msgs_py.ros.raw import raw_subscription
from haptic_msgs_py.stamps import stamp_ns
from haptic_msgs_py.topics import JOINT_STATES, SESSION_TOPICS


def main(path: str) -> int:
    rclpy.init(args=[], signal_handler_options=rclpy.signals.SignalHandlerOptions.NO)
    node = rclpy.create_node("netns_monitor")
    stop: list[int] = []
    signal.signal(signal.SIGINT, lambda *_: stop.append(1))
    signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
    rows: list[str] = []

    def on_js(msg) -> None:
        rows.append(f"{time.monotonic():.6f},{stamp_ns(msg)},{float(msg.effort[0])!r}\n")

    qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.BEST_EFFORT)
    raw_subscription(node, SESSION_TOPICS[JOINT_STATES], JOINT_STATES, on_js, qos)
    with open(path, "w", encoding="utf-8") as fh:
        while not stop:
            rclpy.spin_once(node, timeout_sec=0.05)
            if len(rows) > 200:
                fh.writelines(rows)
                fh.flush()
                rows.clear()
        fh.writelines(rows)
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
