"""The bag being recorded: raw bytes as they came, counts, snapshots, metadata, close."""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest
import yaml
from rosbags.rosbag2 import Reader

from haptic_dob.bag.write import parameter_event
from haptic_dob.recorder.recording import METADATA_KEY, Recording
from haptic_dob.recorder.settings import STORAGES
from haptic_dob.recorder.topics import PARAMETER_EVENT_TYPE
from haptic_msgs_py import wire
from haptic_msgs_py.stamps import command_label
from haptic_msgs_py.topics import EE_POSE, EFFORT_COMMAND, SESSION_TOPICS

MS = 1_000_000


def pose_bytes(stamp_ns: int) -> bytes:
    pose = wire.pose_stamped("base_link")
    pose.header.stamp.sec, pose.header.stamp.nanosec = divmod(stamp_ns, 1_000_000_000)
    return wire.encode(pose)


@pytest.mark.parametrize("storage", STORAGES)
def test_messages_are_written_as_they_came_and_counted(tmp_path: Path, storage: str) -> None:
    said: list[str] = []
    rec = Recording(tmp_path / "bag", storage, MS, on_gap=said.append)
    on_pose = rec.add_topic("/ee_pose", SESSION_TOPICS[EE_POSE])
    on_cmd = rec.add_topic("/effort_command", SESSION_TOPICS[EFFORT_COMMAND])
    assert not rec.records_parameter_events
    on_events = rec.add_topic("/parameter_events", PARAMETER_EVENT_TYPE)
    assert rec.records_parameter_events
    sent = [pose_bytes(k * MS) for k in (0, 1, 3)]
    for data in sent:
        on_pose(data)
    assert said == ["/ee_pose: 1 stamp(s) missing before 3000000 ns (1 in all so far)"]  # at once
    on_cmd(wire.encode(wire.float64_multi_array(command_label(2 * MS), [0.5])))
    rec.write_snapshot("/node", {"gain": 2.0, "ids": [1, 2]}, {"gain": 3, "ids": 7})
    rec.close()
    rec.close()  # idempotent
    on_pose(pose_bytes(4 * MS))  # after the close: received, not written
    on_events(b"")
    rec.write_snapshot("/late", {"x": 1.0}, {})  # nothing after the close
    pose_c, cmd_c, ev_c = rec.counts.topics
    assert (pose_c.received, pose_c.written, pose_c.gaps, pose_c.newest_ns) == (4, 3, 1, 3 * MS)
    assert (cmd_c.written, cmd_c.newest_ns) == (1, 2 * MS)
    assert (ev_c.received, ev_c.written, rec.counts.snapshots) == (1, 1, 1)
    with Reader(tmp_path / "bag") as reader:
        by_topic: dict[str, list[bytes]] = {}
        for conn, _, data in reader.messages():
            by_topic.setdefault(conn.topic, []).append(bytes(data))
        (event,) = [
            wire.TYPESTORE.deserialize_cdr(d, PARAMETER_EVENT_TYPE)
            for d in by_topic["/parameter_events"]
        ]
    assert by_topic["/ee_pose"] == sent  # the bytes as they came
    assert event.node == "/node" and not event.changed_parameters
    values = {p.name: p.value for p in event.new_parameters}
    assert (values["gain"].type, values["gain"].double_value) == (3, 2.0)
    assert (values["ids"].type, list(values["ids"].integer_array_value)) == (7, [1, 2])
    meta = yaml.safe_load((tmp_path / "bag" / "metadata.yaml").read_text())
    custom = meta["rosbag2_bagfile_information"]["custom_data"][METADATA_KEY]
    assert json.loads(custom)["topics"]["/ee_pose"]["written"] == 3


def test_a_bag_that_cannot_be_created_is_named(tmp_path: Path) -> None:
    (tmp_path / "bag").mkdir()
    with pytest.raises(ValueError, match=r"^cannot create the bag .*bag: .*exists already"):
        Recording(tmp_path / "bag", "mcap", MS)
    (tmp_path / "file").write_text("")
    with pytest.raises(ValueError, match=r"^cannot create the bag .*: Not a directory"):
        Recording(tmp_path / "file" / "bag", "sqlite3", MS)


def logged(path: Path) -> list[tuple[str, int, bytes]]:
    """(topic, log time, bytes) of every message, in the bag's (log time) order."""
    with Reader(path) as reader:
        return [(c.topic, t, bytes(d)) for c, t, d in reader.messages()]


@pytest.mark.parametrize("storage", STORAGES)
def test_session_log_time_is_the_stamp_or_the_newest_one(tmp_path: Path, storage: str) -> None:
    """``ros2 bag record --use-sim-time`` as the loop would have it: a loop message at its own
    stamp whatever order it came in, anything else at the newest session time received (0 before
    the first), a snapshot stamped and logged there too."""
    rec = Recording(tmp_path / "bag", storage, MS)
    on_pose = rec.add_topic("/ee_pose", SESSION_TOPICS[EE_POSE], loop=True)
    on_cmd = rec.add_topic("/effort_command", SESSION_TOPICS[EFFORT_COMMAND], loop=True)
    on_events = rec.add_topic("/parameter_events", PARAMETER_EVENT_TYPE)
    on_other = rec.add_topic("/other_pose", SESSION_TOPICS[EE_POSE])  # not the loop's: a wall stamp
    early = parameter_event("/device_node", {"seed": 0}, 1_767_225_600 * 10**9, snapshot=True)
    on_events(early)  # a declaration before the loop runs: the node's own (wall) clock
    rec.write_snapshot("/node", {"gain": 2.0}, {"gain": 3})
    on_pose(pose_bytes(3 * MS))
    on_cmd(wire.encode(wire.float64_multi_array(command_label(2 * MS), [0.5])))  # came later
    on_cmd(wire.encode(wire.float64_multi_array("", [0.1])))  # unlabelled: the newest time
    on_other(pose_bytes(1_767_225_600 * 10**9))
    rec.observe_clock(5 * MS)  # /clock ahead of what was recorded
    on_events(early)
    rec.close()
    got = [(topic, t) for topic, t, _ in logged(tmp_path / "bag")]
    assert sorted(got, key=lambda x: x[1]) == got  # read back in log-time order
    assert sorted(got) == sorted(
        [
            ("/parameter_events", 0),
            ("/parameter_events", 0),  # the snapshot
            ("/ee_pose", 3 * MS),
            ("/effort_command", 2 * MS),
            ("/effort_command", 3 * MS),
            ("/other_pose", 3 * MS),
            ("/parameter_events", 5 * MS),
        ]
    )
    events = [
        wire.TYPESTORE.deserialize_cdr(d, PARAMETER_EVENT_TYPE)
        for topic, _, d in logged(tmp_path / "bag")
        if topic == "/parameter_events"
    ]
    (snap,) = [e for e in events if e.node == "/node"]
    assert (snap.stamp.sec, snap.stamp.nanosec) == (0, 0)


def test_receive_log_time_is_the_wall_clock(tmp_path: Path) -> None:
    before = time.time_ns()
    rec = Recording(tmp_path / "bag", "mcap", MS, log_time="receive")
    on_pose = rec.add_topic("/ee_pose", SESSION_TOPICS[EE_POSE], loop=True)
    rec.add_topic("/parameter_events", PARAMETER_EVENT_TYPE)
    on_pose(pose_bytes(3 * MS))
    rec.write_snapshot("/node", {"gain": 2.0}, {"gain": 3})
    rec.close()
    after = time.time_ns()
    times = [t for _, t, _ in logged(tmp_path / "bag")]
    assert len(times) == 2 and all(before <= t <= after for t in times)
    with pytest.raises(ValueError, match="log_time must be one of session, receive"):
        Recording(tmp_path / "other", "mcap", MS, log_time="wall")


def test_the_analysis_splits_a_session_logged_bag_where_the_changes_took_effect(
    tmp_path: Path,
) -> None:
    """Log times on the session's time keep the analysis right: a change a loop node stamped
    with its sample splits there however late it came; one stamped with a wall clock (a node
    of another graph) splits at the newest sample received before it."""
    from haptic_dob.bag.analyze import analyze_bag
    from haptic_dob.bag.write import vector_template
    from support.bagdata import msd_record, session_params

    x, force, v = msd_record(12.0, 1000.0, 0.5, 2.0, 800.0)
    rec = Recording(tmp_path / "bag", "mcap", MS)
    on = {
        t: rec.add_topic(f"/{t}", SESSION_TOPICS[t], loop=True)
        for t in ("ee_pose", "ee_twist", "wrench_measured")
    }
    on_events = rec.add_topic("/parameter_events", PARAMETER_EVENT_TYPE)
    for node, values in session_params("OL", 0.0, 800.0).items():
        rec.write_snapshot(f"/{node}", values, {})
    tpl = {t: vector_template(SESSION_TOPICS[t]) for t in on}
    wall = 1_767_225_600 * 10**9
    for k in range(x.size):
        for t, value in (("ee_pose", x[k]), ("ee_twist", v[k]), ("wrench_measured", force[k])):
            on[t](tpl[t].fill(k * MS, (float(value), 0.0, 0.0)))
        if k == 4010:  # stamped with sample 4000, received 10 samples later
            on_events(parameter_event("/controller_node", {"kf": 1.0}, 4000 * MS, False))
        if k == 8000:  # a wall-clock stamp: the newest sample received decides
            on_events(parameter_event("/environment_node", {"damping_n_s_per_m": 1.0}, wall, False))
    rec.close()
    segs = analyze_bag(tmp_path / "bag").segments
    assert [s.start_s for s in segs] == [0.0, 4.0, 8.0]
    assert [s.kf for s in segs] == [0.0, 1.0, 1.0]
    assert [s.damping_n_s_per_m for s in segs] == [0.0, 0.0, 1.0]
