"""recorder_node: record a session into a rosbag2 (MCAP or sqlite3) with the ``rosbags`` writer.

- Subscribes raw (serialized CDR) to each topic and writes the bytes as they are: reliable,
  transient-local ``qos.RECORD`` for the loop's topics (a late match still gets the publishers'
  last 2000 samples), the parameter-events profile for ``/parameter_events``, reliable volatile
  for other topics. Bag time is the receive time (wall clock, ns); the analysis times samples by
  their header stamps.
- Writes a snapshot of every node in its namespace (``list_parameters`` + ``get_parameters``;
  a node silent for ``snapshot_timeout_s`` is warned about and still asked) as a
  ``rcl_interfaces/msg/ParameterEvent`` with all parameters in ``new_parameters``, on
  ``/parameter_events`` beside the live events, so the bag says which stiffness, mode and gains
  were active at every moment. Nodes that start later are snapshot when they appear.
- Publishes ``recorder/progress`` (``std_msgs/Header``: the stamp, and this recorder's name in
  ``frame_id`` so a device can follow the slowest of several; reliable, transient local) at
  ``progress_rate_hz``: the newest stamp written, minimum over the stamped topics that are
  flowing (header stamps; the effort command's ``effort@<stamp>`` label). A lockstep device
  holds the loop while that lags, so a recorded lockstep run loses nothing. The report is held
  where a node appeared until its parameters came (at most ``snapshot_timeout_s``), so a short
  lockstep run cannot end before the bag knows the session's parameters.
- On SIGINT/SIGTERM (or after ``duration_s``) it takes what is still queued (at most
  ``drain_timeout_s``, until nothing arrives for 0.1 s), then closes the bag so it is readable,
  and reports per topic what it received, wrote and which stamps are missing (gaps).
"""

from __future__ import annotations

import json
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rclpy.context import Context
from rclpy.qos import (
    DurabilityPolicy,
    HistoryPolicy,
    QoSProfile,
    ReliabilityPolicy,
    qos_profile_parameter_events,
)

from haptic_dob.bag.cdr import command_label_stamp_ns, header_stamp_ns
from haptic_dob.bag.write import parameter_event
from haptic_dob.nodes.common import main_for
from haptic_dob.runtime.params import ParamSpec
from haptic_dob.runtime.ros.params import ParameterTable
from haptic_dob.runtime.ros.spin import LoopNode
from haptic_msgs_py.ros import qos
from haptic_msgs_py.ros.raw import rclpy_type
from haptic_msgs_py.stamps import NS_PER_S, period_ns
from haptic_msgs_py.topics import (
    EFFORT_COMMAND,
    PARAMETER_EVENTS,
    RECORDER_PROGRESS,
    SESSION_TOPICS,
)
from haptic_msgs_py.wire import TYPESTORE

PARAMETER_EVENT_TYPE = "rcl_interfaces/msg/ParameterEvent"
DEFAULT_TOPICS = [*SESSION_TOPICS, PARAMETER_EVENTS]
STORAGES = ("mcap", "sqlite3")
PROGRESS_QOS = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=1,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
)
OTHER_QOS = QoSProfile(
    history=HistoryPolicy.KEEP_LAST, depth=qos.LOOP_HISTORY, reliability=ReliabilityPolicy.RELIABLE
)
DISCOVERY_S = 0.1  # how often new nodes and pending snapshots are looked at
FLOWING_NS = 1_000_000_000  # a topic this far behind the newest one has stopped (ns)
QUIET_S = 0.1  # the shutdown drain ends after this long without a message


def recorder_specs() -> list[ParamSpec]:
    """Every parameter of the recorder node (all fixed at start)."""
    return [
        ParamSpec(
            "output",
            "",
            "bag directory to create ('' = haptic_<date>_<time> in the working directory)",
            read_only=True,
        ),
        ParamSpec("storage", "mcap", "bag storage", choices=STORAGES, read_only=True),
        ParamSpec(
            "topics",
            list(DEFAULT_TOPICS),
            "topics to record: session topics and /parameter_events by name, others as "
            "NAME:pkg/msg/Type",
            read_only=True,
        ),
        ParamSpec(
            "duration_s",
            0.0,
            "stop after this long (wall clock); 0 = until stopped",
            "s",
            0.0,
            1e7,
            read_only=True,
        ),
        ParamSpec(
            "rate_hz", 1000.0, "sample rate of the loop (to count missing stamps)", "Hz", 1.0, 1e5
        ),
        ParamSpec(
            "progress_rate_hz",
            50.0,
            "rate of recorder/progress (lockstep back-pressure)",
            "Hz",
            20.0,
            1000.0,
            read_only=True,
        ),
        ParamSpec(
            "snapshot_timeout_s",
            2.0,
            "warn when a node has not answered the parameter snapshot after this long (it is "
            "still asked)",
            "s",
            0.1,
            60.0,
            read_only=True,
        ),
        ParamSpec(
            "drain_timeout_s",
            2.0,
            "at shutdown: take queued messages for at most this long",
            "s",
            0.0,
            60.0,
            read_only=True,
        ),
    ]


def parse_topics(entries: Sequence[str]) -> list[tuple[str, str]]:
    """(name, type) of each ``topics`` entry; ``ValueError`` naming a bad or unknown one."""
    out: list[tuple[str, str]] = []
    for entry in entries:
        name, sep, typename = entry.partition(":")
        name = name.strip()
        if not name:
            raise ValueError(f"topics: empty topic name in {entry!r}")
        if not sep:
            if name == PARAMETER_EVENTS:
                typename = PARAMETER_EVENT_TYPE
            elif name.lstrip("/") in SESSION_TOPICS:
                typename = SESSION_TOPICS[name.lstrip("/")]
            else:
                raise ValueError(
                    f"topics: {name!r} is not a session topic; give its type as "
                    f"{name}:pkg/msg/Type (session topics: {', '.join(SESSION_TOPICS)})"
                )
        typename = typename.strip()
        if typename not in TYPESTORE.fielddefs:
            raise ValueError(f"topics: unknown message type {typename!r} for {name}")
        if any(n == name for n, _ in out):
            raise ValueError(f"topics: {name} is listed twice")
        out.append((name, typename))
    if not out:
        raise ValueError("topics: nothing to record")
    return out


def stamp_reader(topic: str, typename: str) -> Callable[[bytes], int | None] | None:
    """How to read the stamp of a message of this topic from its bytes (None: unstamped)."""
    fields = TYPESTORE.fielddefs[typename][1]
    if fields and fields[0][0] == "header":
        return header_stamp_ns
    if topic.rsplit("/", 1)[-1] == EFFORT_COMMAND:
        return command_label_stamp_ns
    return None


@dataclass
class TopicCount:
    """What the recorder did with one topic."""

    topic: str
    typename: str
    received: int = 0
    written: int = 0
    gaps: int = 0  # stamps missing between consecutive written messages (stamped topics)
    first_ns: int | None = None  # smallest stamp written
    newest_ns: int | None = None  # largest stamp written


@dataclass
class _Snapshot:
    """A node whose parameters are being fetched."""

    node: str
    started: float
    list_client: Any
    get_client: Any
    progress_ns: int = 0  # the recorder's progress when the node appeared
    future: Any = None
    names: list[str] | None = None
    warned: bool = False


class RecorderNode(LoopNode):
    """Records topics into a bag; reports its progress for lockstep back-pressure."""

    def __init__(
        self, context: Context | None = None, name: str = "recorder_node", **kwargs: Any
    ) -> None:
        super().__init__(name, context=context, **kwargs)
        self.params = ParameterTable(self, recorder_specs())
        v = self.params.values
        topics = parse_topics(v["topics"])
        classes = {}
        for _, typename in topics:
            try:
                classes[typename] = rclpy_type(typename)
            except (ImportError, AttributeError, ValueError):
                raise ValueError(f"topics: {typename} is not an installed message type") from None
        out = v["output"] or time.strftime("haptic_%Y%m%d_%H%M%S")
        self.path = Path(out)
        self.storage = v["storage"]
        self._period = period_ns(v["rate_hz"])
        self._closed = False
        self._writer = self._open_writer()
        self._t_end = time.monotonic() + v["duration_s"] if v["duration_s"] > 0 else None
        self.counts: list[TopicCount] = []
        self._subs: list[tuple[Any, Callable[[bytes], None]]] = []
        self._stamped: list[tuple[Any, TopicCount]] = []
        self._events_conn: Any = None
        for topic, typename in topics:
            resolved = self.resolve_topic_name(topic)
            count = TopicCount(resolved, typename)
            self.counts.append(count)
            conn = self._writer.add_connection(resolved, typename, typestore=TYPESTORE)
            if resolved == PARAMETER_EVENTS and typename == PARAMETER_EVENT_TYPE:
                profile = qos_profile_parameter_events
                self._events_conn = conn
            elif topic.lstrip("/") in SESSION_TOPICS:
                profile = qos.RECORD
            else:
                profile = OTHER_QOS
            stamp_of = stamp_reader(resolved, typename)
            cb = self._callback(conn, count, stamp_of)
            sub = self.create_subscription(classes[typename], topic, cb, profile, raw=True)
            self._subs.append((sub, cb))
            if stamp_of is not None:
                self._stamped.append((sub, count))
        self.snapshots = 0
        self._known = {self.get_fully_qualified_name()}
        self._pending: list[_Snapshot] = []
        self._ticks = 0
        if self._events_conn is not None:
            self.create_timer(DISCOVERY_S, self._on_discovery)
        from std_msgs.msg import Header

        self._progress_msg = Header(frame_id=self.get_fully_qualified_name())
        self._progress = self.create_publisher(Header, RECORDER_PROGRESS, PROGRESS_QOS)
        self.create_timer(1.0 / v["progress_rate_hz"], self._publish_progress)
        self.get_logger().info(f"recording {len(topics)} topic(s) to {self.path} ({self.storage})")

    # --- the bag ---------------------------------------------------------------------------
    def _open_writer(self) -> Any:
        from rosbags.rosbag2 import StoragePlugin, Writer, WriterError

        if self.path.exists():
            raise ValueError(f"{self.path} exists already; the recorder never overwrites a bag")
        plugin = StoragePlugin.MCAP if self.storage == "mcap" else StoragePlugin.SQLITE3
        try:
            writer = Writer(self.path, version=9, storage_plugin=plugin)
            writer.open()
        except (WriterError, OSError) as exc:
            text = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
            raise ValueError(f"cannot create the bag {self.path}: {text}") from None
        return writer

    def _callback(
        self, conn: Any, count: TopicCount, stamp_of: Callable[[bytes], int | None] | None
    ) -> Callable[[bytes], None]:
        write = self._writer.write
        now = time.time_ns
        period = self._period

        def on_message(data: bytes) -> None:
            count.received += 1
            if self._closed:
                return
            write(conn, now(), data)
            count.written += 1
            if stamp_of is None:
                return
            stamp = stamp_of(data)
            if stamp is None:
                return
            newest = count.newest_ns
            if newest is None:
                count.first_ns = count.newest_ns = stamp
            elif stamp > newest:
                if stamp - newest > period + period // 2:
                    count.gaps += round((stamp - newest) / period) - 1
                count.newest_ns = stamp
            elif count.first_ns is not None and stamp < count.first_ns:
                count.first_ns = stamp

        return on_message

    def progress_ns(self) -> int:
        """Newest stamp written (ns), minimum over the stamped topics that are flowing.

        A topic counts while its newest stamp is within ``FLOWING_NS`` of the newest stamp of
        any topic: one that has stopped (its node died, or it publishes only on demand) must not
        hold a lockstep loop forever.
        """
        newest = [c.newest_ns for _, c in self._stamped if c.newest_ns is not None]
        if not newest:
            return 0
        top = max(newest)
        return min(n for n in newest if n >= top - FLOWING_NS)

    def reported_progress_ns(self) -> int:
        """``progress_ns``, held where a node appeared while its parameters are still asked for
        (at most ``snapshot_timeout_s``): a lockstep run waits for what the bag must know."""
        held = [s.progress_ns for s in self._pending if not s.warned]
        return min([self.progress_ns(), *held])

    def _publish_progress(self) -> None:
        if self._closed:
            return
        sec, nsec = divmod(self.reported_progress_ns(), NS_PER_S)
        self._progress_msg.stamp.sec, self._progress_msg.stamp.nanosec = sec, nsec
        self._progress.publish(self._progress_msg)

    # --- parameter snapshots ---------------------------------------------------------------
    def _on_discovery(self) -> None:
        from rcl_interfaces.srv import GetParameters, ListParameters

        self._ticks += 1
        now = time.monotonic()
        if self._ticks % 5 == 1:  # new nodes, twice a second
            ns = self.get_namespace()
            for name, space in self.get_node_names_and_namespaces():
                full = f"{space.rstrip('/')}/{name}"
                if space != ns or name.startswith("_") or full in self._known:
                    continue
                self._known.add(full)
                self._pending.append(
                    _Snapshot(
                        full,
                        now,
                        self.create_client(ListParameters, f"{full}/list_parameters"),
                        self.create_client(GetParameters, f"{full}/get_parameters"),
                        self.progress_ns(),
                    )
                )
        timeout = self.params.values["snapshot_timeout_s"]
        for snap in list(self._pending):
            if self._advance(snap):
                self._finish(snap)
            elif now - snap.started > timeout and not snap.warned:
                # keep asking: a loaded node answers late, and a client dropped under a pending
                # request makes the node's own executor fail to send its response
                snap.warned = True
                self.get_logger().warning(
                    f"no parameters from {snap.node} within {timeout:g} s yet; still asking "
                    "(until then the bag does not know them)"
                )

    def _advance(self, snap: _Snapshot) -> bool:
        """One step of fetching a node's parameters; True when done (written or failed)."""
        from rcl_interfaces.srv import GetParameters, ListParameters

        if snap.future is not None:
            if not snap.future.done():
                return False
            result, snap.future = snap.future.result(), None
            if result is None:
                return True
            if snap.names is not None:
                self._write_snapshot(snap.node, snap.names, list(result.values))
                return True
            snap.names = list(result.result.names)
        if snap.names is None:
            if snap.list_client.service_is_ready():
                snap.future = snap.list_client.call_async(ListParameters.Request(depth=0))
        elif snap.get_client.service_is_ready():
            snap.future = snap.get_client.call_async(GetParameters.Request(names=snap.names))
        return False

    def _write_snapshot(self, node: str, names: list[str], values: list[Any]) -> None:
        from rclpy.parameter import parameter_value_to_python

        if self._closed:
            return
        now = time.time_ns()
        data = parameter_event(
            node,
            {n: parameter_value_to_python(v) for n, v in zip(names, values, strict=True)},
            now,
            snapshot=True,
            kinds={n: v.type for n, v in zip(names, values, strict=True)},
        )
        self._writer.write(self._events_conn, now, data)
        self.snapshots += 1
        for c in self.counts:
            if c.topic == PARAMETER_EVENTS:
                c.written += 1

    def _finish(self, snap: _Snapshot) -> None:
        self._pending.remove(snap)
        self.destroy_client(snap.list_client)
        self.destroy_client(snap.get_client)

    # --- time and shutdown -----------------------------------------------------------------
    def next_wakeup(self) -> float | None:
        return self._t_end

    def on_wakeup(self, now: float) -> None:
        self.finished = True
        self._t_end = None

    def _drain(self) -> None:
        """Take what the middleware still holds for us (bounded by ``drain_timeout_s``)."""
        deadline = time.monotonic() + self.params.values["drain_timeout_s"]
        quiet_since = time.monotonic()
        while time.monotonic() < deadline:
            got = 0
            for sub, cb in self._subs:
                with sub.handle:
                    taken = sub.handle.take_message(sub.msg_type, sub.raw)
                if taken is not None:
                    cb(taken[0])
                    got += 1
            if got:
                quiet_since = time.monotonic()
            elif time.monotonic() - quiet_since >= QUIET_S:
                break
            else:
                time.sleep(0.005)

    def _finish_snapshots(self) -> None:
        """Wait (within ``drain_timeout_s``) for the snapshots still asked for: in a short run a
        loaded node may answer after the session ended; a snapshot declares values from the
        start, so a late one still labels the whole bag. Only when this node spins alone (in a
        composition the other nodes have shut down already)."""
        ex = self.executor
        if ex is None or len(ex.get_nodes()) != 1:
            return
        deadline = time.monotonic() + self.params.values["drain_timeout_s"]
        while self._pending and time.monotonic() < deadline:
            ex.spin_once(timeout_sec=0.02)
            for snap in list(self._pending):
                if self._advance(snap):
                    self._finish(snap)

    def close(self) -> None:
        """Drain, write the counts into the bag's metadata and close it (idempotent)."""
        if self._closed:
            return
        try:
            self._finish_snapshots()
            self._drain()
        except Exception as exc:  # the context may already be gone
            self.get_logger().warning(f"could not drain the queues: {exc}")
        for snap in self._pending:
            self.get_logger().warning(
                f"closing without the parameters of {snap.node}: it never answered"
            )
        self._closed = True
        self._writer.set_custom_data("haptic_dob.recorder", json.dumps(self.report()))
        self._writer.close()

    def report(self) -> dict[str, Any]:
        """Counts per topic and the number of parameter snapshots (JSON-ready)."""
        return {
            "topics": {
                c.topic: {
                    "type": c.typename,
                    "received": c.received,
                    "written": c.written,
                    "gaps": c.gaps,
                    "first_stamp_ns": c.first_ns,
                    "last_stamp_ns": c.newest_ns,
                }
                for c in self.counts
            },
            "parameter_snapshots": self.snapshots,
        }

    def on_shutdown(self) -> None:
        self.close()
        log = self.get_logger()
        for c in self.counts:
            log.info(
                f"{c.topic}: received {c.received}, written {c.written}"
                + (f", {c.gaps} stamp(s) missing" if c.gaps else "")
            )
        log.info(f"closed {self.path} ({self.snapshots} parameter snapshot(s))")


def summary_table(node: RecorderNode) -> str:
    """What the recorder received and wrote, one line per topic."""
    lines = [f"{'topic':<28} {'type':<34} {'received':>9} {'written':>9} {'gaps':>6}  stamps (s)"]
    for c in node.counts:
        span = (
            f"{c.first_ns / NS_PER_S:.3f}-{c.newest_ns / NS_PER_S:.3f}"
            if c.first_ns is not None and c.newest_ns is not None
            else "-"
        )
        lines.append(
            f"{c.topic:<28} {c.typename:<34} {c.received:>9} {c.written:>9} {c.gaps:>6}  {span}"
        )
    lines.append(f"parameter snapshots written: {node.snapshots}")
    lines.append(f"bag: {node.path} ({node.storage})")
    return "\n".join(lines)


def record(
    output: str,
    storage: str = "mcap",
    namespace: str = "",
    duration_s: float = 0.0,
    topics: Sequence[str] | None = None,
    node_name: str = "recorder_node",
    rate_hz: float = 1000.0,
) -> tuple[int, RecorderNode | None]:
    """Run a recorder until SIGINT/SIGTERM or ``duration_s``; (exit code, the node if created)."""
    from rclpy.parameter import Parameter

    from haptic_dob.runtime.ros.spin import run_nodes
    from haptic_msgs_py.ament import ensure_ament_prefix

    ensure_ament_prefix()
    overrides = [
        Parameter("output", value=output),
        Parameter("storage", value=storage),
        Parameter("duration_s", value=float(duration_s)),
        Parameter("rate_hz", value=float(rate_hz)),
    ]
    if topics is not None:
        overrides.append(Parameter("topics", value=list(topics)))
    made: list[RecorderNode] = []

    def make(ctx: Context) -> list[RecorderNode]:
        made.append(
            RecorderNode(
                context=ctx,
                name=node_name,
                namespace=namespace or None,
                parameter_overrides=overrides,
            )
        )
        return made

    code = run_nodes(make, ["haptic-record"])
    return code, (made[0] if made else None)


def main(args: list[str] | None = None) -> int:
    """``ros2 run haptic_dob recorder_node``."""
    return main_for(RecorderNode, args)


if __name__ == "__main__":
    sys.exit(main())
