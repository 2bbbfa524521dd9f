"""The bag being recorded: each message's bytes written as they came, counted per topic.

Bag (log) time, ``log_time``: ``session`` (the default) is the session's own time, as
``ros2 bag record --use-sim-time`` logs it: a message of the loop's topics at its own stamp,
anything else (parameter events, the snapshots, other topics, an unlabelled command) at the
newest session time received so far (the newest loop stamp, or ``/clock`` through
``observe_clock`` where no loop topic is recorded; 0 before the first). ``receive`` is the
wall-clock receive time (ns), as ``ros2 bag record`` logs without it. Parameter snapshots go on
``/parameter_events``. What was written becomes complete records on disk whenever a topic's
newest stamp is ``DURABLE_NS`` of session time past the last time (and at least that often on
the monotonic clock), so a killed recorder loses at most that much of what it wrote. A topic's
connection is added at its first message (or at the close), with the QoS its publishers offer
then (``offered``). Closing writes the counts into the metadata (custom data
``haptic_dob.recorder``). Why: docs/recording-and-analysis.md, "Recording sessions".
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rosbags.rosbag2 import WriterError

from haptic_dob.bag.cdr import stamp_reader
from haptic_dob.bag.write import make_durable, open_writer, parameter_event
from haptic_dob.recorder.counts import RecordingCounts
from haptic_dob.recorder.settings import LOG_TIMES
from haptic_dob.recorder.topics import PARAMETER_EVENT_TYPE
from haptic_msgs_py.topics import PARAMETER_EVENTS
from haptic_msgs_py.wire import TYPESTORE

if TYPE_CHECKING:
    from rosbags.interfaces import Qos

METADATA_KEY = "haptic_dob.recorder"  # custom data of the bag's metadata: the counts (JSON)
DURABLE_NS = 1_000_000_000  # complete records on disk every this much session time (and wall)

OfferedQos = Callable[[str], Sequence["Qos"]]  # a topic -> the QoS its publishers offer
GapReport = Callable[[str], object]  # takes the line that says which stamps are missing


def no_report(line: str) -> None:
    """Say nothing (a recording outside a node)."""


def no_offers(topic: str) -> Sequence[Qos]:
    """No publisher known (a recording outside a ROS graph)."""
    return ()


class _LazyConnection:
    """A topic's bag connection, added when first asked for (``get``)."""

    def __init__(self, add: Callable[[], Any]) -> None:
        self._add = add
        self.conn: Any = None

    def get(self) -> Any:
        """The connection, added now if it was not yet."""
        if self.conn is None:
            self.conn = self._add()
        return self.conn


class Recording:
    """A new bag at ``path`` in ``storage``; the loop period (ns) counts missing stamps;
    ``log_time`` one of ``LOG_TIMES``; ``offered`` the QoS profiles a topic's publishers offer;
    ``on_gap`` is told at once when a stamped topic's message comes after missing stamps
    (``TopicCount.gap_line``), so a recorder killed later has still said what it never got.

    Raises ``ValueError`` saying why the bag cannot be created.
    """

    def __init__(
        self,
        path: Path,
        storage: str,
        period_ns: int,
        log_time: str = "session",
        offered: OfferedQos = no_offers,
        on_gap: GapReport = no_report,
    ) -> None:
        if log_time not in LOG_TIMES:
            raise ValueError(f"log_time must be one of {', '.join(LOG_TIMES)}, got {log_time!r}")
        try:
            self._writer = open_writer(path, storage)
        except (WriterError, OSError) as exc:
            text = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
            raise ValueError(f"cannot create the bag {path}: {text}") from None
        self.path = path
        self.storage = storage
        self.period_ns = period_ns
        self.log_time = log_time
        self.session_ns = 0  # the newest session time received (a loop stamp or /clock), ns
        self.counts = RecordingCounts()
        self.closed = False
        self._offered = offered
        self._on_gap = on_gap
        self._connections: list[_LazyConnection] = []
        self._events: _LazyConnection | None = None  # /parameter_events, if recorded
        self._durable_ns = time.monotonic_ns()  # when everything written was last made durable

    @property
    def records_parameter_events(self) -> bool:
        """Whether ``/parameter_events`` is recorded (and so can hold snapshots)."""
        return self._events is not None

    def now_ns(self) -> int:
        """The bag time of a message without a session stamp of its own, received now."""
        return self.session_ns if self.log_time == "session" else time.time_ns()

    def observe_clock(self, stamp_ns: int) -> None:
        """A ``/clock`` message: the session's time is at least ``stamp_ns``."""
        if stamp_ns > self.session_ns:
            self.session_ns = stamp_ns

    def add_topic(self, topic: str, typename: str, loop: bool = False) -> Callable[[bytes], None]:
        """Record ``topic`` (resolved name; ``loop``: one of the loop's topics, stamped on the
        session's time); returns what to call with each message's bytes."""
        count = self.counts.add_topic(topic, typename)
        writer, offered = self._writer, self._offered
        lazy = _LazyConnection(
            lambda: writer.add_connection(
                topic,
                typename,
                typestore=TYPESTORE,
                offered_qos_profiles=list(offered(topic)),
            )
        )
        self._connections.append(lazy)
        if topic == PARAMETER_EVENTS and typename == PARAMETER_EVENT_TYPE:
            self._events = lazy
        stamp_of = stamp_reader(topic, typename)
        own_stamp = loop and stamp_of is not None and self.log_time == "session"
        write = writer.write
        period = self.period_ns

        def on_message(data: bytes) -> None:
            count.received += 1
            if self.closed:
                return
            stamp = None if stamp_of is None else stamp_of(data)
            if own_stamp and stamp is not None:
                t = stamp
                if stamp > self.session_ns:
                    self.session_ns = stamp
            else:
                t = self.now_ns()
            write(lazy.conn or lazy.get(), t, data)
            missing = count.wrote(stamp, period)
            if missing:
                self._on_gap(count.gap_line(missing))
            newest = count.newest_ns
            durable = count.first_ns if count.durable_ns is None else count.durable_ns
            if newest is not None and durable is not None and newest - durable >= DURABLE_NS:
                self.make_durable()
            else:
                self.keep_durable()

        return on_message

    def make_durable(self) -> None:
        """Put everything written so far into complete records on disk (a kill -9 after that
        loses none of it; ``haptic-record --recover`` reads it back)."""
        if self.closed:
            return
        make_durable(self._writer)
        self._durable_ns = time.monotonic_ns()
        for c in self.counts.topics:
            c.durable_ns = c.newest_ns

    def keep_durable(self) -> None:
        """Call often (each message, and a timer while none come): ``make_durable`` when the
        last time is ``DURABLE_NS`` ago on the monotonic clock (for messages without a stamp;
        the stamped ones are made durable by their own time as they are written)."""
        if time.monotonic_ns() - self._durable_ns >= DURABLE_NS:
            self.make_durable()

    def write_snapshot(
        self, node: str, values: Mapping[str, Any], kinds: Mapping[str, int]
    ) -> None:
        """Write all parameters of ``node`` (``ParameterValue`` type codes ``kinds``) as one
        ``ParameterEvent`` with them in ``new_parameters``, stamped and logged at ``now_ns``."""
        if self.closed or self._events is None:
            return
        now = self.now_ns()
        data = parameter_event(node, values, now, snapshot=True, kinds=kinds)
        self._writer.write(self._events.get(), now, data)
        self.counts.snapshot_written()

    def close(self) -> None:
        """Write the counts into the metadata and close the bag (idempotent); a topic without
        a message is added with the QoS its publishers offer now."""
        if self.closed:
            return
        self.closed = True
        for lazy in self._connections:
            lazy.get()
        self._writer.set_custom_data(METADATA_KEY, json.dumps(self.counts.to_json()))
        self._writer.close()
