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
        "launch.substitutions": subs,
        "launch_ros": ros,
        "launch_ros.actions": ros_actions,
    }.items():
        monkeypatch.setitem(sys.modules, name, mod)


def _plan(monkeypatch, **launch_args: str) -> list:
    path = Path(get_package_share_directory("haptic_dob")) / "launch" / "session.launch.py"
    assert path.is_file()
    _stub_modules(monkeypatch, {"config": "slide_sim", "namespace": "slide1", **launch_args})
    spec = importlib.util.spec_from_file_location("session_launch", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    ld = module.generate_launch_description()
    opaque = ld.args[0][-1]
    return opaque.kwargs["function"](context=None)


def test_launch_file_is_installed_and_plans_the_session(monkeypatch) -> None:
    nodes = _plan(monkeypatch, composed="false")
    planned = [(n.kwargs["package"], n.kwargs["executable"], n.kwargs["namespace"]) for n in nodes]
    assert planned == [
        ("haptic_dob", "environment_node", "slide1"),
        ("haptic_dob", "observer_node", "slide1"),
        ("haptic_dob", "controller_node", "slide1"),
        ("haptic_sim", "device_node", "slide1"),
    ]
    device = nodes[-1].kwargs["parameters"][0]
    assert device["clock_mode"] == "lockstep" and device["rate_hz"] == 1000.0
    assert device["hand.behaviour"] == "semi_random"
    for n in nodes:  # every process is required: its end shuts the launch down
        assert type(n.kwargs["on_exit"]).__name__ == "_Recorder", n.kwargs
        assert "ended" in n.kwargs["on_exit"].kwargs["reason"]
    for pkg, exe, _ in planned:
        shim = Path(get_package_share_directory(pkg)).parents[1] / "lib" / pkg / exe
        assert shim.is_file(), shim


def test_launch_file_composes_the_loop_by_default(monkeypatch) -> None:
    """As haptic-launch: the loop's nodes in the container, with a params file by node name."""
    import yaml

    (node,) = _plan(monkeypatch, composed="true")
    assert (node.kwargs["package"], node.kwargs["executable"]) == ("haptic_dob", "container")
    assert node.kwargs["arguments"] == [
        "environment_node",
        "observer_node",
        "controller_node",
        "device_node",
    ]
    assert node.kwargs["namespace"] == "slide1" and "name" not in node.kwargs
    assert "device_node" in node.kwargs["on_exit"].kwargs["reason"]
    (params_file,) = node.kwargs["parameters"]
    doc = yaml.safe_load(Path(params_file).read_text())
    assert doc["/**/device_node"]["ros__parameters"]["clock_mode"] == "lockstep"
    assert doc["/**/environment_node"]["ros__parameters"]["stiffness_n_per_m"] == 800.0
    shim = Path(get_package_share_directory("haptic_dob")).parents[1] / "lib" / "haptic_dob"
    assert (shim / "container").is_file()
