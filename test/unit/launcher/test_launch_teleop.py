"""haptic-launch of a teleoperation YAML: each node's parameters, --set, the process plan (each
side's nodes in a process by default, --composed, --processes, --group, --only) and the options a
single loop's launch has that a teleoperation graph refuses."""

from __future__ import annotations

import sys
import time

import pytest
import yaml

from haptic_dob.errors import InputError
from haptic_dob.launcher.node_params import add_command_tokens
from haptic_dob.launcher.options import LaunchOptions
from haptic_dob.launcher.process_plan import ProcessSpec
from haptic_dob.launcher.supervise import launch
from haptic_dob.launcher.teleop import (
    add_teleop_recorder,
    endless_devices,
    select_nodes,
    teleop_command,
    teleop_groups,
    teleop_params,
    teleop_plan,
    write_teleop_params,
)
from haptic_dob.teleop.graph import RECORDER, load_teleop_sections


@pytest.fixture
def sections(root):
    return load_teleop_sections(root / "config" / "teleop_sim.yaml")


def test_each_node_gets_its_sections_from_the_general_to_the_specific(sections, root) -> None:
    params = teleop_params(sections, [])
    assert list(params)[-2:] == ["master/device_node", "slave/device_node"]  # devices last
    master, slave = params["master/device_node"], params["slave/device_node"]
    assert master["model"] == "slide" and slave["model"] == "urdf"  # /<ns>/**
    assert master["duration_s"] == slave["duration_s"] == 6.0  # /**/device_node
    assert master["rate_hz"] == 1000.0  # /**
    urdf = root / "config" / "urdf"
    assert slave["urdf_path"] == str(urdf / "arm7_truth.urdf")  # beside the YAML
    assert params["slave/observer_node"]["urdf_path"] == str(urdf / "arm7_identified.urdf")
    assert params["slave/slave_controller_node"]["urdf_path"] == str(urdf / "arm7.urdf")  # /<ns>/**
    assert params["master/channel_node"]["role"] == "master"
    assert params["slave/channel_node"]["channel.round_trip_delay_ms"] == 2.0


def test_each_side_takes_its_commands_from_its_own_controller_by_one_token(sections) -> None:
    params = teleop_params(sections, [])
    assert params["slave/device_node"]["command_source"] == "slave_controller_node"
    assert "command_source" not in params["master/device_node"]  # controller_node, the default
    lines = add_command_tokens(params, list(params))
    token = params["master/device_node"]["command_token"]
    for name in ("master/controller_node", "slave/device_node", "slave/slave_controller_node"):
        assert params[name]["command_token"] == token
    assert lines == [
        f"{ns}/device_node takes effort_command only from {source}, by this launch's command token"
        for ns, source in (("master", "controller_node"), ("slave", "slave_controller_node"))
    ]


def test_a_realtime_side_does_not_wait_for_its_peer_unless_told(sections) -> None:
    assert "wait_for_peer" not in teleop_params(sections, [])["master/channel_node"]  # lockstep
    params = teleop_params(sections, ["**/device_node:clock_mode=realtime"])
    assert params["master/channel_node"]["wait_for_peer"] is False
    assert params["slave/channel_node"]["wait_for_peer"] is False
    sets = ["**/device_node:clock_mode=realtime", "slave/channel_node:wait_for_peer=true"]
    assert teleop_params(sections, sets)["slave/channel_node"]["wait_for_peer"] is True


def test_set_names_one_node_or_both_sides(sections) -> None:
    params = teleop_params(
        sections, ["**/device_node:duration_s=1.5", "slave/observer_node:kind=momentum"]
    )
    assert params["master/device_node"]["duration_s"] == 1.5
    assert params["slave/device_node"]["duration_s"] == 1.5
    assert params["slave/observer_node"]["kind"] == "momentum"
    assert params["master/observer_node"].get("kind", "dob") == "dob"
    for bad in ("device_node:seed=1", "master/nosuch:x=1", "slave/device_node:seed"):
        with pytest.raises(InputError, match="--set needs NS/NODE:PARAM=VALUE"):
            teleop_params(sections, [bad])


def test_one_process_by_default_a_process_per_side_or_per_node_as_asked(sections, tmp_path) -> None:
    params = teleop_params(sections, [])
    path = write_teleop_params(params, tmp_path)
    doc = yaml.safe_load(path.read_text())
    assert set(doc) == {f"/{n}" for n in params}  # full names: no wildcard to interpret
    names = list(params)
    assert teleop_groups(names, False, False, ()) == [names]
    master, slave = teleop_plan(
        params, path, teleop_groups(names, False, False, ("master", "slave"))
    )
    assert master.nodes == [n for n in names if n.startswith("master/")]
    assert slave.nodes == [n for n in names if n.startswith("slave/")]
    assert slave.executable.endswith("container") and slave.args[:4] == slave.nodes
    (one,) = teleop_plan(params, path, teleop_groups(names, True, False, ()))
    assert one.executable.endswith("container") and one.args[: len(params)] == names
    each = teleop_plan(params, path, teleop_groups(names, False, True, ()))
    assert [s.name for s in each] == names
    dev = each[-1]
    assert dev.executable.endswith("device_node")
    assert dev.args[-4:] == ["-r", "__ns:=/slave", "-r", "__node:=device_node"]


def test_group_and_only_take_sides_or_nodes(sections, tmp_path) -> None:
    params = teleop_params(sections, [])
    names = list(params)
    path = write_teleop_params(params, tmp_path)
    groups = teleop_groups(names, False, False, ("master,slave/device_node",))
    plan = teleop_plan(params, path, groups)
    assert plan[-1].nodes == [*(n for n in names if n.startswith("master/")), "slave/device_node"]
    assert [s.nodes for s in plan[:-1]] == [
        ["slave/observer_node"],
        ["slave/slave_controller_node"],
        ["slave/channel_node"],
    ]
    assert select_nodes(names, ("slave",)) == [n for n in names if n.startswith("slave/")]
    assert select_nodes(names, ("master/device_node", "slave")) == [
        *(n for n in names if n.startswith("slave/") and n != "slave/device_node"),
        "master/device_node",
        "slave/device_node",
    ]
    for bad in (("arm",), ("device_node",), ("master/nosuch",)):
        with pytest.raises(InputError, match="give a side"):
            select_nodes(names, bad)
    with pytest.raises(InputError, match="more than one place"):
        teleop_groups(names, False, False, ("master", "master/device_node"))
    with pytest.raises(InputError, match="pick one"):
        teleop_groups(names, True, False, ("master",))


def test_only_one_side_starts_that_sides_nodes_and_refuses_record(sections, tmp_path) -> None:
    opts = LaunchOptions(config="teleop_sim", only=("slave",), record=str(tmp_path / "bag"))
    with pytest.raises(InputError, match="--record with --only"):
        teleop_command(opts, sections)


def test_record_adds_a_recorder_of_both_sides_apart_that_both_devices_wait_for(
    sections, tmp_path
) -> None:
    params = teleop_params(sections, [])
    add_teleop_recorder(params, str(tmp_path / "bag"), "mcap")
    rec = params["recorder_node"]
    assert rec["namespaces"] == ["/master", "/slave"] and rec["rate_hz"] == 1000.0
    topics = [t.partition(":")[0] for t in rec["topics"]]
    for name in ("/master/joint_states", "/slave/sim/hand_wrench", "/slave/pose_desired"):
        assert name in topics
    assert {"/teleop/to_slave", "/teleop/to_master", "/parameter_events"} <= set(topics)
    for ns in ("master", "slave"):
        assert params[f"{ns}/device_node"]["wait_for"][-1] == RECORDER
    path = write_teleop_params(params, tmp_path)
    assert "/recorder_node" in yaml.safe_load(path.read_text())
    names = [n for n in params if "/" in n]
    for composed, processes in ((False, False), (True, False), (False, True)):
        plan = teleop_plan(params, path, teleop_groups(names, composed, processes, ()))
        assert plan[0].nodes == ["recorder_node"]  # first, alone, in the root namespace
        assert [s.off_path for s in plan] == [True] + [False] * (len(plan) - 1)
        assert plan[0].executable.endswith("recorder_node") and "__ns:=" not in plan[0].args
        assert all("recorder_node" not in s.nodes for s in plan[1:])
    with pytest.raises(InputError, match="exists already"):
        add_teleop_recorder(params, str(tmp_path), "mcap")


@pytest.mark.parametrize(
    ("option", "flag"),
    [
        ({"namespace": "x"}, "--namespace"),
        ({"pin": True}, "--pin"),
    ],
)
def test_single_loop_options_are_refused(sections, option, flag) -> None:
    with pytest.raises(InputError, match=f"{flag}: not for a teleoperation graph"):
        teleop_command(LaunchOptions(config="teleop_sim", **option), sections)


def test_a_side_that_runs_until_stopped_does_not_hold_the_others_finished_run(
    sections,
) -> None:
    """``--group master --group slave`` with the master's device running until stopped
    (``duration_s`` 0) and the slave's ending its run: the slave's end stops the graph, as in
    one process (its container stops when every node that ends a run has)."""
    params = teleop_params(sections, ["master/device_node:duration_s=0"])
    assert endless_devices(params) == {"master/device_node"}
    forever = [sys.executable, "-c", "import time; time.sleep(120)"]
    ends = [sys.executable, "-c", "import time; time.sleep(0.5)"]
    specs = [
        ProcessSpec("master", ["master/device_node"], forever[0], forever[1:]),
        ProcessSpec("slave", ["slave/device_node"], ends[0], ends[1:]),
    ]
    t0 = time.monotonic()  # --duration 30 bounds a launch that would wait for the master
    assert launch(specs, 5.0, 30.0, endless=endless_devices(params)) == 0
    assert time.monotonic() - t0 < 20.0  # the slave's end stopped it, not the duration
