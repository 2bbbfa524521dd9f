"""The bag being recorded: each message's bytes written as they came, counted per topic.

Bag (log) time, ``log_time``:

- ``session`` (the default): the session's own time, as ``ros2 bag record --use-sim-time`` logs
  it. A message of the loop's topics is logged at its own stamp (the sample it belongs to: the
  device's ``k * T``, also on ``/clock``), anything else (parameter events, the snapshots,
  other topics, an unlabelled command) at the newest session time received so far: the newest
  loop stamp, or ``/clock`` (``observe_clock``) where no loop topic is recorded; 0 before the
  first. ``ros2 bag play --clock`` of such a bag then publishes ``/clock`` on the samples' time
  base, and a lockstep run gives the same log times every time.
- ``receive``: the wall-clock receive time (ns), as ``ros2 bag record`` without it (a graph
  whose stamps are the system clock).

Parameter snapshots go on ``/parameter_events`` beside the live events. At least once a second
(monotonic clock) what was written goes into complete records on disk, so a killed recorder
loses at most its last second (``haptic-record --recover``). Closing writes the counts into the
bag's metadata (custom data ``haptic_dob.recorder``) so the bag is readable and says what the
recorder received and wrote.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from haptic_dob.bag.write import make_durable, open_writer, parameter_event
from haptic_dob.recorder.counts import RecordingCounts
from haptic_dob.recorder.settings import LOG_TIMES
from haptic_dob.recorder.topics import PARAMETER_EVENT_TYPE, stamp_reader
from haptic_msgs_py.topics import PARAMETER_EVENTS
from haptic_msgs_py.wire import TYPESTORE

METADATA_KEY = "haptic_dob.recorder"  # custom data of the bag's metadata: the counts (JSON)
DURABLE_EVERY_NS = 1_000_000_000  # complete records on disk at least this often (monotonic)


class Recording:
    """A new bag at ``path`` in ``storage``; the loop period (ns) counts missing stamps;
    ``log_time`` one of ``LOG_TIMES``.

    Raises ``ValueError`` saying why the bag cannot be created.
    """

    def __init__(self, path: Path, storage: str, period_ns: int, log_time: str = "session") -> None:
        from rosbags.rosbag2 import WriterError

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
        self._events: Any = None  # the /parameter_events connection, if recorded
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
        conn = self._writer.add_connection(topic, typename, typestore=TYPESTORE)
        if topic == PARAMETER_EVENTS and typename == PARAMETER_EVENT_TYPE:
            self._events = conn
        stamp_of = stamp_reader(topic, typename)
        own_stamp = loop and stamp_of is not None and self.log_time == "session"
        write = self._writer.write
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
            write(conn, t, data)
            count.wrote(stamp, period)
            self.keep_durable()

        return on_message

    def keep_durable(self) -> None:
        """Call often (each message, and a timer while none come): when the last time is
        ``DURABLE_EVERY_NS`` ago, everything written so far goes into complete records on disk
        (a kill -9 after that loses none of it; ``haptic-record --recover`` reads it back)."""
        t = time.monotonic_ns()
        if not self.closed and t - self._durable_ns >= DURABLE_EVERY_NS:
            make_durable(self._writer)
            self._durable_ns = t

    def write_snapshot(
        self, node: str, values: Mapping[str, Any], kinds: Mapping[str, int]
    ) -> None:
        """Write all parameters of ``node`` (``ParameterValue`` type codes ``kinds``) as one
        ``ParameterEvent`` with them in ``new_parameters``, stamped and logged at ``now_ns``."""
        if self.closed:
            return
        now = self.now_ns()
        data = parameter_event(node, values, now, snapshot=True, kinds=kinds)
        self._writer.write(self._events, now, data)
        self.counts.snapshot_written()

    def close(self) -> None:
        """Write the counts into the metadata and close the bag (idempotent)."""
        if self.closed:
            return
        self.closed = True
        self._writer.set_custom_data(METADATA_KEY, json.dumps(self.counts.to_json()))
        self._writer.close()
