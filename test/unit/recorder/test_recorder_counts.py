"""The recorder's accounting: received and written per topic, missing stamps, progress."""

from __future__ import annotations

import json
from pathlib import Path

from haptic_dob.recorder.counts import FLOWING_NS, RecordingCounts, TopicCount

MS = 1_000_000


def test_gaps_first_and_newest_stamps() -> None:
    c = TopicCount("/ee_pose", "geometry_msgs/msg/PoseStamped")
    for stamp in (5 * MS, 6 * MS, 9 * MS, 7 * MS, 2 * MS, 9 * MS):  # 7, 8 missing; 2 late
        c.wrote(stamp, MS)
    assert (c.written, c.gaps, c.first_ns, c.newest_ns) == (6, 2, 2 * MS, 9 * MS)
    # system-clock stamps: each up to a period after its grid point (10, 11, 12 ...)
    c.wrote(int(10.9 * MS), MS)  # late tick: none missing
    c.wrote(int(11.0 * MS), MS)
    c.wrote(int(12.95 * MS), MS)  # 1.95 periods after the last: a late tick, none missing
    assert c.wrote(int(15.1 * MS), MS) == 1  # 2.15 periods: grid point 14 was missed
    assert (c.gaps, c.newest_ns) == (3, int(15.1 * MS))
    assert c.gap_line(1) == ("/ee_pose: 1 stamp(s) missing before 15100000 ns (3 in all so far)")
    assert c.wrote(16 * MS, MS) == 0
    c.wrote(None, MS)  # an unstamped message is only counted
    assert (c.written, c.gaps) == (12, 3)
    c.received = 12
    assert c.log_line() == "/ee_pose: received 12, written 12, 3 stamp(s) missing"
    assert TopicCount("/x", "t", 3, 3).log_line() == "/x: received 3, written 3"


def test_progress_is_the_slowest_flowing_topic() -> None:
    counts = RecordingCounts()
    pose = counts.add_topic("/ee_pose", "geometry_msgs/msg/PoseStamped")
    cmd = counts.add_topic("/effort_command", "std_msgs/msg/Float64MultiArray")
    events = counts.add_topic("/parameter_events", "rcl_interfaces/msg/ParameterEvent")
    assert counts.progress_ns() == 0  # nothing written yet
    events.wrote(None, MS)
    assert counts.progress_ns() == 0  # unstamped topics never count
    pose.wrote(10 * MS, MS)
    assert counts.progress_ns() == 10 * MS
    cmd.wrote(8 * MS, MS)
    assert counts.progress_ns() == 8 * MS  # the slowest
    pose.wrote(8 * MS + FLOWING_NS, MS)
    assert counts.progress_ns() == 8 * MS  # still flowing: exactly FLOWING_NS behind
    pose.wrote(8 * MS + FLOWING_NS + 1, MS)
    assert counts.progress_ns() == 8 * MS + FLOWING_NS + 1  # the command stopped


def test_snapshots_json_and_table() -> None:
    counts = RecordingCounts()
    pose = counts.add_topic("/ee_pose", "geometry_msgs/msg/PoseStamped")
    events = counts.add_topic("/parameter_events", "rcl_interfaces/msg/ParameterEvent")
    pose.received = 3
    for k in (0, 1, 3):
        pose.wrote(k * MS, MS)
    events.received = 2
    events.wrote(None, MS)
    events.wrote(None, MS)
    counts.snapshot_written()
    assert (counts.snapshots, events.written) == (1, 3)  # snapshots go beside the live events
    report = counts.to_json()
    assert report == {
        "topics": {
            "/ee_pose": {
                "type": "geometry_msgs/msg/PoseStamped",
                "received": 3,
                "written": 3,
                "gaps": 1,
                "first_stamp_ns": 0,
                "last_stamp_ns": 3 * MS,
            },
            "/parameter_events": {
                "type": "rcl_interfaces/msg/ParameterEvent",
                "received": 2,
                "written": 3,
                "gaps": 0,
                "first_stamp_ns": None,
                "last_stamp_ns": None,
            },
        },
        "parameter_snapshots": 1,
    }
    assert json.loads(json.dumps(report)) == report
    lines = counts.table(Path("out/bag"), "mcap").splitlines()
    assert lines[0].split() == ["topic", "type", "received", "written", "gaps", "stamps", "(s)"]
    assert lines[1].split() == [
        "/ee_pose",
        "geometry_msgs/msg/PoseStamped",
        "3",
        "3",
        "1",
        "0.000-0.003",
    ]
    assert lines[2].split()[-1] == "-"
    assert lines[3:] == ["parameter snapshots written: 1", "bag: out/bag (mcap)"]
