"""Parameters driven the way ``ros2 param`` drives them: rclpy's own parameter client, over the
node's parameter services. Declared types hold: a refused value changes neither the value nor
the described type, an integer given for a double is stored as a double (at start-up too)."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest
import rclpy
from rcl_interfaces.msg import ParameterType
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient

from haptic_dob.nodes.controller_node import ControllerNode
from haptic_sim.nodes.device_node import DeviceNode
from support.rosgraph import isolated_env
from support.waits import wait_until


@pytest.fixture
def context(monkeypatch: pytest.MonkeyPatch) -> Iterator[Context]:
    env = isolated_env()
    monkeypatch.setenv("ROS_DOMAIN_ID", env["ROS_DOMAIN_ID"])
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    ctx = Context()
    rclpy.init(context=ctx, args=["--ros-args", "-p", "kf:=25", "-p", "effort_limits:=[3]"])
    yield ctx
    rclpy.try_shutdown(context=ctx)


class Cli:
    """``ros2 param`` in a few lines: an AsyncParameterClient on its own node, spun with the
    target node in one executor."""

    def __init__(self, context: Context, target: Any) -> None:
        self.node = rclpy.create_node("param_cli", context=context)
        self.ex = SingleThreadedExecutor(context=context)
        self.ex.add_node(target)
        self.ex.add_node(self.node)
        self.client = AsyncParameterClient(self.node, target.get_fully_qualified_name())
        assert self.client.wait_for_services(timeout_sec=30.0), "parameter services not found"

    def call(self, future: Any) -> Any:
        # a hang guard, not a timing bound
        wait_until(future.done, 30.0, step=lambda: self.ex.spin_once(timeout_sec=0.1))
        assert future.done(), "no answer from the parameter service"
        return future.result()

    def set(self, name: str, value: Any) -> Any:
        return self.call(self.client.set_parameters([Parameter(name, value=value)])).results[0]

    def get(self, name: str) -> Any:
        return self.call(self.client.get_parameters([name])).values[0]

    def describe(self, name: str) -> Any:
        return self.call(self.client.describe_parameters([name])).descriptors[0]

    def close(self) -> None:
        self.ex.shutdown()
        self.node.destroy_node()


def test_declared_types_hold_through_the_parameter_services(context: Context) -> None:
    ctl = ControllerNode(context=context)
    cli = Cli(context, ctl)
    try:
        # -p kf:=25 is an integer on the command line: taken as the double it is declared as
        got = cli.get("kf")
        assert (got.type, got.double_value) == (ParameterType.PARAMETER_DOUBLE, 25.0)
        assert ctl.controller.law.kf == 25.0
        law = ctl.controller.law
        res = cli.set("kf", "abc")
        assert not res.successful and "type" in res.reason.lower(), res.reason
        assert cli.describe("kf").type == ParameterType.PARAMETER_DOUBLE
        assert cli.get("kf").double_value == 25.0 and ctl.controller.law is law
        res = cli.set("kf", 1)  # ros2 param set /controller_node kf 1
        assert res.successful, res.reason
        got = cli.get("kf")
        assert (got.type, got.double_value) == (ParameterType.PARAMETER_DOUBLE, 1.0)
        assert ctl.controller.law.kf == 1.0
        assert cli.describe("kf").type == ParameterType.PARAMETER_DOUBLE
        res = cli.set("mode", 3)  # a number for a string: refused, type and value kept
        assert not res.successful
        assert cli.describe("mode").type == ParameterType.PARAMETER_STRING
        assert cli.get("mode").string_value == "OL"
    finally:
        cli.close()
        ctl.destroy_node()


def test_arrays_are_typed_also_when_empty(context: Context) -> None:
    dev = DeviceNode(context=context)
    cli = Cli(context, dev)
    try:
        got = cli.get("effort_limits")  # -p effort_limits:=[3]: integers, declared doubles
        assert got.type == ParameterType.PARAMETER_DOUBLE_ARRAY
        assert list(got.double_array_value) == [3.0] and dev.limits == (3.0,)
        got = cli.get("cpu_affinity")  # default [] (rclpy alone would make it a byte array)
        assert got.type == ParameterType.PARAMETER_INTEGER_ARRAY
        assert list(got.integer_array_value) == []
        assert cli.describe("arm.initial_position").type == ParameterType.PARAMETER_DOUBLE_ARRAY
        res = cli.set("effort_limits", [2])
        assert res.successful, res.reason
        assert dev.limits == (2.0,)
        res = cli.set("effort_limits", ["a"])
        assert not res.successful and dev.limits == (2.0,)
        assert cli.describe("effort_limits").type == ParameterType.PARAMETER_DOUBLE_ARRAY
    finally:
        cli.close()
        dev.destroy_node()


@pytest.mark.parametrize("config", ["slide_sim.yaml", "phantom_sim.yaml"])
@pytest.mark.parametrize("namespace", ["/", "/slide1", "/lab/station2"])
def test_the_config_files_apply_in_any_namespace(monkeypatch, config: str, namespace: str) -> None:
    """``ros2 run ... --ros-args -r __ns:=/slide1 --params-file config/...``: every node
    section still applies (its keys are ``/**/<node>``)."""
    from pathlib import Path

    from haptic_dob.nodes.controller_node import ControllerNode
    from haptic_dob.nodes.environment_node import EnvironmentNode
    from haptic_dob.nodes.observer_node import ObserverNode
    from haptic_dob.runtime.params import load_node_params, node_view

    path = Path(__file__).resolve().parents[2] / "config" / config
    sections = load_node_params(path)
    monkeypatch.setenv("ROS_DOMAIN_ID", isolated_env()["ROS_DOMAIN_ID"])
    ctx = Context()
    rclpy.init(
        context=ctx, args=["--ros-args", "-r", f"__ns:={namespace}", "--params-file", str(path)]
    )
    try:
        for cls in (DeviceNode, EnvironmentNode, ObserverNode, ControllerNode):
            node = cls(context=ctx)
            try:
                assert node.get_namespace() == namespace
                own = sections.get(node.get_name(), {})
                assert own, f"{config} has no section for {node.get_name()}"
                for name, value in node_view(sections, node.get_name()).items():
                    if name not in own and not node.has_parameter(name):
                        continue  # a /** value for other nodes
                    got = node.get_parameter(name).value
                    if isinstance(value, str):
                        assert got == value, (node.get_name(), name)
                    else:
                        assert got == pytest.approx(value), (node.get_name(), name, got, value)
            finally:
                node.destroy_node()
    finally:
        rclpy.try_shutdown(context=ctx)
