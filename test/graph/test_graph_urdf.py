"""observer_node with model:=urdf as a teleoperation slave's force sensor, on the wire.

Two observer_node processes (namespaces /plain and /shuffled) run the 3-link test arm from
``config/urdf/arm3.urdf``. The test publishes the simulated arm's joint_states (a known 3.7 N
tip force from 0.2 s) to both, 20 samples at a time, waiting for their estimates: to /plain in
model order, to /shuffled with the joints in another order and two extra joints. Checked: the
wrench_estimate on the wire converges to the known force within the lag c predicts
(``test_urdf.check_known_force``), equals the in-process observer's, and the shuffled stream gives
exactly the same estimate. A JointState lacking a joint is refused with one clear error and the
node keeps answering; incomplete URDF settings stop the node with one ERROR line.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest

from haptic_dob.core.observers.disturbance import DisturbanceObserver
from haptic_msgs_py.stamps import stamp_ns
from support.arm3 import ARM3, GAIN, check_known_force, known_force_run
from support.rosgraph import BIN, Collector, Process, isolated_env, read_force
from support.waits import wait_until

pytestmark = [pytest.mark.multiprocess, pytest.mark.slow]

EXTRA = ("gripper_finger", "wrist_camera_tilt")
SHUFFLED = ("joint3", EXTRA[0], "joint1", EXTRA[1], "joint2")
BATCH = 20  # samples in flight at once (the observer queues 1000)


def observer(ns: str, env: dict[str, str], log: Path) -> Process:
    argv = [
        str(BIN / "haptic-observer-node"),
        "--ros-args",
        "-r",
        f"__ns:=/{ns}",
        "-p",
        "model:=urdf",
        "-p",
        f"urdf_path:={ARM3}",
        "-p",
        "tip_frame:=tool",
        "-p",
        f"gain:={GAIN}",
        "-p",
        "output_limit:=0.0",
    ]
    return Process(argv, env, log)


class Feeder:
    """An in-test node publishing sensor_msgs/JointState to both observers."""

    def __init__(self, env: dict[str, str]) -> None:
        import os

        import rclpy
        from rclpy.context import Context
        from sensor_msgs.msg import JointState

        self._saved = os.environ.get("ROS_DOMAIN_ID")
        os.environ["ROS_DOMAIN_ID"] = env["ROS_DOMAIN_ID"]
        self.JointState = JointState
        self.context = Context()
        rclpy.init(context=self.context, args=[])
        self.node = rclpy.create_node("arm_driver", context=self.context)
        self.pubs = {
            ns: self.node.create_publisher(JointState, f"/{ns}/joint_states", 100)
            for ns in ("plain", "shuffled")
        }

    def matched(self) -> bool:
        return all(p.get_subscription_count() >= 1 for p in self.pubs.values())

    def send(self, ns: str, k: int, names, q, qd, effort) -> None:
        msg = self.JointState()
        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(k * 1_000_000, 1_000_000_000)
        msg.name, msg.position, msg.velocity, msg.effort = (
            list(names),
            list(q),
            list(qd),
            list(effort),
        )
        self.pubs[ns].publish(msg)

    def close(self) -> None:
        import os

        import rclpy

        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)
        if self._saved is None:
            os.environ.pop("ROS_DOMAIN_ID", None)
        else:
            os.environ["ROS_DOMAIN_ID"] = self._saved


def shuffle(values, extra=(0.123, -4.5)) -> list[float]:
    """Model-order values (joint1..3) in SHUFFLED order with values for the extra joints."""
    by_name = dict(zip(("joint1", "joint2", "joint3"), values, strict=True))
    by_name.update(zip(EXTRA, extra, strict=True))
    return [float(by_name[n]) for n in SHUFFLED]


def test_urdf_observer_node_recovers_a_known_tip_force(tmp_path: Path) -> None:
    samples, truth, model, dt = known_force_run()
    env = isolated_env()
    topics = {
        f"/{ns}/wrench_estimate": "geometry_msgs/msg/WrenchStamped" for ns in ("plain", "shuffled")
    }
    nodes = [observer(ns, env, tmp_path / f"{ns}.log") for ns in ("plain", "shuffled")]
    col = Collector(env, topics)
    feed = Feeder(env)
    try:
        assert wait_until(feed.matched, 60), nodes[0].output() + nodes[1].output()
        # its estimates are volatile
        assert wait_until(col.matched, 60), nodes[0].output() + nodes[1].output()

        def send(k: int) -> None:
            q, qd, tau = samples[k]
            feed.send("plain", k, ("joint1", "joint2", "joint3"), q, qd, tau)
            feed.send("shuffled", k, SHUFFLED, shuffle(q), shuffle(qd), shuffle(tau))

        # sample 0 until both answer: the feeder may match an observer's reader before that
        # reader knows the feeder, and a volatile reader drops what came before (the observer
        # answers a repeated sample again, with the same estimate)
        assert wait_until(
            lambda: all(col.newest_stamp_ns(t) is not None for t in topics),
            60,
            poll_s=0.2,
            check=lambda: send(0),
        ), "no estimate of sample 0\n" + nodes[1].output()
        for k in range(1, len(samples)):
            send(k)
            if k % BATCH == BATCH - 1 or k == len(samples) - 1:  # a few at a time: none is lost
                for topic in topics:
                    assert col.wait_for_stamp(topic, k * 1_000_000, 10.0), (
                        f"no estimate {k} on {topic}"
                    )
        # a sample lacking joint3, twice: refused with one error; the next good one is answered
        n = len(samples)
        q, qd, tau = samples[-1]
        for k in (n, n + 1):
            feed.send("plain", k, ("joint1", "joint2"), q[:2], qd[:2], tau[:2])
        feed.send("plain", n + 2, ("joint1", "joint2", "joint3"), q, qd, tau)
        assert col.wait_for_stamp("/plain/wrench_estimate", (n + 2) * 1_000_000, 10.0)
        time.sleep(0.3)
    finally:
        feed.close()
        for p in nodes:
            p.stop()
        col.close()
    est = {t: {stamp_ns(m): np.array(read_force(m)) for m in col.messages(t)} for t in topics}
    plain, shuffled = est["/plain/wrench_estimate"], est["/shuffled/wrench_estimate"]
    stamps = [k * 1_000_000 for k in range(len(samples))]
    assert all(s in plain and s in shuffled for s in stamps)
    e_plain = np.array([plain[s] for s in stamps])
    e_shuffled = np.array([shuffled[s] for s in stamps])
    np.testing.assert_array_equal(e_shuffled, e_plain)  # same estimate, bit for bit
    # the node computes what the core observer computes in-process
    obs = DisturbanceObserver(model, GAIN, dt)
    ref = []
    for q, qd, tau in samples:
        obs.update(q, qd, tau)
        ref.append(obs.wrench(q))
    np.testing.assert_allclose(e_plain, np.array(ref), rtol=0, atol=1e-12)
    check_known_force(e_plain, samples, truth, model, dt)
    # the bad samples got no answer, the good one after them did; one error line for both
    assert (len(samples)) * 1_000_000 not in plain and (len(samples) + 2) * 1_000_000 in plain
    log = nodes[0].output()
    assert log.count("lacks joint(s) joint3") == 1, log
    assert nodes[0].proc.returncode in (0, -2), log  # stopped by SIGINT, not crashed


def test_urdf_observer_node_refuses_incomplete_settings_with_one_error(tmp_path: Path) -> None:
    env = isolated_env()
    cases = {
        "nourdf": (["-p", "tip_frame:=tool"], "needs robot_description (URDF text) or urdf_path"),
        "badtip": (
            ["-p", f"urdf_path:={ARM3}", "-p", "tip_frame:=gripper"],
            "'gripper' is not a frame",
        ),
    }
    for name, (params, message) in cases.items():
        argv = [str(BIN / "haptic-observer-node"), "--ros-args", "-p", "model:=urdf", *params]
        p = Process(argv, env, tmp_path / f"{name}.log")
        try:
            assert p.wait(60) == 2
        finally:
            p.stop()
        out = p.output()
        assert out.count("ERROR:") == 1 and message in out and "Traceback" not in out, out
