"""The ROS command line's parameters in rcl's order: which -p a section shadows, which nodes a
params file names."""

from __future__ import annotations

from pathlib import Path

from haptic_dob.nodes.registry import NODES
from haptic_dob.runtime.ros_args import (
    ParamRule,
    configured_nodes,
    parse_rule,
    shadow_line,
    shadowed,
)

SECTIONS = """\
/**:
  ros__parameters:
    rate_hz: 1000.0
/**/device_node:
  ros__parameters:
    clock_mode: lockstep
    duration_s: 5.0
"""

NO_COMMON = """\
/**/device_node:
  ros__parameters:
    clock_mode: lockstep
"""


def write(tmp_path: Path, text: str, name: str = "p.yaml") -> str:
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def test_a_rule_is_read_as_rcl_reads_it() -> None:
    assert parse_rule("kf:=25") == ParamRule("/**", "kf", "25")
    assert parse_rule("controller_node:kf:=25") == ParamRule("controller_node", "kf", "25")
    assert parse_rule("kf=25") is None and parse_rule("/ns/node:kf:=1") is None


def test_a_bare_p_after_a_file_with_a_common_section_loses_to_the_node_section(tmp_path) -> None:
    """The -p joins the file's earlier /** entry; the node's entry comes later and wins. A value
    no section sets (rate_hz replaces the /** entry's own) is the node's."""
    f = write(tmp_path, SECTIONS)
    argv = ["dev", "--ros-args", "--params-file", f, "-p", "clock_mode:=realtime", "-p",
            "rate_hz:=500.0", "-p", "device_node:duration_s:=2.0"]  # fmt: skip
    found = shadowed(argv, "/device_node")
    assert [(s.rule.text, s.section, s.source, s.value) for s in found] == [
        ("-p clock_mode:=realtime", "/**/device_node", f, "lockstep")
    ]
    assert shadowed(argv, "/controller_node") == []
    line = shadow_line(found, "/device_node")
    assert "ignored -p clock_mode:=realtime (the /**/device_node section of" in line
    assert line.endswith("type -p device_node:clock_mode:=realtime after the last --params-file")


def test_the_order_decides_without_a_common_section(tmp_path) -> None:
    """Without a /** section in the file, a bare -p after it is an entry of its own, later: it
    wins; before it, the file's section wins. A node-qualified -p before the file loses too."""
    f = write(tmp_path, NO_COMMON)
    assert shadowed(["d", "--ros-args", "--params-file", f, "-p", "clock_mode:=realtime"],
                    "/device_node") == []  # fmt: skip
    before = shadowed(["d", "--ros-args", "-p", "clock_mode:=realtime", "--params-file", f],
                      "/device_node")  # fmt: skip
    qualified = shadowed(
        ["d", "--ros-args", "-p", "device_node:clock_mode:=realtime", "--params-file", f],
        "/device_node",
    )
    assert [s.rule.name for s in before] == ["clock_mode"] == [s.rule.name for s in qualified]


def test_in_a_namespace_the_advice_is_a_second_file(tmp_path) -> None:
    f = write(tmp_path, SECTIONS)
    argv = [
        "d",
        "--ros-args",
        "-r",
        "__ns:=/slide1",
        "--params-file",
        f,
        "-p",
        "clock_mode:=realtime",
    ]
    line = shadow_line(shadowed(argv, "/slide1/device_node"), "/slide1/device_node")
    assert "second --params-file" in line and "/slide1/device_node: {ros__parameters:" in line
    # a node-qualified -p names the root namespace's node only: nothing of it reaches /slide1
    qualified = ["d", "--ros-args", "--params-file", f, "-p", "device_node:clock_mode:=realtime"]
    assert shadowed(qualified, "/slide1/device_node") == []


def test_the_nodes_a_params_file_names(root) -> None:
    known = [n for n in NODES if n != "recorder_node"]
    slide = ["--ros-args", "--params-file", str(root / "config" / "slide_sim.yaml")]
    assert sorted(configured_nodes(slide, known)) == sorted(
        ["device_node", "environment_node", "observer_node", "controller_node"]
    )
    teleop = configured_nodes(
        ["--ros-args", "--params-file", str(root / "config" / "teleop_sim.yaml")], known
    )
    assert "device_node" not in teleop and {"master/device_node", "slave/device_node"} <= set(
        teleop
    )
    assert configured_nodes(["--ros-args", "-p", "kf:=1"], known) == []
