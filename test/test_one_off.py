"""A person's one-off command arrives: ``ros2 topic pub --once`` from a fresh process, as a user
types it at a device running alone in lockstep, steps the device by one sample every time.

The publisher is made as ``ros2 topic pub --once`` makes it (reliable, the default QoS): a new
process, it waits until it has matched a subscription, publishes once, keeps its node alive a
moment (``--keep-alive``, 0.1 s) and exits. A best-effort reader can drop that message when it has
not yet matched the new writer itself; the loop's inputs are reliable, so none is lost.
"""

from __future__ import annotations

import subprocess
import sys

import pytest

from haptic_msgs_py.topics import JOINT_STATES, SESSION_TOPICS
from rosgraph import BIN, Collector, Process, isolated_env
from waits import wait_until

pytestmark = [pytest.mark.multiprocess, pytest.mark.slow]

ONCE = """
import time
import rclpy
from std_msgs.msg import Float64MultiArray
rclpy.init()
node = rclpy.create_node("topic_pub_once")
pub = node.create_publisher(Float64MultiArray, "/effort_command", 10)
end = time.monotonic() + 30.0
while pub.get_subscription_count() < 1 and time.monotonic() < end:
    time.sleep(0.001)
pub.publish(Float64MultiArray(data=[0.1]))
time.sleep(0.1)
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
