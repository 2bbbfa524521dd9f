"""Nodes composed in one process: the loop is handed over in process, DDS serves readers elsewhere.

The four loop nodes are built in one private context and turned over by hand (the device's
sample, then the deferred work the spin loop would run), so the test sees each cycle.
"""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest
import rclpy
from rclpy.context import Context
from rclpy.experimental import EventsExecutor
from rclpy.parameter import Parameter

from haptic_dob.nodes.controller_node import ControllerNode
from haptic_dob.nodes.environment_node import EnvironmentNode
from haptic_dob.nodes.observer_node import ObserverNode
from haptic_msgs_py.ros.loop_io import LoopPublisher, LoopSubscription
from haptic_sim.nodes.device_node import DeviceNode
from haptic_sim.slide.session import SessionConfig, run_session
from support.rosgraph import isolated_env
from support.waits import wait_until

LOOP_TOPICS = {
    "/joint_states",
    "/ee_pose",
    "/ee_twist",
    "/wrench_measured",
    "/wrench_desired",
    "/wrench_estimate",
    "/effort_command",
}


@pytest.fixture
def composed(monkeypatch: pytest.MonkeyPatch):
    """(executor, nodes, sends): the loop's nodes in one context, their executor (spun until the
    graph settled); ``sends`` counts DDS sends."""
    monkeypatch.setenv("ROS_DOMAIN_ID", isolated_env()["ROS_DOMAIN_ID"])
    sends: Counter[str] = Counter()
    original = LoopPublisher.send

    def counting(self: LoopPublisher, value: object) -> None:
        sends[self.topic] += 1
        original(self, value)

    monkeypatch.setattr(LoopPublisher, "send", counting)
    ctx = Context()
    args = ["--ros-args", "-p", "mode:=DOB", "-p", "kf:=1.0", "-p", "wait_for:=[]"]
    rclpy.init(context=ctx, args=args)
    nodes = [cls(context=ctx) for cls in (EnvironmentNode, ObserverNode, ControllerNode)]
    nodes.append(DeviceNode(context=ctx))
    ex = EventsExecutor(context=ctx)
    for n in nodes:
        ex.add_node(n)
    # as the spin loop does before sample 0: the graph's events (matches made and undone while
    # the nodes were built) for 0.3 s
    wait_until(lambda: False, 0.3, step=lambda: ex.spin_once(timeout_sec=0.01))
    yield ex, nodes, sends
    ex.shutdown()
    for n in nodes:
        n.destroy_node()
    rclpy.try_shutdown(context=ctx)


def turn(device: DeviceNode, cycles: int) -> list[float]:
    """Sample 0 (if not sent yet), then ``cycles`` cycles, as the spin loop runs them; the
    position of every sample sent."""
    bus = device._bus
    q = []
    if not device.loop.started:
        device.loop.started = True
        q.append(device.device.sample().q[0])
        device.loop.publish(device.device.sample())
    for _ in range(cycles):
        assert len(bus.soon) == 1, "each command defers exactly the next sample"
        q.append(device.device.sample().q[0])  # sample k+1, moved by command k, goes out now
        bus.soon.popleft()()
    return q


def test_the_loop_turns_in_process_and_equals_the_batch_run(composed) -> None:
    _ex, nodes, sends = composed
    device = nodes[-1]
    subs = [s for n in nodes for s in vars(n).values() if isinstance(s, LoopSubscription)]
    assert not any(s.dds for s in subs)  # no DDS subscription where the publisher is here
    q = turn(device, 1999)  # samples 0..1999; the plant at sample 2000
    assert device.device.k == 2000
    assert not sends  # nobody elsewhere listens: nothing went on DDS
    batch = run_session(SessionConfig().replace(loop__duration_s=2.0, law__mode="DOB", law__kf=1.0))
    assert np.array_equal(np.array(q[:2000]), batch.q)  # the batch run, bit for bit
    assert device.device.sample().effort[0] == np.clip(batch.command[-1], -4.0, 4.0)


def test_the_nodes_and_their_topics_stay_visible_and_readers_elsewhere_get_the_stream(
    composed,
) -> None:
    ex, nodes, sends = composed
    device = nodes[-1]
    names = {n for n, _ in nodes[0].get_node_names_and_namespaces()}
    assert {"device_node", "environment_node", "observer_node", "controller_node"} <= names
    published = {
        t
        for n in nodes
        for t, _ in n.get_publisher_names_and_types_by_node(n.get_name(), n.get_namespace())
    }
    assert published >= LOOP_TOPICS
    # a reader in another process-like context: its matched event reaches the publisher, and
    # from then on the topic goes on DDS after each command
    other = Context()
    rclpy.init(context=other, args=[])
    reader = rclpy.create_node("outside_reader", context=other)
    from geometry_msgs.msg import WrenchStamped

    got: list[object] = []
    sub = reader.create_subscription(WrenchStamped, "wrench_desired", got.append, 1000)
    ex_other = EventsExecutor(context=other)
    ex_other.add_node(reader)
    env = nodes[0]
    try:
        wait_until(
            lambda: env._pub.readers >= 1 and sub.get_publisher_count() >= 1,
            20,
            step=lambda: (ex.spin_once(timeout_sec=0.02), ex_other.spin_once(timeout_sec=0.0)),
        )
        assert env._pub.readers == 1
        turn(device, 100)
        assert sends == Counter({"/wrench_desired": 101})  # samples 0..100; nothing else
        wait_until(lambda: len(got) >= 101, 10, step=lambda: ex_other.spin_once(timeout_sec=0.05))
        assert len(got) == 101
    finally:
        ex_other.shutdown()
        reader.destroy_node()
        rclpy.try_shutdown(context=other)


def test_a_live_switch_acts_on_the_next_cycle_in_process(composed) -> None:
    _ex, nodes, _sends = composed
    controller, device = nodes[2], nodes[-1]
    turn(device, 200)
    assert controller.set_parameters([Parameter("mode", value="CL")])[0].successful
    k = device.device.k
    turn(device, 1)
    join = controller.join
    wall, measured = join.desired.value, join.measured_in.value
    expected = float(np.clip(wall[0] + 1.0 * (wall[0] + measured[0]), -4.0, 4.0))
    assert join.law.mode.value == "CL" and join.sent_ns == k * controller.period_ns
    assert device.device.sample().effort[0] == expected


def test_parameter_events_carry_the_sample_a_change_applies_from(composed) -> None:
    ex, nodes, _sends = composed
    env, observer, controller, device = nodes
    from rcl_interfaces.msg import ParameterEvent

    events: list[ParameterEvent] = []
    listener = rclpy.create_node("event_listener", context=env.context)
    listener.create_subscription(ParameterEvent, "/parameter_events", events.append, 100)
    ex.add_node(listener)
    before = env.get_clock().now().nanoseconds
    assert env.set_parameters([Parameter("stiffness_n_per_m", value=1000.0)])[0].successful
    turn(device, 300)
    k = device.device.k
    period = controller.period_ns
    assert controller.set_parameters([Parameter("kf", value=2.0)])[0].successful
    assert env.set_parameters([Parameter("stiffness_n_per_m", value=1200.0)])[0].successful
    assert observer.set_parameters([Parameter("gain", value=300.0)])[0].successful
    assert not env.set_parameters([Parameter("stiffness_n_per_m", value=-1.0)])[0].successful
    # the node's own clock is untouched: a refused change and the next reading see real time
    assert env.get_clock().now().nanoseconds >= before
    wait_until(lambda: len(events) >= 4, 10, step=lambda: ex.spin_once(timeout_sec=0.05))
    ex.remove_node(listener)
    listener.destroy_node()
    from rclpy.parameter import parameter_value_to_python

    stamps = {
        (e.node, p.name, parameter_value_to_python(p.value)): e.stamp.sec * 10**9 + e.stamp.nanosec
        for e in events
        for p in e.changed_parameters
    }
    # before the loop ran: the node's clock (wall time, not a sample's stamp)
    assert stamps[("/environment_node", "stiffness_n_per_m", 1000.0)] >= before
    # the loop ran samples 0..k-1 and sent commands 0..k-1: sample k is the first changed
    assert stamps[("/controller_node", "kf", 2.0)] == k * period
    assert stamps[("/environment_node", "stiffness_n_per_m", 1200.0)] == k * period
    assert stamps[("/observer_node", "gain", 300.0)] == k * period
    assert len(events) == 4, [(e.node, e.stamp) for e in events]
