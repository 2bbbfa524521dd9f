"""The bag being recorded: each message's bytes written as they came, counted per topic.

Bag time is the receive time (wall clock, ns); the analysis times samples by their stamps.
Parameter snapshots go on ``/parameter_events`` beside the live events. At least once a second
what was written goes into complete records on disk, so a killed recorder loses at most its
last second (``haptic-record --recover``). Closing writes the counts into the bag's metadata
(custom data ``haptic_dob.recorder``) so the bag is readable and says what the recorder received
and wrote.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from haptic_dob.bag.write import make_durable, open_writer, parameter_event
from haptic_dob.recorder.counts import RecordingCounts
from haptic_dob.recorder.topics import PARAMETER_EVENT_TYPE, stamp_reader
from haptic_msgs_py.topics import PARAMETER_EVENTS
from haptic_msgs_py.wire import TYPESTORE

METADATA_KEY = "haptic_dob.recorder"  # custom data of the bag's metadata: the counts (JSON)
DURABLE_EVERY_NS = 1_000_000_000  # complete records on disk at least this often (receive time)


class Recording:
    """A new bag at ``path`` in ``storage``; the loop period (ns) counts missing stamps.

    Raises ``ValueError`` saying why the bag cannot be created.
    """

    def __init__(self, path: Path, storage: str, period_ns: int) -> None:
        from rosbags.rosbag2 import WriterError

        try:
            self._writer = open_writer(path, storage)
        except (WriterError, OSError) as exc:
            text = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
            raise ValueError(f"cannot create the bag {path}: {text}") from None
        self.path = path
        self.storage = storage
        self.period_ns = period_ns
        self.counts = RecordingCounts()
        self.closed = False
        self._events: Any = None  # the /parameter_events connection, if recorded
        self._durable_ns = time.time_ns()  # when everything written was last made durable

    @property
    def records_parameter_events(self) -> bool:
        """Whether ``/parameter_events`` is recorded (and so can hold snapshots)."""
        return self._events is not None

    def add_topic(self, topic: str, typename: str) -> Callable[[bytes], None]:
        """Record ``topic`` (resolved name); returns what to call with each message's bytes."""
        count = self.counts.add_topic(topic, typename)
        conn = self._writer.add_connection(topic, typename, typestore=TYPESTORE)
        if topic == PARAMETER_EVENTS and typename == PARAMETER_EVENT_TYPE:
            self._events = conn
        stamp_of = stamp_reader(topic, typename)
        write = self._writer.write
        now = time.time_ns
        period = self.period_ns

        def on_message(data: bytes) -> None:
            count.received += 1
            if self.closed:
                return
            t = now()
            write(conn, t, data)
            count.wrote(None if stamp_of is None else stamp_of(data), period)
            if t - self._durable_ns >= DURABLE_EVERY_NS:
                self._make_durable(t)

        return on_message

    def keep_durable(self) -> None:
        """Call often (a timer): when the last time is ``DURABLE_EVERY_NS`` ago, everything
        written so far goes into complete records on disk, also while no message comes (a kill -9
        after that loses none of it; ``haptic-record --recover`` reads it back)."""
        t = time.time_ns()
        if not self.closed and t - self._durable_ns >= DURABLE_EVERY_NS:
            self._make_durable(t)

    def _make_durable(self, now_ns: int) -> None:
        make_durable(self._writer)
        self._durable_ns = now_ns

    def write_snapshot(
        self, node: str, values: Mapping[str, Any], kinds: Mapping[str, int]
    ) -> None:
        """Write all parameters of ``node`` (``ParameterValue`` type codes ``kinds``) as one
        ``ParameterEvent`` with them in ``new_parameters``, stamped now."""
        if self.closed:
            return
        now = time.time_ns()
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
