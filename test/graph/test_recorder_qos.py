"""The recorder between real publishers: its bag holds each topic's offered QoS as ``ros2 bag
record`` of Jazzy stores it, so ``ros2 bag play`` offers it again, in a closed bag and in one
recovered after a kill -9, MCAP and sqlite3; a late ``ros2 topic echo`` of its progress is told
of no lost message."""

from __future__ import annotations

import os
import signal
import subprocess
import time
from pathlib import Path
from typing import Any

import pytest
import yaml
from rclpy.duration import Duration
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from haptic_dob.bag.cdr import header_stamp_ns
from haptic_msgs_py import wire
from haptic_msgs_py.ros import qos
from haptic_msgs_py.ros.raw import rclpy_type
from haptic_msgs_py.topics import EE_POSE, JOINT_STATES, RECORDER_PROGRESS, SESSION_TOPICS
from support.jazzy_bag import check_bag, offered
from support.paths import tool
from support.rosgraph import Collector, Process, isolated_env
from support.waits import wait_until

MS = 1_000_000
LATCHED = QoSProfile(  # a description published once for late joiners
    history=HistoryPolicy.KEEP_LAST,
    depth=1,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
)
WITH_DEADLINE = QoSProfile(  # reliable, volatile, a deadline: a policy play must offer again
    history=HistoryPolicy.KEEP_LAST,
    depth=100,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.VOLATILE,
    deadline=Duration(seconds=0, nanoseconds=250_000_000),
)
INFINITE = {"sec": 9223372036, "nsec": 854775807}
#: topic -> (rosbag2's reliability, durability, deadline) of its one publisher
WANT = {
    "/joint_states": ("reliable", "volatile", INFINITE),
    "/ee_pose": ("reliable", "volatile", {"sec": 0, "nsec": 250_000_000}),
    "/robot_description": ("reliable", "transient_local", INFINITE),
}


def record(tmp_path: Path, storage: str, kill: bool) -> Path:
    """Joint states (the loop's profile), poses (with a deadline) and a latched description
    into ``haptic-record``; stopped with SIGINT, or killed with SIGKILL once 1.1 s of session
    time and a wall second have passed since the messages were written (so they are durable)."""
    env = isolated_env()
    bag = tmp_path / "session"
    col = Collector(env, {RECORDER_PROGRESS: "std_msgs/msg/Header"})
    node = col.node
    js = node.create_publisher(rclpy_type(SESSION_TOPICS[JOINT_STATES]), JOINT_STATES, qos.LOOP)
    pose = node.create_publisher(rclpy_type(SESSION_TOPICS[EE_POSE]), EE_POSE, WITH_DEADLINE)
    desc = node.create_publisher(rclpy_type("std_msgs/msg/String"), "/robot_description", LATCHED)
    topics = ["--topic", JOINT_STATES, "--topic", EE_POSE]
    topics += ["--topic", "/robot_description:std_msgs/msg/String"]
    rec = Process(
        [tool("haptic-record"), str(bag), "--storage", storage, *topics], env, tmp_path / "log"
    )

    def written_ns() -> int:
        with col._lock:
            reports = col.records[RECORDER_PROGRESS]
            return header_stamp_ns(reports[-1][1]) if reports else -1  # type: ignore[return-value]

    try:
        pubs = (js, pose, desc)
        assert wait_until(lambda: all(p.get_subscription_count() for p in pubs), 60), rec.output()
        assert wait_until(lambda: written_ns() >= 0, 60), rec.output()
        desc.publish(wire.encode(wire.TYPESTORE.types["std_msgs/msg/String"](data="<robot/>")))
        state, where = wire.joint_state(["slide"], "base_link"), wire.pose_stamped("base_link")

        def publish(k: int) -> None:
            for msg in (state, where):
                msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(k * MS, 10**9)
            js.publish(wire.encode(state))
            pose.publish(wire.encode(where))

        n = 1101
        for k in range(n):
            publish(k)
            if k % 100 == 0:
                time.sleep(0.01)  # paced a little: the pose's reader has no deep history
        # the progress is the slower topic's newest stamp written: where a reader lost the last
        # sample (a keep-last history overrun on a loaded machine, which the recorder reports),
        # a further stamp on both topics lets it pass
        for k in range(n, n + 12):
            if wait_until(lambda: written_ns() >= (n - 1) * MS, 5):
                break
            publish(k)
        else:
            assert wait_until(lambda: written_ns() >= (n - 1) * MS, 5), rec.output()
        if kill:
            time.sleep(1.5)  # a wall second: durable however the recorder flushes
            os.killpg(rec.proc.pid, signal.SIGKILL)
            rec.proc.wait(10)
    finally:
        code = rec.stop()
        col.close()
    if not kill:
        assert code == 0, rec.output()
        return bag
    out = subprocess.run(
        [tool("haptic-record"), "--recover", str(bag)], capture_output=True, text=True
    )
    assert out.returncode == 0, out.stderr
    return tmp_path / "session_recovered"


def reliability_durability(profile: Any) -> tuple[str, str]:
    return profile.reliability.name.lower(), profile.durability.name.lower()


@pytest.mark.multiprocess
@pytest.mark.parametrize("kill", [False, True], ids=["closed", "recovered"])
@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_the_bag_holds_each_topics_offered_qos_as_rosbag2_jazzy_writes_it(
    tmp_path: Path, storage: str, kill: bool
) -> None:
    """Each topic's one publisher's profile, as the graph reported it (rmw_fastrtps gives no
    history or depth of a remote writer: ``unknown``, 0), in ``metadata.yaml`` (what ``ros2 bag
    play`` reads), the MCAP channels or sqlite3 topics, and read back by rosbags; the bag names
    ``jazzy`` as its distribution. Before: no profile and ``rosbags``."""
    from rosbags.rosbag2 import Reader

    bag = record(tmp_path, storage, kill)
    meta = check_bag(bag, storage, in_order=False)
    raw = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert raw["ros_distro"] == "jazzy"
    got = offered(meta)
    assert set(got) == set(WANT)
    for topic, (reliability, durability, deadline) in WANT.items():
        (profile,) = got[topic]
        assert (profile["reliability"], profile["durability"]) == (reliability, durability), topic
        assert profile["deadline"] == deadline, topic
        assert (profile["history"], profile["depth"]) == ("unknown", 0), topic
        assert profile["liveliness"] == "automatic", topic
    with Reader(bag) as reader:
        back = {c.topic: c.ext.offered_qos_profiles for c in reader.connections}
        assert reader.ros_distro == "jazzy"
    for topic, (reliability, durability, _) in WANT.items():
        (profile,) = back[topic]
        assert reliability_durability(profile) == (reliability, durability), topic


@pytest.mark.multiprocess
def test_a_late_echo_of_the_progress_hears_no_loss(tmp_path: Path) -> None:
    """``ros2 topic echo /recorder/progress`` started a second after the recorder, with its
    default QoS (Jazzy's ``echo``: the sensor-data profile with the reliability and durability
    every publisher offers): it gets the reports and no message-lost event. Before, the progress
    was transient-local with a history of one: a late transient-local reader was told the
    reports before the kept one were lost ("A message was lost!!!")."""
    import rclpy
    from rclpy.context import Context
    from rclpy.event_handler import SubscriptionEventCallbacks
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.qos import qos_profile_sensor_data
    from std_msgs.msg import Header

    env = isolated_env()
    rec = Process([tool("haptic-record"), str(tmp_path / "bag")], env, tmp_path / "log")
    saved = {k: os.environ.get(k) for k in ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE")}
    os.environ.update({k: env[k] for k in saved})
    context = Context()
    rclpy.init(context=context, args=[])
    node = rclpy.create_node("echo", context=context, start_parameter_services=False)
    ex = SingleThreadedExecutor(context=context)
    ex.add_node(node)
    try:
        infos = lambda: node.get_publishers_info_by_topic(f"/{RECORDER_PROGRESS}")  # noqa: E731
        assert wait_until(infos, 60), rec.output()
        time.sleep(1.0)  # about 50 reports sent before the echo joins
        profile = QoSProfile(
            history=qos_profile_sensor_data.history,
            depth=qos_profile_sensor_data.depth,
            reliability=qos_profile_sensor_data.reliability,
            durability=qos_profile_sensor_data.durability,
        )
        offers = [i.qos_profile for i in infos()]
        if all(q.reliability == ReliabilityPolicy.RELIABLE for q in offers):
            profile.reliability = ReliabilityPolicy.RELIABLE
        if all(q.durability == DurabilityPolicy.TRANSIENT_LOCAL for q in offers):
            profile.durability = DurabilityPolicy.TRANSIENT_LOCAL
        got: list[Any] = []
        lost: list[int] = []
        events = SubscriptionEventCallbacks(
            message_lost=lambda status: lost.append(status.total_count_change)
        )
        node.create_subscription(
            Header, RECORDER_PROGRESS, got.append, profile, event_callbacks=events
        )
        step = lambda: ex.spin_once(timeout_sec=0.02)  # noqa: E731
        assert wait_until(lambda: len(got) >= 25, 60, step=step), rec.output()
        for _ in range(10):
            step()
    finally:
        ex.shutdown()
        node.destroy_node()
        rclpy.try_shutdown(context=context)
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
        rec.stop()
    assert lost == [], f"message-lost events: {lost} (echo's QoS {profile})"
