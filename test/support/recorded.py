"""Reading the bags the recorder wrote: stamps per topic, and its received/written counts."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import yaml

from haptic_dob.bag.cdr import command_label_stamp_ns, header_stamp_ns
from haptic_dob.bag.reader import open_bag


def _stamp(topic: str, data: bytes) -> int | None:
    """A loop message's stamp (header or effort@ label)."""
    read = command_label_stamp_ns if topic.endswith("effort_command") else header_stamp_ns
    return read(data)


def bag_stamps(path: Path) -> dict[str, np.ndarray]:
    """Per topic, the stamps of its messages in bag order (header or effort@ label)."""
    out: dict[str, list[int | None]] = {}
    with open_bag(path) as reader:
        for conn, _, data in reader.messages():
            if conn.topic != "/parameter_events":
                out.setdefault(conn.topic, []).append(_stamp(conn.topic, data))
    return {t: np.array(s, dtype=np.int64) for t, s in out.items()}


def assert_logged_on_session_time(path: Path) -> None:
    """The bag's log times are the session's (``log_time: session``): each loop message at its
    own stamp, every parameter event within the session's span, the bag starting at 0 (so
    ``ros2 bag play --clock`` publishes /clock on the samples' time base)."""
    last, events = 0, []
    with open_bag(path) as reader:
        for conn, t, data in reader.messages():
            if conn.topic == "/parameter_events":
                events.append(t)
                continue
            stamp = _stamp(conn.topic, data)
            assert t == stamp, (path, conn.topic, t, stamp)
            last = max(last, t)
    assert events and all(0 <= t <= last for t in events), (path, min(events), max(events), last)
    meta = yaml.safe_load((path / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert meta["starting_time"]["nanoseconds_since_epoch"] == 0
    assert meta["duration"]["nanoseconds"] == last


def recorder_report(path: Path) -> dict:
    """The counts the recorder wrote into the bag's metadata."""
    meta = yaml.safe_load((path / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    return json.loads(meta["custom_data"]["haptic_dob.recorder"])


def message_counts(path: Path) -> dict[str, int]:
    with open_bag(path) as reader:
        return {c.topic: c.msgcount for c in reader.connections}


def assert_received_written_in_bag(path: Path) -> dict:
    """received = written for every topic, written = what the bag holds (+ snapshots)."""
    report = recorder_report(path)
    counts = message_counts(path)
    for topic, c in report["topics"].items():
        extra = report["parameter_snapshots"] if topic == "/parameter_events" else 0
        assert c["written"] == c["received"] + extra, (path, topic, c)
        assert counts[topic] == c["written"], (path, topic)
    return report
