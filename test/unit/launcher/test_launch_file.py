"""The ros2 launch file: installed, and it plans the same nodes as haptic-launch.

The ROS 2 command line (launch, launch_ros) is not installed here; the test gives the file
minimal stand-ins for those modules and checks what it asks launch_ros to start.
"""

from __future__ import annotations

import importlib.util
import sys
import types
from pathlib import Path

from ament_index_python.packages import get_package_share_directory


class _Recorder:
    """Stand-in launch classes that remember their arguments."""

    def __init__(self, *args, **kwargs) -> None:
        self.args, self.kwargs = args, kwargs


def _stub_modules(monkeypatch, launch_args: dict[str, str]) -> None:
    launch = types.ModuleType("launch")
    launch.LaunchDescription = _Recorder
    actions = types.ModuleType("launch.actions")
    actions.DeclareLaunchArgument = _Recorder
    actions.OpaqueFunction = _Recorder
    actions.Shutdown = _Recorder
    actions.RegisterEventHandler = _Recorder
    handlers = types.ModuleType("launch.event_handlers")
    handlers.OnShutdown = _Recorder
    subs = types.ModuleType("launch.substitutions")

    class LaunchConfiguration:
        def __init__(self, name: str) -> None:
            self.name = name

        def perform(self, context) -> str:
            return launch_args[self.name]

    subs.LaunchConfiguration = LaunchConfiguration
    ros = types.ModuleType("launch_ros")
    ros_actions = types.ModuleType("launch_ros.actions")
    ros_actions.Node = _Recorder
    for name, mod in {
        "launch": launch,
        "launch.actions": actions,
        "launch.event_handlers": handlers,
        "launch.substitutions": subs,
        "launch_ros": ros,
        "launch_ros.actions": ros_actions,
    }.items():
        monkeypatch.setitem(sys.modules, name, mod)


def _plan(monkeypatch, **launch_args: str) -> tuple[list, dict]:
    """The processes the launch file asks for, and the params file they share (read before the
    launch's shutdown removes it)."""
    import yaml

    path = Path(get_package_share_directory("haptic_dob")) / "launch" / "session.launch.py"
    assert path.is_file()
    _stub_modules(monkeypatch, {"config": "slide_sim", "namespace": "slide1", **launch_args})
    spec = importlib.util.spec_from_file_location("session_launch", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    ld = module.generate_launch_description()
    opaque = ld.args[0][-1]
    cleanup, *nodes = opaque.kwargs["function"](context=None)
    # the params file's folder goes when the launch shuts down
    (on_shutdown,) = cleanup.args
    params_file = Path(nodes[0].kwargs["parameters"][0])
    doc = yaml.safe_load(params_file.read_text())
    on_shutdown.kwargs["on_shutdown"](None, None)
    assert not params_file.parent.exists()
    return nodes, doc


def _ends_graph_once(node) -> str:
    """The process's on_exit shuts the launch down, unless it is already shutting down; the
    reason it gives."""
    on_exit = node.kwargs["on_exit"]
    assert on_exit(None, types.SimpleNamespace(is_shutdown=True)) is None
    action = on_exit(None, types.SimpleNamespace(is_shutdown=False))
    assert type(action).__name__ == "_Recorder"
    return action.kwargs["reason"]


def test_launch_file_is_installed_and_plans_the_session(monkeypatch) -> None:
    nodes, doc = _plan(monkeypatch, composed="false")
    planned = [(n.kwargs["package"], n.kwargs["executable"], n.kwargs["namespace"]) for n in nodes]
    assert planned == [
        ("haptic_dob", "environment_node", "slide1"),
        ("haptic_dob", "observer_node", "slide1"),
        ("haptic_dob", "controller_node", "slide1"),
        ("haptic_sim", "device_node", "slide1"),
    ]
    assert [n.kwargs["name"] for n in nodes] == [
        "environment_node",
        "observer_node",
        "controller_node",
        "device_node",
    ]
    assert len({n.kwargs["parameters"][0] for n in nodes}) == 1  # one params file ...
    device = doc["/**/device_node"]["ros__parameters"]  # ... that any namespace matches
    assert device["clock_mode"] == "lockstep" and doc["/**"]["ros__parameters"]["rate_hz"] == 1000
    assert device["hand.behaviour"] == "semi_random"
    for n in nodes:  # every process is required: its end shuts the launch down
        assert "ended" in _ends_graph_once(n)
    for pkg, exe, _ in planned:
        shim = Path(get_package_share_directory(pkg)).parents[1] / "lib" / pkg / exe
        assert shim.is_file(), shim


def test_launch_file_composes_the_loop_by_default(monkeypatch) -> None:
    """As haptic-launch: the loop's nodes in the container, with a params file by node name."""
    (node,), doc = _plan(monkeypatch, composed="true")
    assert (node.kwargs["package"], node.kwargs["executable"]) == ("haptic_dob", "container")
    assert node.kwargs["arguments"] == [
        "environment_node",
        "observer_node",
        "controller_node",
        "device_node",
    ]
    assert node.kwargs["namespace"] == "slide1" and "name" not in node.kwargs
    assert "device_node" in _ends_graph_once(node)
    (params_file,) = node.kwargs["parameters"]
    assert params_file.endswith("params.yaml")
    assert doc["/**/device_node"]["ros__parameters"]["clock_mode"] == "lockstep"
    assert doc["/**/environment_node"]["ros__parameters"]["stiffness_n_per_m"] == 800.0
    shim = Path(get_package_share_directory("haptic_dob")).parents[1] / "lib" / "haptic_dob"
    assert (shim / "container").is_file()
