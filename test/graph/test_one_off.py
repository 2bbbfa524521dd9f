"""A person's one-off command arrives: ``ros2 topic pub --once`` from a fresh process, as a user
types it at a device running alone in lockstep (its command input opened for this bench work,
``open_command_input``), steps the device by one sample every time.

The publisher is made as ``ros2 topic pub --once`` makes it (reliable, the default QoS): a new
process, it waits until it has matched a subscription, publishes once and exits. A reader can
match the new writer after the writer matched it and sent: a best-effort reader then drops the
message for good; a reliable one asks for it again and acknowledges it. The loop's inputs are
reliable, so the publisher here stays until every matched reader has acknowledged (at most 10 s)
instead of ``ros2 topic pub``'s fixed ``--keep-alive`` of 0.1 s, which a busy machine can outrun
(a fresh-clone CI run lost command 8 of 8 that way); docs/running.md says to pass
``--keep-alive 1.0`` there. Against a best-effort reader the wait returns at once (best-effort
readers never acknowledge) and a late-matched command is lost, which this test would catch.
"""

from __future__ import annotations

import subprocess
import sys

import pytest

from haptic_msgs_py.topics import JOINT_STATES, SESSION_TOPICS
from support.rosgraph import BIN, Collector, Process, isolated_env
from support.waits import wait_until

pytestmark = [pytest.mark.multiprocess, pytest.mark.slow]

ONCE = """
import time
import rclpy
from rclpy.duration import Duration
from std_msgs.msg import Float64MultiArray
rclpy.init()
node = rclpy.create_node("topic_pub_once")
pub = node.create_publisher(Float64MultiArray, "/effort_command", 10)
end = time.monotonic() + 30.0
while pub.get_subscription_count() < 1 and time.monotonic() < end:
    time.sleep(0.001)
pub.publish(Float64MultiArray(data=[0.1]))
if not pub.wait_for_all_acked(Duration(seconds=10.0)):
    raise SystemExit("the one-off command was not acknowledged within 10 s")
node.destroy_node()
rclpy.shutdown()
"""
TRIES = 8


def test_every_one_off_command_steps_a_lone_lockstep_device(tmp_path) -> None:
    env = isolated_env()
    device = Process(
        [
            str(BIN / "haptic-device-node"),
            "--ros-args",
            "-p",
            "wait_for:=[]",
            "-p",
            "start_delay_s:=0.0",
            "-p",
            "lockstep_timeout_s:=3600.0",  # no re-send: only the commands move the samples
            "-p",
            "open_command_input:=true",  # a person's commands by hand: a bench session
        ],
        env,
        tmp_path / "device.log",
    )
    col = Collector(env, {JOINT_STATES: SESSION_TOPICS[JOINT_STATES]})
    try:
        assert wait_until(lambda: col.count(JOINT_STATES) >= 1, 60), device.output()
        for k in range(1, TRIES + 1):
            subprocess.run([sys.executable, "-c", ONCE], env=env, timeout=120, check=True)
            stepped = wait_until(
                lambda k=k: (col.newest_stamp_ns(JOINT_STATES) or 0) >= k * 1_000_000, 30
            )
            assert stepped, f"one-off command {k} was lost\n" + device.output()[-2000:]
    finally:
        device.stop()
        col.close()
