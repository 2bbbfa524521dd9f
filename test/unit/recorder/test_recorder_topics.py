"""What the recorder records: topics entries, subscription kinds, stamp readers, defaults."""

from __future__ import annotations

import pytest

from haptic_dob.bag.cdr import command_label_stamp_ns, header_stamp_ns, stamp_reader
from haptic_dob.recorder.settings import DEFAULT_TOPICS
from haptic_dob.recorder.topics import (
    PARAMETER_EVENT_TYPE,
    TopicEntry,
    TopicKind,
    parse_topics,
)
from haptic_msgs_py import wire
from haptic_msgs_py.stamps import command_label
from haptic_msgs_py.topics import EE_POSE, EFFORT_COMMAND, PARAMETER_EVENTS, SESSION_TOPICS


def test_topics_default_and_parsing() -> None:
    assert [*SESSION_TOPICS, PARAMETER_EVENTS] == DEFAULT_TOPICS
    assert len(parse_topics(DEFAULT_TOPICS)) == len(DEFAULT_TOPICS)
    assert parse_topics(["ee_pose", "/parameter_events", " /other : std_msgs/msg/String "]) == [
        TopicEntry("ee_pose", "geometry_msgs/msg/PoseStamped"),
        TopicEntry("/parameter_events", PARAMETER_EVENT_TYPE),
        TopicEntry("/other", "std_msgs/msg/String"),
    ]
    assert parse_topics(["/ee_pose"]) == [TopicEntry("/ee_pose", SESSION_TOPICS[EE_POSE])]


@pytest.mark.parametrize(
    ("entries", "message"),
    [
        (["odometry"], "'odometry' is not a session topic; give its type as odometry:pkg/msg/Type"),
        (["x:foo/msg/Bar"], "unknown message type 'foo/msg/Bar' for x"),
        (["ee_pose", "ee_pose"], "ee_pose is listed twice"),
        ([":std_msgs/msg/String"], "empty topic name in ':std_msgs/msg/String'"),
        ([], "nothing to record"),
    ],
)
def test_bad_entries_are_named(entries: list[str], message: str) -> None:
    with pytest.raises(ValueError, match=f"^topics: {message}"):
        parse_topics(entries)


def test_subscription_kinds() -> None:
    events = TopicEntry("/parameter_events", PARAMETER_EVENT_TYPE)
    assert events.kind("/parameter_events") is TopicKind.EVENTS
    string_events = TopicEntry("/parameter_events", "std_msgs/msg/String")
    assert string_events.kind("/parameter_events") is TopicKind.OTHER
    # a session topic by its name as given, wherever it resolves
    assert TopicEntry("ee_pose", SESSION_TOPICS[EE_POSE]).kind("/ns/ee_pose") is TopicKind.SESSION
    assert TopicEntry("/ee_pose", SESSION_TOPICS[EE_POSE]).kind("/ee_pose") is TopicKind.SESSION
    assert TopicEntry("/other", "std_msgs/msg/String").kind("/other") is TopicKind.OTHER


def test_stamps_are_read_from_the_bytes() -> None:
    pose = wire.pose_stamped("base_link")
    pose.header.stamp.sec, pose.header.stamp.nanosec = 12, 345_000_000
    read = stamp_reader("/ee_pose", SESSION_TOPICS[EE_POSE])
    assert read is header_stamp_ns
    assert read(wire.encode(pose)) == 12_345_000_000
    cmd = wire.float64_multi_array(command_label(7_000_000), [0.5])
    assert stamp_reader("/ns/effort_command", SESSION_TOPICS[EFFORT_COMMAND]) is (
        command_label_stamp_ns
    )
    assert command_label_stamp_ns(wire.encode(cmd)) == 7_000_000
    tokened = wire.float64_multi_array(command_label(7_000_000, "0123abcd"), [0.5])
    assert command_label_stamp_ns(wire.encode(tokened)) == 7_000_000  # a sender's token after it
    assert command_label_stamp_ns(wire.encode(wire.float64_multi_array("x", [0.5]))) is None
    assert stamp_reader("/parameter_events", PARAMETER_EVENT_TYPE) is None
    assert stamp_reader("/other", "std_msgs/msg/Float64MultiArray") is None
