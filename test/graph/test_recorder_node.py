"""The recorder in-process and its command line: topics, stamps, counts, snapshots, progress."""

from __future__ import annotations

import json
import subprocess
import time
from collections.abc import Callable
from pathlib import Path

import pytest
import rclpy
from builtin_interfaces.msg import Time
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter

from haptic_dob.bag.cdr import command_label_stamp_ns, header_stamp_ns
from haptic_dob.bag.reader import open_bag
from haptic_dob.nodes.recorder_node import RecorderNode
from haptic_msgs_py import wire
from haptic_msgs_py.ros import qos
from haptic_msgs_py.ros.raw import RawPublisher
from haptic_msgs_py.stamps import command_label
from haptic_msgs_py.topics import EE_POSE, EFFORT_COMMAND, SESSION_TOPICS
from support.paths import tool
from support.rosgraph import isolated_env
from support.waits import wait_until


def spin(ex: SingleThreadedExecutor) -> Callable[[], None]:
    """One executor turn: the ``step`` of ``wait_until``."""
    return lambda: ex.spin_once(timeout_sec=0.01)


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_records_counts_snapshots_and_reports_progress(context, tmp_path, storage) -> None:
    """Poses with one missing stamp, commands, a node's parameters: all in a readable bag."""
    out = tmp_path / "bag"
    rec = RecorderNode(
        context=context,
        parameter_overrides=[
            Parameter("output", value=str(out)),
            Parameter("storage", value=storage),
            Parameter("topics", value=["ee_pose", "effort_command", "/parameter_events"]),
        ],
    )
    src = rclpy.create_node("environment_node", context=context)
    src.declare_parameter("stiffness_n_per_m", 800.0)
    pose_pub = RawPublisher(src, SESSION_TOPICS[EE_POSE], EE_POSE, qos.LOOP)
    cmd_pub = RawPublisher(src, SESSION_TOPICS[EFFORT_COMMAND], EFFORT_COMMAND, qos.LOOP)
    ex = SingleThreadedExecutor(context=context)
    ex.add_node(rec)
    ex.add_node(src)
    counts = rec.recording.counts
    try:
        assert wait_until(lambda: counts.snapshots == 1, 10.0, step=spin(ex)), "no snapshot"
        assert rec.progress_ns() == 0  # publishers matched, nothing written yet
        pose = wire.pose_stamped("base_link")
        stamps = [k * 1_000_000 for k in range(200) if k != 50]  # sample 50 never sent
        for s in stamps:
            pose.header.stamp.sec, pose.header.stamp.nanosec = divmod(s, 1_000_000_000)
            pose_pub.publish(pose)
            cmd_pub.publish(wire.float64_multi_array(command_label(s), [0.1]))
        assert wait_until(lambda: counts.topics[1].received == len(stamps), 10.0, step=spin(ex))
        assert rec.progress_ns() == stamps[-1]
        live = counts.topics[2].received  # the node's own declarations, if they came in time
        src.set_parameters([Parameter("stiffness_n_per_m", value=1600.0)])
        assert wait_until(lambda: counts.topics[2].received == live + 1, 10.0, step=spin(ex))
    finally:
        ex.shutdown()
        rec.close()
        src.destroy_node()
        rec.destroy_node()
    pose_c, cmd_c, ev_c = counts.topics
    assert (pose_c.received, pose_c.written, pose_c.gaps) == (199, 199, 1)
    assert (cmd_c.received, cmd_c.written, cmd_c.gaps) == (199, 199, 1)
    assert (pose_c.first_ns, pose_c.newest_ns) == (0, 199_000_000)
    assert ev_c.written == ev_c.received + 1  # the live events and the snapshot
    with open_bag(out) as reader:
        in_bag = {c.topic: c.msgcount for c in reader.connections}
        assert in_bag == {
            "/ee_pose": 199,
            "/effort_command": 199,
            "/parameter_events": ev_c.written,
        }
        logged = [(c.topic, t, d) for c, t, d in reader.messages()]
        events = [
            reader.deserialize(d, c.msgtype)
            for c, _, d in reader.messages()
            if c.topic == "/parameter_events"
        ]
    # bag time is the session's: a loop message's own stamp, the live change (stamped with the
    # node's wall clock) at the newest stamp received before it
    pose_t = [(t, header_stamp_ns(d)) for topic, t, d in logged if topic == "/ee_pose"]
    assert all(t == stamp for t, stamp in pose_t) and len(pose_t) == 199
    cmd_t = [(t, command_label_stamp_ns(d)) for topic, t, d in logged if topic == "/effort_command"]
    assert all(t == stamp for t, stamp in cmd_t) and len(cmd_t) == 199
    assert [t for topic, t, _ in logged if topic == "/parameter_events"][-1] == stamps[-1]
    env = [e for e in events if e.node == "/environment_node"]
    snaps = [
        e
        for e in env
        if {p.name for p in e.new_parameters} >= {"stiffness_n_per_m", "use_sim_time"}
    ]
    assert len(snaps) == 1 and not snaps[0].changed_parameters
    values = {p.name: p.value.double_value for p in snaps[0].new_parameters}
    assert values["stiffness_n_per_m"] == 800.0
    assert [(p.name, p.value.double_value) for p in env[-1].changed_parameters] == [
        ("stiffness_n_per_m", 1600.0)
    ]
    meta = (out / "metadata.yaml").read_text()
    assert "haptic_dob.recorder" in meta
    report = counts.to_json()
    assert report["topics"]["/ee_pose"]["written"] == 199
    assert json.loads(json.dumps(report)) == report


def test_without_loop_topics_the_session_time_comes_from_clock(context, tmp_path) -> None:
    """Recording only ``/parameter_events``: the recorder reads ``/clock`` (the device publishes
    it while someone reads it) and logs the events at its newest time."""
    from rosgraph_msgs.msg import Clock

    out = tmp_path / "bag"
    rec = RecorderNode(
        context=context,
        parameter_overrides=[
            Parameter("output", value=str(out)),
            Parameter("topics", value=["/parameter_events"]),
        ],
    )
    src = rclpy.create_node("environment_node", context=context)
    src.declare_parameter("stiffness_n_per_m", 800.0)
    clock = src.create_publisher(Clock, "/clock", qos.CLOCK)
    ex = SingleThreadedExecutor(context=context)
    ex.add_node(rec)
    ex.add_node(src)
    try:
        assert wait_until(lambda: clock.get_subscription_count() == 1, 10.0, step=spin(ex))
        clock.publish(Clock(clock=Time(sec=7, nanosec=5)))
        assert wait_until(lambda: rec.recording.session_ns > 0, 10.0, step=spin(ex))
        count = rec.recording.counts.topics[0]
        live = count.received
        src.set_parameters([Parameter("stiffness_n_per_m", value=1600.0)])
        assert wait_until(lambda: count.received == live + 1, 10.0, step=spin(ex))
    finally:
        ex.shutdown()
        rec.close()
        src.destroy_node()
        rec.destroy_node()
    with open_bag(out) as reader:
        times = [t for _, t, _ in reader.messages()]
    assert times[-1] == 7_000_000_005


def test_progress_is_held_while_a_node_has_not_given_its_parameters(context, tmp_path) -> None:
    """A lockstep run must not end before the bag knows a node's parameters: the reported
    progress stays where the node appeared until it answers or ``snapshot_timeout_s`` passed."""
    rec = RecorderNode(
        context=context,
        parameter_overrides=[
            Parameter("output", value=str(tmp_path / "bag")),
            Parameter("topics", value=["ee_pose", "/parameter_events"]),
            Parameter("snapshot_timeout_s", value=1.0),
        ],
    )
    src = rclpy.create_node("silent_node", context=context, start_parameter_services=False)
    pose_pub = RawPublisher(src, SESSION_TOPICS[EE_POSE], EE_POSE, qos.LOOP)
    ex = SingleThreadedExecutor(context=context)
    ex.add_node(rec)
    ex.add_node(src)
    try:
        assert wait_until(
            lambda: any(p.node == "/silent_node" for p in rec.snapshots.pending),
            10.0,
            step=spin(ex),
        )
        t_seen = time.monotonic()
        pose = wire.pose_stamped("base_link")
        for k in range(100):
            pose.header.stamp.sec, pose.header.stamp.nanosec = divmod(k * 1_000_000, 10**9)
            pose_pub.publish(pose)
        pose_c = rec.recording.counts.topics[0]
        assert wait_until(lambda: pose_c.received == 100, 10.0, step=spin(ex))
        assert rec.progress_ns() == 99_000_000
        if time.monotonic() - t_seen < 0.9:  # still within snapshot_timeout_s
            assert rec.reported_progress_ns() == 0
        # the node never answers: after the timeout it is warned about and the hold ends
        assert wait_until(lambda: rec.reported_progress_ns() == 99_000_000, 10.0, step=spin(ex))
        assert time.monotonic() - t_seen >= 0.9
        assert rec.recording.counts.snapshots == 0
    finally:
        ex.shutdown()
        rec.close()
        src.destroy_node()
        rec.destroy_node()


def test_refuses_to_overwrite_and_names_bad_topics(tmp_path: Path) -> None:
    existing = tmp_path / "bag"
    existing.mkdir()
    out = subprocess.run(
        [tool("haptic-record"), str(existing)], capture_output=True, text=True, timeout=60
    )
    assert out.returncode == 2
    assert out.stderr == (
        f"ERROR: {existing} exists already; the recorder never overwrites a bag\n"
    )
    env = isolated_env()
    out = subprocess.run(
        [tool("haptic-record"), str(tmp_path / "new"), "--topic", "odometry"],
        capture_output=True,
        text=True,
        timeout=60,
        env=env,
    )
    assert out.returncode == 2, out.stderr
    assert (
        out.stderr.strip()
        .splitlines()[-1]
        .startswith(
            "ERROR: topics: 'odometry' is not a session topic; give its type as "
            "odometry:pkg/msg/Type"
        )
    )
    assert "Traceback" not in out.stderr
    assert not (tmp_path / "new").exists()
    out = subprocess.run(
        [tool("haptic-record"), str(tmp_path / "x"), "--duration", "-1"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert (out.returncode, out.stderr) == (2, "ERROR: --duration must be >= 0 s, got -1\n")
    out = subprocess.run(
        [tool("haptic-record"), "--storage", "rosbag1"], capture_output=True, text=True, timeout=60
    )
    assert out.returncode == 2
    assert out.stderr.splitlines()[-1].startswith("ERROR: argument --storage: invalid choice")


def test_duration_stops_and_prints_the_counts(tmp_path: Path) -> None:
    env = isolated_env()
    out = subprocess.run(
        [tool("haptic-record"), str(tmp_path / "bag"), "--duration", "0.5", "--storage", "sqlite3"],
        capture_output=True,
        text=True,
        timeout=60,
        env=env,
    )
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    assert lines[0].split()[:5] == ["topic", "type", "received", "written", "gaps"]
    assert lines[1].split()[:5] == ["/joint_states", "sensor_msgs/msg/JointState", "0", "0", "0"]
    assert lines[-1] == f"bag: {tmp_path / 'bag'} (sqlite3)"
    assert (tmp_path / "bag" / "metadata.yaml").exists()


def test_says_a_publisher_lost_mid_stream_when_one_matches_again(context, tmp_path) -> None:
    """The recorder hears of its topics' publishers from DDS (``matched``): when the only
    publisher of a topic that was flowing goes and one comes back, the watch counts one
    rematch (and the node logs the line ``test_recorder_publishers`` checks)."""
    rec = RecorderNode(
        context=context,
        parameter_overrides=[
            Parameter("output", value=str(tmp_path / "bag")),
            Parameter("topics", value=["ee_pose"]),
        ],
    )
    ex = SingleThreadedExecutor(context=context)
    ex.add_node(rec)
    watch = rec.publisher_watches[0]
    count = rec.recording.counts.topics[0]
    pose = wire.pose_stamped("base_link")
    try:
        for sent in (5, 10):  # one publisher, then after it went, another
            src = rclpy.create_node("environment_node", context=context)
            pub = RawPublisher(src, SESSION_TOPICS[EE_POSE], EE_POSE, qos.LOOP)
            ex.add_node(src)
            assert wait_until(lambda: watch.matched == 1, 10.0, step=spin(ex)), "no match"
            first = count.received
            for k in range(first, sent):
                pose.header.stamp.nanosec = k * 1_000_000
                pub.publish(pose)
            assert wait_until(lambda n=sent: count.received == n, 10.0, step=spin(ex))
            ex.remove_node(src)
            src.destroy_node()
            if sent == 5:
                assert wait_until(lambda: watch.lost_at_s is not None, 10.0, step=spin(ex))
                assert watch.rematches == 0
    finally:
        ex.shutdown()
        rec.close()
        rec.destroy_node()
    assert watch.rematches == 1
