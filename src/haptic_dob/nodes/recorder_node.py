"""recorder_node: record a session into a rosbag2 (MCAP or sqlite3) with the ``rosbags`` writer.

- Subscribes raw (serialized CDR) and writes the bytes as they are: reliable ``qos.RECORD`` for
  the loop's topics, the parameter-events profile for ``/parameter_events``, reliable volatile
  otherwise; bag time is the session's (``log_time``) or receive time. Stores each topic's
  offered QoS in the bag, as ``ros2 bag record`` does.
- Snapshots the parameters of every node in its ``namespaces`` (a ``ParameterEvent`` on
  ``/parameter_events``), nodes that start later when they appear.
- Publishes ``recorder/progress`` (``std_msgs/Header``: newest stamp written, its topic in
  ``frame_id``; volatile) at ``progress_rate_hz``: a lockstep device holds the loop while it lags.
- On SIGINT/SIGTERM (or after ``duration_s``) takes what is still queued (at most
  ``drain_timeout_s``), closes the bag readable and logs per topic what it received and wrote.

ROS-free parts: ``haptic_dob.recorder``; details: docs/recording-and-analysis.md.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Iterator
from typing import Any

from rcl_interfaces.srv import GetParameters, ListParameters
from rclpy._rclpy_pybind11 import InvalidHandle, RCLError
from rclpy.client import Client
from rclpy.context import Context
from rclpy.parameter import parameter_value_to_python
from rclpy.qos import (
    DurabilityPolicy,
    HistoryPolicy,
    QoSProfile,
    ReliabilityPolicy,
    qos_profile_parameter_events,
)
from rosbags.interfaces import Qos
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Header

from haptic_dob.bag.jazzy import offered_qos
from haptic_dob.nodes.common import main_for
from haptic_dob.nodes.recorder_events import publisher_events
from haptic_dob.recorder.drain import take_until_quiet
from haptic_dob.recorder.matching import ReaderMatch, reported_progress
from haptic_dob.recorder.publishers import PublisherWatch
from haptic_dob.recorder.recording import Recording
from haptic_dob.recorder.settings import new_bag_path, progress_topic, recorder_specs
from haptic_dob.recorder.snapshots import ParameterSnapshot, SnapshotTracker
from haptic_dob.recorder.topics import TopicKind, parse_topics
from haptic_dob.runtime.cpus import scheduling
from haptic_dob.runtime.ros.spin import LoopNode
from haptic_msgs_py.ros import qos
from haptic_msgs_py.ros.raw import rclpy_type
from haptic_msgs_py.stamps import NS_PER_S, period_ns
from haptic_msgs_py.topics import CLOCK

PROGRESS_QOS = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=10,  # a report lost on the way is repaired, not counted lost by a reliable reader
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.VOLATILE,
)
SUBSCRIPTION_QOS = {
    TopicKind.EVENTS: qos_profile_parameter_events,
    TopicKind.SESSION: qos.RECORD,
    TopicKind.OTHER: QoSProfile(
        history=HistoryPolicy.KEEP_LAST,
        depth=qos.LOOP_HISTORY,
        reliability=ReliabilityPolicy.RELIABLE,
    ),
}
DISCOVERY_S = 0.1  # how often new nodes and pending snapshots are looked at


class RecorderNode(LoopNode):
    """Records topics into a bag; reports its progress for lockstep back-pressure."""

    def __init__(
        self, context: Context | None = None, name: str = "recorder_node", **kwargs: Any
    ) -> None:
        super().__init__(name, specs=recorder_specs(), context=context, **kwargs)
        v = self.params.values
        topics = parse_topics(v["topics"])
        classes = {}
        for t in topics:
            try:
                classes[t.typename] = rclpy_type(t.typename)
            except (ImportError, AttributeError, ValueError):
                raise ValueError(f"topics: {t.typename} is not an installed message type") from None
        path, period = new_bag_path(v["output"]), period_ns(v["rate_hz"])
        self.recording = Recording(
            path, v["storage"], period, v["log_time"], self._offered_qos, self.log.warning
        )
        self._t_end = time.monotonic() + v["duration_s"] if v["duration_s"] > 0 else None
        self._subs: list[tuple[Any, Callable[[bytes], None]]] = []
        self.publisher_watches: list[PublisherWatch] = []  # per topic, in order
        kinds = [t.kind(self.resolve_topic_name(t.name)) for t in topics]
        for t, kind in zip(topics, kinds, strict=True):
            loop = kind is TopicKind.SESSION
            cb = self.recording.add_topic(self.resolve_topic_name(t.name), t.typename, loop)
            watch, events = publisher_events(self.recording.counts.topics[-1], self.log.warning)
            self.publisher_watches.append(watch)
            profile = SUBSCRIPTION_QOS[kind]
            sub = self.create_subscription(
                classes[t.typename], t.name, cb, profile, raw=True, event_callbacks=events
            )
            self._subs.append((sub, cb))
        if v["log_time"] == "session" and TopicKind.SESSION not in kinds:  # no loop stamps
            self.create_subscription(Clock, CLOCK, self._on_clock, qos.CLOCK)
        spaces = [n.rstrip("/") or "/" for n in v["namespaces"] if n] or [self.get_namespace()]
        self.snapshots: SnapshotTracker[Client] = SnapshotTracker(
            self.get_fully_qualified_name(),
            spaces,
            v["snapshot_timeout_s"],
            lambda: ListParameters.Request(depth=0),
            lambda names: GetParameters.Request(names=names),
        )
        self._ticks = 0
        if self.recording.records_parameter_events:
            self.create_timer(DISCOVERY_S, self._on_discovery)
        self._progress_msg = Header(frame_id=self.get_fully_qualified_name())
        self._progress = [
            self.create_publisher(Header, progress_topic(n), PROGRESS_QOS) for n in v["namespaces"]
        ]
        self.create_timer(1.0 / v["progress_rate_hz"], self._publish_progress)
        self.log.info(
            f"recording {len(topics)} topic(s) to {self.recording.path} "
            f"({self.recording.storage}), scheduling {scheduling()}"
        )

    def _offered_qos(self, topic: str) -> list[Qos]:
        """The QoS profiles the publishers of ``topic`` offer, as the graph reports them."""
        try:
            return [offered_qos(i.qos_profile) for i in self.get_publishers_info_by_topic(topic)]
        except (RCLError, InvalidHandle):  # the context is going away: the bag still closes
            return []

    # --- progress --------------------------------------------------------------------------
    def progress_ns(self) -> int:
        """Newest stamp written (ns), minimum over the stamped topics that are flowing."""
        return self.recording.counts.progress_ns()

    def reported_progress_ns(self) -> int:
        """``progress_ns``, held where a node appeared while its parameters are still asked for
        (at most ``snapshot_timeout_s``): a lockstep run waits for what the bag must know.
        Before the loop starts, ``PROGRESS_NOT_MATCHED_NS`` while a reader has not matched."""
        held = self.snapshots.held_ns(self.progress_ns())
        return reported_progress(held, self.recording.counts, self._reader_matches())

    def _reader_matches(self) -> Iterator[ReaderMatch]:
        for sub, _ in self._subs:
            yield ReaderMatch(
                sub.topic_name, sub.get_publisher_count(), self.count_publishers(sub.topic_name)
            )

    def _publish_progress(self) -> None:
        if self.recording.closed:
            return
        sec, nsec = divmod(self.reported_progress_ns(), NS_PER_S)
        self._progress_msg.stamp.sec, self._progress_msg.stamp.nanosec = sec, nsec
        for pub in self._progress:
            pub.publish(self._progress_msg)
        self.recording.keep_durable()  # while no message comes: once a second of wall time

    def _on_clock(self, msg: Clock) -> None:
        self.recording.observe_clock(msg.clock.sec * NS_PER_S + msg.clock.nanosec)

    # --- parameter snapshots ---------------------------------------------------------------
    def _on_discovery(self) -> None:
        self._ticks += 1
        now = time.monotonic()
        if self._ticks % 5 == 1:  # new nodes, twice a second
            for node in self.snapshots.appeared(self.get_node_names_and_namespaces()):
                self.snapshots.ask(
                    node,
                    now,
                    self.progress_ns(),
                    self.create_client(ListParameters, f"{node}/list_parameters"),
                    self.create_client(GetParameters, f"{node}/get_parameters"),
                )
        self._step_snapshots(now)
        timeout = self.snapshots.timeout_s
        for snap in self.snapshots.overdue(now):
            self.log.warning(
                f"no parameters from {snap.node} within {timeout:g} s yet; still asking "
                "(until then the bag does not know them)"
            )

    def _step_snapshots(self, now_s: float) -> None:
        """Ask each pending node one step further at monotonic ``now_s`` (s); write what came,
        drop the finished clients."""
        done = self.snapshots.step(now_s)
        for answer in done.answered:
            self._write_snapshot(answer)
        for snap in done.ended:
            self.destroy_client(snap.list_client)
            self.destroy_client(snap.get_client)

    def _write_snapshot(self, snap: ParameterSnapshot) -> None:
        pairs = list(zip(snap.names, snap.values, strict=True))
        self.recording.write_snapshot(
            snap.node,
            {n: parameter_value_to_python(v) for n, v in pairs},
            {n: v.type for n, v in pairs},
        )

    # --- time and shutdown -----------------------------------------------------------------
    def next_wakeup(self) -> float | None:
        return self._t_end

    def on_wakeup(self, now: float) -> None:
        self.finished = True
        self._t_end = None

    def _take_round(self) -> int:
        """Take one queued message of each topic, if any; how many were taken."""
        got = 0
        for sub, cb in self._subs:
            with sub.handle:
                taken = sub.handle.take_message(sub.msg_type, sub.raw)
            if taken is not None:
                cb(taken[0])
                got += 1
        return got

    def _finish_snapshots(self) -> None:
        """Wait (within ``drain_timeout_s``) for snapshots still asked for (a late one still
        labels the whole bag); only when this node spins alone, not in a composition."""
        ex = self.executor
        if ex is None or len(ex.get_nodes()) != 1:
            return
        deadline = time.monotonic() + self.params.values["drain_timeout_s"]
        while self.snapshots.pending and time.monotonic() < deadline:
            ex.spin_once(timeout_sec=0.02)
            self._step_snapshots(time.monotonic())

    def close(self) -> None:
        """Drain, write the counts into the bag's metadata and close it (idempotent)."""
        if self.recording.closed:
            return
        try:
            self._finish_snapshots()
            take_until_quiet(self._take_round, self.params.values["drain_timeout_s"])
        except Exception as exc:  # the context may already be gone
            self.log.warning(f"could not drain the queues: {exc}")
        for snap in self.snapshots.pending:
            self.log.warning(f"closing without the parameters of {snap.node}: it never answered")
        self.recording.close()

    def on_shutdown(self) -> None:
        self.close()
        log = self.log
        for c in self.recording.counts.topics:
            log.info(c.log_line())
        snapshots = self.recording.counts.snapshots
        log.info(f"closed {self.recording.path} ({snapshots} parameter snapshot(s))")


def main(args: list[str] | None = None) -> int:
    """``ros2 run haptic_dob recorder_node``."""
    return main_for(RecorderNode, args, recorder_specs())


if __name__ == "__main__":
    sys.exit(main())
