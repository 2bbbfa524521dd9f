"""Safety properties in-process: no bad command reaches the plant; no refused parameter acts.

Hypothesis drives the device node's command path with NaN, inf, wrong lengths and huge values, and
every node's parameter service with random names, types and values.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from rclpy.exceptions import ParameterNotDeclaredException
from rclpy.parameter import Parameter

from haptic_dob.nodes.controller_node import ControllerNode
from haptic_dob.nodes.environment_node import EnvironmentNode
from haptic_dob.nodes.observer_node import ObserverNode
from haptic_msgs_py.values import EffortCommand
from haptic_sim.nodes.device_node import DeviceNode
from support.rosgraph import private_context

SETTINGS = settings(
    max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)


@pytest.fixture(scope="module")
def context():
    with private_context(["--ros-args", "-p", "clock_mode:=realtime"]) as ctx:
        yield ctx


values = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(min_value=-10.0, max_value=10.0),
    st.sampled_from([1e300, -1e300, 4.0, -4.0, 4.0000001, 0.0]),
)
commands = st.lists(values, min_size=0, max_size=4)


@given(stream=st.lists(commands, min_size=1, max_size=30))
@SETTINGS
def test_no_bad_command_reaches_the_plant(context, stream) -> None:
    """Every applied effort is finite, within the limits, zero after a refused command."""
    dev = DeviceNode(context=context)
    try:
        dev.set_parameters([Parameter("effort_limits", value=[3.0])])
        assert dev.limits == (3.0,)
        now = 100.0
        dev.loop.tick(now)  # start: sample 0
        for cmd in stream:
            k = dev.device.k
            dev.loop.command(EffortCommand(k * dev.period_ns, tuple(cmd)))
            now += 0.001
            dev.loop.tick(now)
            applied = dev.device.sample().effort[0]
            assert math.isfinite(applied) and abs(applied) <= 3.0
            valid = len(cmd) == 1 and math.isfinite(cmd[0])
            expected = float(np.clip(cmd[0], -3.0, 3.0)) if valid else 0.0
            assert applied == expected
    finally:
        dev.destroy_node()


def test_watchdog_zeroes_the_effort_and_the_next_command_resumes(context) -> None:
    """Command 0, then silence: the command is held for ``command_timeout_s`` of samples, then
    the effort is zero and the report says why; the next valid command resumes."""
    dev = DeviceNode(context=context)
    try:
        limit = round(dev.params.values["command_timeout_s"] * 1e9 / dev.period_ns)  # samples
        t = 10.0
        dev.loop.tick(t)
        dev.loop.command(EffortCommand(0, (1.5,)))
        for _ in range(limit + 1):  # held over [1, limit + 1): the timeout after the command
            t += 0.001
            dev.loop.tick(t)
            assert dev.device.sample().effort == (1.5,) and not dev.loop.watchdog.tripped
        t += 0.001
        dev.loop.tick(t)
        assert dev.device.sample().effort == (0.0,) and dev.loop.watchdog.tripped
        _level, message, values = dev._report()
        assert "watchdog tripped" in message and values["watchdog"].startswith("tripped")
        dev.loop.command(EffortCommand(dev.device.k * dev.period_ns, (-1.0,)))
        dev.loop.tick(t + 0.001)
        assert dev.device.sample().effort == (-1.0,) and not dev.loop.watchdog.tripped
    finally:
        dev.destroy_node()


@pytest.mark.parametrize("gap_s", [0.0, 0.05], ids=["bunched", "stalled"])
def test_watchdog_counts_the_plant_s_samples_not_the_wall_clock(context, gap_s: float) -> None:
    """The simulated plant moves one sample per tick: ticks bunched in no wall time still trip
    the watchdog after ``command_timeout_s`` of samples, and a stall of the device's own process
    between two ticks (50 ms here, ten timeouts) does not."""
    dev = DeviceNode(context=context)
    try:
        limit = round(dev.params.values["command_timeout_s"] * 1e9 / dev.period_ns)  # samples
        dev.loop.tick(10.0)
        dev.loop.command(EffortCommand(0, (1.5,)))
        t = 10.0 + gap_s
        for _ in range(limit + 1):
            dev.loop.tick(t)
            assert dev.device.sample().effort == (1.5,) and not dev.loop.watchdog.tripped
        dev.loop.tick(t)
        assert dev.device.sample().effort == (0.0,) and dev.loop.watchdog.tripped
    finally:
        dev.destroy_node()


def test_effort_limits_are_checked_against_the_actuator(context) -> None:
    dev = DeviceNode(context=context)
    try:
        res = dev.set_parameters([Parameter("effort_limits", value=[5.0])])[0]
        assert not res.successful and "effort_limits[0] must be in (0, 4]" in res.reason
        res = dev.set_parameters([Parameter("effort_limits", value=[1.0, 1.0])])[0]
        assert not res.successful and "needs 1 values" in res.reason
        assert dev.limits == (4.0,)
    finally:
        dev.destroy_node()


# --- parameter fuzz ------------------------------------------------------------------------
any_value = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(10**6), max_value=10**6),
    st.text(max_size=12),
    st.booleans(),
    st.lists(st.floats(allow_nan=True, allow_infinity=True), max_size=4),
    st.lists(st.text(max_size=6), min_size=1, max_size=3),
    st.sampled_from(["OL", "CL", "DOB", "zero", "slide", "lockstep", "realtime"]),
)


def fingerprint(node) -> tuple:
    """What the node's behaviour depends on, for checking that a refusal changed nothing."""
    table = dict(node.params.values)
    if isinstance(node, ControllerNode):
        return (
            table,
            node.controller.law,
            node.controller.command([0.0], (-1.0, 0.0, 0.0), (0.5, 0.0, 0.0), (0.8, 0.0, 0.0)),
        )
    if isinstance(node, EnvironmentNode):
        return (table, node.wall, node.wall.force((0.001, 0, 0), (0.1, 0, 0)))
    if isinstance(node, ObserverNode):
        return (
            table,
            node.observer.gain,
            None if node.observer.limit is None else tuple(node.observer.limit),
        )
    return (table, node.limits)


@pytest.mark.parametrize(
    "cls", [ControllerNode, EnvironmentNode, ObserverNode, DeviceNode], ids=lambda c: c.__name__
)
def test_parameter_fuzz_refusals_change_nothing(context, cls) -> None:
    node = cls(context=context)
    names = [*sorted(node.params.specs), "no_such_parameter"]

    @given(name=st.sampled_from(names), value=any_value)
    @SETTINGS
    def one(name: str, value) -> None:
        before = fingerprint(node)
        try:
            param = Parameter(name, value=value)
        except Exception:  # rclpy cannot even express the value: nothing to send
            return
        try:
            result = node.set_parameters([param])[0]
        except ParameterNotDeclaredException:  # the service answers "not declared"
            assert name == "no_such_parameter"
            assert fingerprint(node) == before
            return
        after = fingerprint(node)
        if not result.successful:
            assert result.reason, "a refusal carries a reason"
            assert after == before, f"refused {name}={value!r} changed the node"
        else:
            assert name in node.params.specs
            assert not node.params.specs[name].read_only

    try:
        one()
    finally:
        node.destroy_node()
