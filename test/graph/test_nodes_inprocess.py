"""Nodes in-process with a private Context: parameter tables, descriptors and refusals."""

from __future__ import annotations

from pathlib import Path

import pytest
import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter

from haptic_dob.launcher import write_params_file
from haptic_dob.nodes.channel_node import ChannelNode
from haptic_dob.nodes.controller_node import ControllerNode
from haptic_dob.nodes.environment_node import EnvironmentNode
from haptic_dob.nodes.observer_node import ObserverNode
from haptic_dob.nodes.slave_controller_node import SlaveControllerNode
from haptic_msgs_py.topics import EFFORT_COMMAND, WRENCH_ESTIMATE
from haptic_msgs_py.values import EffortCommand, JointSample, StampedVector
from haptic_sim.nodes.device_node import DeviceNode
from support.rosgraph import isolated_env
from support.waits import wait_until

NODES = [
    DeviceNode,
    EnvironmentNode,
    ObserverNode,
    ControllerNode,
    ChannelNode,
    SlaveControllerNode,
]


@pytest.mark.parametrize("cls", NODES, ids=lambda c: c.__name__)
def test_every_parameter_has_a_description_and_ranges(cls, context) -> None:
    node = cls(context=context)
    try:
        for name, spec in node.params.specs.items():
            d = node.describe_parameter(name)
            assert d.description, name
            if spec.kind in (float, int) and spec.min is not None and spec.max is not None:
                ranges = d.floating_point_range if spec.kind is float else d.integer_range
                assert len(ranges) == 1, name
                assert (ranges[0].from_value, ranges[0].to_value) == (spec.min, spec.max)
            assert d.read_only == spec.read_only, name
    finally:
        node.destroy_node()


def test_structural_parameters_are_read_only(context) -> None:
    dev = DeviceNode(context=context)
    ctl = ControllerNode(context=context)
    try:
        for name in ("model", "clock_mode", "rate_hz", "seed", "plant.mass_kg", "hand.behaviour"):
            assert dev.describe_parameter(name).read_only, name
        res = dev.set_parameters([Parameter("plant.mass_kg", value=1.0)])[0]
        assert not res.successful and "read-only" in res.reason
        # the slide's physics is plant.*; slide.* is the model the other nodes assume
        assert not dev.has_parameter("slide.mass_kg") and dev.has_parameter("slide.axis")
        for name in ("mode", "kf", "max_force_n"):
            assert not ctl.describe_parameter(name).read_only, name
    finally:
        dev.destroy_node()
        ctl.destroy_node()


@pytest.mark.parametrize(
    ("name", "value", "reason"),
    [
        ("mode", "PID", r"mode must be one of OL, CL, DOB"),
        # rclpy checks the declared range first and says so itself
        ("kf", -1.0, r"kf out of range Min: 0.0, Max: 10000.0|kf must be >= 0"),
        ("kf", "two", r"Wrong parameter type"),  # rclpy: the declared type holds
        ("max_force_n", 0.0, r"max_force_n out of range|max_force_n must be >= 0.001"),
    ],
)
def test_controller_refuses_bad_values_and_keeps_the_law(context, name, value, reason) -> None:
    import re

    ctl = ControllerNode(context=context)
    try:
        before = ctl.controller.law
        res = ctl.set_parameters([Parameter(name, value=value)])[0]
        assert not res.successful and re.search(reason, res.reason), res.reason
        assert ctl.controller.law is before
        assert ctl.get_parameter(name).value == ctl.params.values[name]
    finally:
        ctl.destroy_node()


def test_controller_takes_good_values_at_once(context) -> None:
    ctl = ControllerNode(context=context)
    try:
        assert ctl.set_parameters([Parameter("kf", value=3)])[0].successful  # int for a double
        assert ctl.controller.law.kf == 3.0
        assert ctl.set_parameters([Parameter("max_force_n", value=2.5)])[0].successful
        assert ctl.controller.law.max_force_n == 2.5
    finally:
        ctl.destroy_node()


def test_switch_to_dob_is_refused_until_the_observer_is_warm(context) -> None:
    ctl = ControllerNode(context=context)
    try:
        res = ctl.set_parameters([Parameter("mode", value="DOB")])[0]
        assert not res.successful and "wrench_estimate" in res.reason
        assert ctl.controller.law.mode.value == "OL"
        period = ctl.period_ns
        for k in range(30):  # estimates and wall forces of 30 consecutive cycles
            ctl._on_estimated(StampedVector(k * period, (0.0, 0.0, 0.0)))
            ctl._on_desired(StampedVector(k * period, (0.0, 0.0, 0.0)))
        assert ctl.set_parameters([Parameter("mode", value="DOB")])[0].successful
        assert ctl.controller.law.mode.value == "DOB"
        res = ctl.set_parameters([Parameter("mode", value="CL")])[0]
        assert not res.successful and "wrench_measured" in res.reason
    finally:
        ctl.destroy_node()


def test_environment_wall_changes_at_run_time_and_refuses_a_zero_normal(context) -> None:
    env = EnvironmentNode(context=context)
    try:
        assert env.set_parameters([Parameter("stiffness_n_per_m", value=1600.0)])[0].successful
        assert env.wall.stiffness_n_per_m == 1600.0
        res = env.set_parameters([Parameter("normal", value=[0.0, 0.0, 0.0])])[0]
        assert not res.successful and "normal must be a non-zero vector" in res.reason
        assert env.wall.normal == (1.0, 0.0, 0.0)
        res = env.set_parameters([Parameter("position", value=[0.0, 1.0])])[0]
        assert not res.successful and "3 elements" in res.reason
    finally:
        env.destroy_node()


def test_observer_retunes_without_a_jump_and_refuses_a_bad_gain(context) -> None:
    obs = ObserverNode(context=context)
    try:
        assert obs.set_parameters([Parameter("gain", value=10.0)])[0].successful
        assert obs.observer.gain == 10.0
        res = obs.set_parameters([Parameter("gain", value=0.0)])[0]
        assert not res.successful and obs.observer.gain == 10.0
        assert obs.set_parameters([Parameter("output_limit", value=0.0)])[0].successful
        assert obs.observer.limit is None
    finally:
        obs.destroy_node()


def test_the_observer_answers_a_gap_and_says_so_after_it_once_per_throttle(context, capfd) -> None:
    """Samples 0, 1, 3, 4, 7: every one answered with an estimate; the two gaps counted, the
    first said after its estimate went out, the second (within the 5 s throttle) not said."""
    obs = ObserverNode(context=context)
    events: list[tuple[str, int]] = []
    publish, warning = obs._publish, obs.log.warning

    def sent(stamp_ns: int) -> None:
        events.append(("estimate", stamp_ns))
        publish(stamp_ns)

    def said(message: str, **kwargs: float) -> bool:
        events.append(("said", obs._last_ns))
        return warning(message, **kwargs)

    obs._publish = sent  # type: ignore[method-assign]
    obs.log.warning = said  # type: ignore[method-assign]
    try:
        capfd.readouterr()
        stamps = [k * obs.period_ns for k in (0, 1, 3, 4, 7)]
        for k, stamp in enumerate(stamps):
            obs._on_joint_states(JointSample(stamp, obs._names, (0.001 * k,), (0.0,), (0.1,)))
        assert [s for e, s in events if e == "estimate"] == stamps and obs.gaps == 2
        assert events.index(("estimate", stamps[2])) < events.index(("said", stamps[2]))
        err = capfd.readouterr().err
        assert err.count("joint_states jumped") == 1, err
        assert "joint_states jumped 2 periods (1 gaps so far)" in err, err
    finally:
        obs.destroy_node()


def test_bad_start_values_fail_the_node_with_the_reason() -> None:
    ctx = Context()
    rclpy.init(context=ctx, args=["--ros-args", "-p", "kf:=-2.0"])
    try:
        with pytest.raises(Exception, match="kf"):
            ControllerNode(context=ctx)
    finally:
        rclpy.try_shutdown(context=ctx)


def test_device_holds_the_loop_while_a_recorder_lags(context) -> None:
    """Lockstep back-pressure: a command is held until the recorder's progress catches up."""
    from haptic_msgs_py import wire

    dev = DeviceNode(context=context)
    try:
        dev.loop.started = True
        period = dev.period_ns
        for k in range(600):  # 0.6 s of simulated time, no recorder yet: the loop runs freely
            dev.loop.command(EffortCommand(k * period, (0.0,)))
        assert dev.device.k == 600
        fast, slow = wire.header("/fast_recorder"), wire.header("/slow_recorder")
        fast.stamp = wire.Time(sec=0, nanosec=590_000_000)
        slow.stamp = wire.Time(sec=0, nanosec=50_000_000)  # has written 0.05 s
        dev._on_progress(fast)
        dev._on_progress(slow)
        dev.loop.command(EffortCommand(600 * period, (0.0,)))
        held = dev.loop.recorders.held
        assert dev.device.k == 600 and held is not None  # the slowest is 0.55 s behind: held
        slow.stamp = wire.Time(sec=0, nanosec=400_000_000)
        dev._on_progress(slow)  # caught up to 0.2 s behind: released
        assert dev.device.k == 601 and dev.loop.recorders.held is None
        res = dev.set_parameters([Parameter("max_recorder_lag_s", value=0.0)])[0]
        assert not res.successful
    finally:
        dev.destroy_node()


def test_after_a_switch_the_controller_waits_for_a_lagging_input(context) -> None:
    """In OL the observer is off the lockstep critical path and may lag; after the switch to DOB
    the controller waits for estimate k (no fallback, no zero command); once caught up, a silent
    input still trips the fallback after ``input_timeout_s``."""
    ctl = ControllerNode(context=context)
    assert ctl.set_parameters([Parameter("kf", value=1.0)])[0].successful
    sent: dict[int, float] = {}
    ctl._pub.publish = lambda m: sent.__setitem__(m.stamp_ns, m.effort[0])
    period = ctl.period_ns

    def wrench(k: int, fx: float) -> StampedVector:
        return StampedVector(k * period, (fx, 0.0, 0.0))

    try:
        for k in range(100):  # OL; the observer 50 cycles behind
            ctl._on_desired(wrench(k, -1.0))
            if k >= 50:
                ctl._on_estimated(wrench(k - 50, 0.5))
        assert ctl.set_parameters([Parameter("mode", value="DOB")])[0].successful
        ctl._on_desired(wrench(100, -1.0))
        assert 100 * period not in sent and ctl.join.fallback_reason is None  # waiting
        for k in range(50, 101):
            ctl._on_estimated(wrench(k, 0.5))
        assert sent[100 * period] == -1.0 + 1.0 * (-1.0 + 0.5)  # the DOB law, stamp-100 inputs
        assert ctl.join.fallbacks == 0
        for k in range(101, 130):  # caught up; now the estimate stops
            ctl._on_desired(wrench(k, -1.0))
        assert ctl.join.fallback_reason and "wrench_estimate" in ctl.join.fallback_reason
    finally:
        ctl.destroy_node()


def _touch_cycles(monkeypatch, mode: str) -> tuple[list[tuple[str, int]], list[int], bool]:
    """Three samples of the Touch's URDF through the observer and the controller composed in
    ``mode`` (the observer built first, as the registry builds them): what happened in order by
    stamp (the command, the estimate, the observer making its dynamics), the stamps, and
    whether the controller takes the joint states."""
    from rclpy.node import Node

    from haptic_msgs_py import codecs
    from haptic_msgs_py.bus import bus_for
    from haptic_msgs_py.ros import qos
    from haptic_msgs_py.ros.loop_io import LoopPublisher
    from haptic_msgs_py.topics import JOINT_STATES, WRENCH_DESIRED

    monkeypatch.setenv("ROS_DOMAIN_ID", isolated_env()["ROS_DOMAIN_ID"])
    urdf = Path(__file__).resolve().parents[2] / "config" / "urdf" / "phantom_omni.urdf"
    ctx = Context()
    params = ("model:=urdf", f"urdf_path:={urdf}", "tip_frame:=tip", f"mode:={mode}")
    rclpy.init(context=ctx, args=["--ros-args", *(x for p in params for x in ("-p", p))])
    obs, ctl = ObserverNode(context=ctx), ControllerNode(context=ctx)
    device = Node("device", context=ctx)
    log: list[tuple[str, int]] = []
    dynamics = obs.observer._dynamics
    obs.observer._dynamics = lambda q, qd: (
        log.append(("dynamics", obs._last_ns)),
        dynamics(q, qd),
    )[1]
    bus = bus_for(ctx)
    for topic in (EFFORT_COMMAND, WRENCH_ESTIMATE):
        bus.add_subscriber(f"/{topic}", lambda v, t=topic: log.append((t, v.stamp_ns)), lambda: 0)
    p_js = LoopPublisher(device, JOINT_STATES, codecs.JOINT_STATE, qos.LOOP, "world")
    p_wall = LoopPublisher(device, WRENCH_DESIRED, codecs.WRENCH, qos.LOOP, "world")
    names = tuple(obs.model.joint_names)
    try:
        stamps = [k * ctl.period_ns for k in range(1, 4)]
        for stamp in stamps:
            p_wall.publish(StampedVector(stamp, (0.0, 0.0, 0.5)))
            p_js.publish(JointSample(stamp, names, (0.0, 0.3, 0.2), (0.0,) * 3, (0.0,) * 3))
        return log, stamps, ctl.join.needs_q
    finally:
        for n in (device, ctl, obs):
            n.destroy_node()
        rclpy.try_shutdown(context=ctx)


@pytest.mark.parametrize("mode", ["OL", "DOB"])
def test_composed_the_command_goes_out_before_the_observer_makes_its_dynamics(
    monkeypatch, mode: str
) -> None:
    """The Touch's URDF, composed. OL: its Jacobian depends on q, so the controller takes the
    joint states, and so does the observer, whose estimate OL does not use: command k is out
    before estimate k is made, though the observer joined the process first. DOB: estimate k
    goes to the controller and command k out; in either, only then does the observer make the
    dynamics at sample k that its next update needs (``DisturbanceObserver.prepare``)."""
    log, stamps, needs_q = _touch_cycles(monkeypatch, mode)
    assert needs_q
    assert log == [(t, s) for s in stamps for t in (EFFORT_COMMAND, WRENCH_ESTIMATE, "dynamics")]


@pytest.mark.parametrize("passivity", [False, True])
def test_composed_the_slaves_command_goes_out_before_its_estimate_is_made(
    monkeypatch, passivity: bool
) -> None:
    """A teleoperation slave (the 7-DOF arm's URDF) composed in real time: its channel end, its
    controller and its observer. Without the passivity controller, the point to track needs no
    force, so command k goes out before the observer's estimate k is made, and the message to
    the master after it; with the controller on, the point waits for the estimate. A force
    newer than the newest point answers nothing again."""
    from rclpy.node import Node

    from haptic_msgs_py import codecs
    from haptic_msgs_py.bus import bus_for
    from haptic_msgs_py.ros import qos
    from haptic_msgs_py.ros.loop_io import LoopPublisher
    from haptic_msgs_py.topics import (
        EE_POSE,
        EE_TWIST,
        EFFORT_COMMAND,
        JOINT_STATES,
        POSE_DESIRED,
        WRENCH_ESTIMATE,
    )

    monkeypatch.setenv("ROS_DOMAIN_ID", isolated_env()["ROS_DOMAIN_ID"])
    urdf = Path(__file__).resolve().parents[2] / "config" / "urdf" / "arm7.urdf"
    ctx = Context()
    params = (
        "model:=urdf",
        f"urdf_path:={urdf}",
        "tip_frame:=tool",
        "role:=slave",
        f"channel.passivity:={str(passivity).lower()}",
        "wait_for_peer:=false",  # real time: the master is not here
    )
    rclpy.init(context=ctx, args=["--ros-args", *(x for p in params for x in ("-p", p))])
    log: list[tuple[str, int]] = []  # in the order they are published: called before the nodes
    for topic in (EFFORT_COMMAND, WRENCH_ESTIMATE, POSE_DESIRED):
        bus_for(ctx).add_subscriber(
            f"/{topic}", lambda v, t=topic: log.append((t, v.stamp_ns)), lambda: 0, first=True
        )
    obs, chan = ObserverNode(context=ctx), ChannelNode(context=ctx)
    ctl = SlaveControllerNode(context=ctx)
    device = Node("device", context=ctx)
    p_js = LoopPublisher(device, JOINT_STATES, codecs.JOINT_STATE, qos.LOOP, "world")
    p_pose = LoopPublisher(device, EE_POSE, codecs.POSE, qos.LOOP, "world")
    p_twist = LoopPublisher(device, EE_TWIST, codecs.TWIST, qos.LOOP, "world")
    p_force = LoopPublisher(device, WRENCH_ESTIMATE, codecs.WRENCH, qos.LOOP, "world")
    names = tuple(obs.model.joint_names)
    q = (0.0, -0.3, 0.0, -2.0, 0.0, 1.8, 0.8)
    tip = tuple(float(x) for x in obs.model.forward_kinematics(q))
    try:
        stamps = [k * 1_000_000 for k in range(1, 4)]  # at the default 1 kHz
        for stamp in stamps:  # as the bridge publishes a state: the point, then the joints
            p_pose.publish(StampedVector(stamp, tip))
            p_twist.publish(StampedVector(stamp, (0.0, 0.0, 0.0)))
            p_js.publish(JointSample(stamp, names, q, (0.0,) * 7, (0.0,) * 7))
        order = (
            [POSE_DESIRED, EFFORT_COMMAND, WRENCH_ESTIMATE]
            if not passivity
            else [WRENCH_ESTIMATE, POSE_DESIRED, EFFORT_COMMAND]
        )
        assert log == [(t, s) for s in stamps for t in order], log
        p_force.publish(StampedVector(stamps[-1] + 1_000_000, (0.0, 0.0, 0.0)))
        assert log[-1] == (WRENCH_ESTIMATE, stamps[-1] + 1_000_000)  # and nothing after it
    finally:
        for n in (device, ctl, chan, obs):
            n.destroy_node()
        rclpy.try_shutdown(context=ctx)


@pytest.mark.parametrize("wait_for", ["[absent_node]", "[]"])
def test_a_realtime_device_ticks_only_once_its_graph_is_up(monkeypatch, wait_for: str) -> None:
    """In real time as in lockstep the device waits for ``wait_for`` (and says for what);
    ``[]`` ticks at once."""
    import time

    monkeypatch.setenv("ROS_DOMAIN_ID", isolated_env()["ROS_DOMAIN_ID"])
    ctx = Context()
    args = ["--ros-args", "-p", "clock_mode:=realtime", "-p", f"wait_for:={wait_for}"]
    rclpy.init(context=ctx, args=args)
    dev = DeviceNode(context=ctx)
    try:
        for _ in range(5):
            dev.on_wakeup(time.monotonic())
        if wait_for == "[]":
            assert dev.loop.started and dev.device.k >= 1
        else:
            assert not dev.loop.started and dev.device.k == 0
            assert dev.waiting_for() == "node absent_node in /"
            assert dev._report()[1] == "waiting for the graph"
    finally:
        dev.destroy_node()
        rclpy.try_shutdown(context=ctx)


def test_a_realtime_device_publishes_its_stamps_on_clock(monkeypatch) -> None:
    """In real time too, ``/clock`` carries the samples' stamps (the system clock when each was
    taken), so tools with ``use_sim_time`` share the loop's time base (issue: stamps vs ROS
    time)."""
    import time

    from rosgraph_msgs.msg import Clock

    from haptic_msgs_py.ros.qos import CLOCK

    monkeypatch.setenv("ROS_DOMAIN_ID", isolated_env()["ROS_DOMAIN_ID"])
    ctx = Context()
    rclpy.init(context=ctx, args=["--ros-args", "-p", "clock_mode:=realtime", "-p", "wait_for:=[]"])
    dev = DeviceNode(context=ctx)
    probe = rclpy.create_node("clock_probe", context=ctx)
    got: list[int] = []
    probe.create_subscription(
        Clock, "/clock", lambda m: got.append(m.clock.sec * 10**9 + m.clock.nanosec), CLOCK
    )
    ex = SingleThreadedExecutor(context=ctx)
    ex.add_node(probe)
    ex.add_node(dev)  # its publisher-matched events
    try:
        assert wait_until(lambda: dev._p_clock.wanted, 30, step=lambda: ex.spin_once(0.05))
        for _ in range(20):
            dev.on_wakeup(time.monotonic())
        last = dev.loop.stamp_ns  # the newest sample's stamp
        # /clock keeps only its newest message (depth 1): what arrives ends with the newest stamp
        assert wait_until(lambda: got and got[-1] == last, 30, step=lambda: ex.spin_once(0.05))
        assert got == sorted(set(got)) and abs(time.time_ns() - last) < 60 * 10**9
    finally:
        ex.shutdown()
        probe.destroy_node()
        dev.destroy_node()
        rclpy.try_shutdown(context=ctx)


def test_a_late_echo_sees_the_live_stream_not_a_replay(monkeypatch) -> None:
    """A reader that joins a running loop and takes the publisher's durability, as ``ros2 topic
    echo`` does, gets the newest samples at once, not up to 2000 old ones (issue: late echo)."""
    import time

    from rclpy.event_handler import SubscriptionEventCallbacks
    from rclpy.qos import QoSProfile
    from sensor_msgs.msg import JointState

    from haptic_msgs_py.stamps import stamp_ns

    monkeypatch.setenv("ROS_DOMAIN_ID", isolated_env()["ROS_DOMAIN_ID"])
    ctx = Context()
    rclpy.init(context=ctx, args=["--ros-args", "-p", "clock_mode:=realtime", "-p", "wait_for:=[]"])
    dev = DeviceNode(context=ctx)
    echo = rclpy.create_node("late_echo", context=ctx)
    ex = SingleThreadedExecutor(context=ctx)
    ex.add_node(echo)
    ex.add_node(dev)
    try:
        for _ in range(300):
            dev.on_wakeup(time.monotonic())
        joined_k = dev.device.k
        (offered,) = echo.get_publishers_info_by_topic("/joint_states")
        qos = QoSProfile(depth=10, durability=offered.qos_profile.durability)  # as echo adapts
        got: list[int] = []
        lost: list[int] = []  # ros2 topic echo prints "A message was lost!!!" on these events
        events = SubscriptionEventCallbacks(message_lost=lambda e: lost.append(e.total_count))
        echo.create_subscription(
            JointState,
            "/joint_states",
            lambda m: got.append(stamp_ns(m)),
            qos,
            event_callbacks=events,
        )

        def tick_and_spin() -> None:
            dev.on_wakeup(time.monotonic())
            ex.spin_once(0.01)

        assert wait_until(lambda: len(got) >= 5, 30, step=tick_and_spin)
        assert got[0] >= joined_k * dev.device.period_ns, (got[:5], joined_k)
        assert not lost, f"{lost[-1]} messages reported lost"
    finally:
        ex.shutdown()
        echo.destroy_node()
        dev.destroy_node()
        rclpy.try_shutdown(context=ctx)


@pytest.mark.parametrize(
    ("cls", "topic", "default"),
    [
        (DeviceNode, "/effort_command", "reliable"),
        (EnvironmentNode, "/ee_pose", "best_effort"),
        (ControllerNode, "/wrench_desired", "best_effort"),
    ],
    ids=lambda x: getattr(x, "__name__", x),
)
@pytest.mark.parametrize("asked", [None, "reliable", "best_effort"])
def test_the_command_input_is_reliable_and_sensor_streams_best_effort(
    monkeypatch, cls, topic, default, asked
) -> None:
    """A one-off ``ros2 topic pub --once`` to the device's command input must arrive: it is
    reliable, as ``ros2 topic info -v`` shows; the sensor streams are best effort (ROS 2's
    sensor-data convention, faster between processes); ``input_reliability`` chooses."""
    from rclpy.qos import ReliabilityPolicy

    monkeypatch.setenv("ROS_DOMAIN_ID", isolated_env()["ROS_DOMAIN_ID"])
    ctx = Context()
    args = [] if asked is None else ["--ros-args", "-p", f"input_reliability:={asked}"]
    rclpy.init(context=ctx, args=args)
    node = cls(context=ctx)
    try:

        def reliabilities() -> set[ReliabilityPolicy]:
            infos = node.get_subscriptions_info_by_topic(topic)
            return {i.qos_profile.reliability for i in infos if i.node_name == node.get_name()}

        assert wait_until(reliabilities, 10)
        policy = {
            "reliable": ReliabilityPolicy.RELIABLE,
            "best_effort": ReliabilityPolicy.BEST_EFFORT,
        }
        assert reliabilities() == {policy[asked or default]}
    finally:
        node.destroy_node()
        rclpy.try_shutdown(context=ctx)


@pytest.mark.parametrize("token", ["4111751691456e08", "0123", "1e5", "true"])
def test_a_number_like_token_in_the_launch_params_file_reaches_the_node_as_text(
    token: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """rcl types an unquoted scalar by its look: the launcher's file quotes its strings."""
    path = write_params_file({"controller_node": {"command_token": token}}, tmp_path)
    monkeypatch.setenv("ROS_DOMAIN_ID", isolated_env()["ROS_DOMAIN_ID"])
    ctx = Context()
    rclpy.init(context=ctx, args=["--ros-args", "--params-file", str(path)])
    try:
        node = ControllerNode(context=ctx)
        try:
            assert node.get_parameter("command_token").value == token
        finally:
            node.destroy_node()
    finally:
        rclpy.try_shutdown(context=ctx)
