"""A node stopped while samples still come in answers them before it exits (nothing lost at a stop).

At the end of a lockstep run the launcher stops every node as soon as the device finishes; the
observer, off the critical path in OL and CL, may then still hold samples it has not answered.
"""

from __future__ import annotations

import os
import signal
import time

import numpy as np
import pytest

from haptic_msgs_py import wire
from haptic_msgs_py.ros import qos
from haptic_msgs_py.ros.raw import RawPublisher
from haptic_msgs_py.stamps import stamp_ns
from haptic_msgs_py.topics import JOINT_STATES, SESSION_TOPICS, WRENCH_ESTIMATE
from support.rosgraph import BIN, Collector, Process, isolated_env
from support.waits import wait_until

pytestmark = [pytest.mark.multiprocess, pytest.mark.slow]

N = 800  # fewer than the observer's input queue holds (qos.LOOP_IN_DEPTH)


def test_observer_answers_every_queued_sample_when_stopped(tmp_path) -> None:
    env = isolated_env()
    col = Collector(env, {WRENCH_ESTIMATE: SESSION_TOPICS[WRENCH_ESTIMATE]})
    pub = RawPublisher(col.node, SESSION_TOPICS[JOINT_STATES], JOINT_STATES, qos.LOOP)
    observer = Process([str(BIN / "haptic-observer-node")], env, tmp_path / "observer.log")
    try:
        if not wait_until(
            lambda: (
                pub.get_subscription_count() >= 1 and col.node.count_publishers(WRENCH_ESTIMATE)
            ),
            30,
        ):
            pytest.fail("the observer did not come up: " + observer.output()[-2000:])
        msg = wire.joint_state(["slide"], "")
        msg.velocity = np.zeros(1)
        msg.effort = np.zeros(1)

        def send(k: int) -> None:
            msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(k * 1_000_000, 10**9)
            msg.position = np.array([1e-6 * k])
            pub.publish(msg)

        # sample 0 until it is answered: both ends of both topics matched
        wait_until(lambda: col.count(WRENCH_ESTIMATE), 30, check=lambda: send(0))
        assert col.count(WRENCH_ESTIMATE), observer.output()
        # samples keep coming in after the stop signal, as the device's last ones do when the
        # launcher stops the graph: each is answered
        for k in range(1, N):
            send(k)
            if k == N // 2:
                os.killpg(observer.proc.pid, signal.SIGINT)
            if k % 50 == 0:
                time.sleep(0.002)
        assert observer.wait(15) == 0, observer.output()
        assert col.wait_for(WRENCH_ESTIMATE, N, 10), (col.count(WRENCH_ESTIMATE), observer.output())
    finally:
        observer.stop()
        col.close()
    stamps = sorted({stamp_ns(m) for m in col.messages(WRENCH_ESTIMATE)})
    assert stamps == [k * 1_000_000 for k in range(N)]
