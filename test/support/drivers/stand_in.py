"""The loop's controller played by a test: answers the bridge's samples with chosen commands.

A node of the test's own (private context, its own thread) subscribes to the loop's
``joint_states`` in a namespace and answers each sample with ``effort_command`` labelled with
its stamp and the session's command token, the values ``answer(k)`` gives (None: no answer),
or sends whatever the test asks (``send``). It counts the samples it saw, so a test waits in
samples, never in milliseconds.
"""

from __future__ import annotations

import os
import threading
from collections.abc import Callable, Sequence
from typing import Any

from support.waits import wait_until

Answer = Callable[[int], Sequence[float] | None]


class LoopStandIn:
    """The loop of namespace ``ns`` as far as the bridge sees it: samples in, commands out."""

    def __init__(
        self,
        env: dict[str, str],
        ns: str,
        answer: Answer,
        token: str = "",
        name: str = "controller_node",
    ) -> None:
        import rclpy
        from rclpy.context import Context
        from rclpy.experimental import EventsExecutor

        from haptic_msgs_py import codecs
        from haptic_msgs_py.ros import qos
        from haptic_msgs_py.ros.raw import rclpy_type

        self._saved = {
            k: os.environ.get(k) for k in ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE")
        }
        os.environ["ROS_DOMAIN_ID"] = env["ROS_DOMAIN_ID"]
        os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = env["ROS_AUTOMATIC_DISCOVERY_RANGE"]
        self.context = Context()
        rclpy.init(context=self.context, args=[])
        self.node = rclpy.create_node(
            name, namespace=ns, context=self.context, start_parameter_services=False
        )
        self.answer = answer
        self.token = token  # the session's command token its commands carry (as a controller's)
        self._lock = threading.Lock()
        self.samples: list[Any] = []  # JointSample values, in arrival order
        self._decode = codecs.JOINT_STATE.decoder()
        self._encode = codecs.EFFORT.encoder("")
        self._pub = self.node.create_publisher(
            rclpy_type("std_msgs/msg/Float64MultiArray"), "effort_command", qos.LOOP
        )
        self._sub = self.node.create_subscription(
            rclpy_type("sensor_msgs/msg/JointState"),
            "joint_states",
            self._on,
            qos.LOOP_IN,
            raw=True,
        )
        self.executor = EventsExecutor(context=self.context)
        self.executor.add_node(self.node)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._spin, daemon=True)
        self._thread.start()

    def _spin(self) -> None:
        while not self._stop.is_set() and self.context.ok():
            self.executor.spin_once(timeout_sec=0.05)

    def _on(self, data: bytes) -> None:
        js = self._decode(data)
        with self._lock:
            self.samples.append(js)
            k = len(self.samples)
        values = self.answer(k)
        if values is not None:
            self.send(js.stamp_ns, values)

    def send(self, stamp_ns: int | None, values: Sequence[float]) -> None:
        """An ``effort_command`` for the sample stamped ``stamp_ns`` (None: unlabelled), with the
        stand-in's command token."""
        from haptic_msgs_py.values import EffortCommand

        self._pub.publish(self._encode(EffortCommand(stamp_ns, tuple(values), self.token)))

    def count(self) -> int:
        """Samples seen so far."""
        with self._lock:
            return len(self.samples)

    def newest_stamp(self) -> int:
        with self._lock:
            return int(self.samples[-1].stamp_ns)

    def wait_samples(self, n: int, timeout: float) -> bool:
        """Wait until ``n`` more samples than now arrived (False on timeout)."""
        target = self.count() + n
        return wait_until(lambda: self.count() >= target, timeout, poll_s=0.02)

    def matched(self) -> bool:
        return self._pub.get_subscription_count() >= 1 and self._sub.get_publisher_count() >= 1

    def close(self) -> None:
        import rclpy

        self._stop.set()
        self._thread.join(5)
        self.executor.shutdown()
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)
        for k, v in self._saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
