"""``ros2 run <package> <node> --help`` prints what the node does and its parameters, each with
its default, unit, range and whether it changes at run time; an argument that is not a ROS
argument gets one ERROR line and exit 2 (rclpy alone would ignore it and start the node)."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest
from ament_index_python.packages import get_package_prefix

from haptic_dob.nodes.common import usage
from haptic_dob.nodes.controller_node import ControllerNode, controller_node_specs

NODES = [
    ("haptic_sim", "device_node"),
    ("haptic_dob", "environment_node"),
    ("haptic_dob", "observer_node"),
    ("haptic_dob", "controller_node"),
    ("haptic_dob", "channel_node"),
    ("haptic_dob", "slave_controller_node"),
    ("haptic_dob", "recorder_node"),
    ("haptic_dob", "bridge_node"),
]


def run(package: str, name: str, *args: str) -> subprocess.CompletedProcess[str]:
    exe = Path(get_package_prefix(package)) / "lib" / package / name
    return subprocess.run([str(exe), *args], capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize(("package", "name"), NODES, ids=[n for _, n in NODES])
def test_help_prints_the_usage_and_every_parameter(package: str, name: str) -> None:
    out = run(package, name, "--help")
    assert out.returncode == 0, out.stderr
    assert out.stdout.startswith(f"usage: ros2 run {package} {name} [--ros-args"), out.stdout
    assert "rate_hz" in out.stdout or name == "recorder_node"
    assert "Traceback" not in out.stderr


def test_the_controller_help_shows_defaults_units_ranges_and_when_each_changes() -> None:
    text = usage(ControllerNode, controller_node_specs())
    assert "  mode = 'OL', one of OL | CL | DOB, at run time\n      control law" in text
    assert "  max_force_n = 4.0 N, in [0.001, 1000], at run time" in text
    assert "  rate_hz = 1000.0 Hz, in [1, 100000], at start-up" in text
    names = [s.name for s in controller_node_specs()]
    listed = [
        line.split(" = ")[0].strip()
        for line in text.splitlines()
        if line.startswith("  ") and not line.startswith("   ")
    ]
    assert listed == names


# mode:=DOB: rclpy would drop it as a deprecated remap rule and start the node in OL
@pytest.mark.parametrize("stray", ["kf:=25", "mode:=DOB", "--mode", "DOB"])
def test_a_stray_argument_gets_one_line_and_exit_2(stray: str) -> None:
    out = run("haptic_dob", "controller_node", stray, "--ros-args", "-p", "kf:=1.0")
    assert out.returncode == 2
    assert out.stderr.strip().splitlines() == [
        f"ERROR: unexpected argument {stray!r}: parameters go after --ros-args "
        "(-p NAME:=VALUE or --params-file FILE); --help lists them"
    ]


def test_an_argument_after_the_ros_arguments_end_is_the_nodes_own() -> None:
    out = run("haptic_dob", "controller_node", "--ros-args", "-p", "kf:=1.0", "--", "--help")
    assert out.returncode == 0 and out.stdout.startswith("usage: ros2 run haptic_dob")


def test_bad_ros_arguments_get_one_line_and_exit_2(tmp_path: Path) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text("a: [\n")
    out = run("haptic_dob", "controller_node", "--ros-args", "--params-file", str(bad))
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert [line for line in out.stderr.splitlines() if line.startswith("ERROR: ")], out.stderr
    out = run("haptic_dob", "controller_node", "--ros-args", "--help")
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert (
        out.stderr.strip()
        .splitlines()[-1]
        .startswith("ERROR: unknown ROS argument(s) '--help': after --ros-args come -p NAME:=VALUE")
    ), out.stderr
