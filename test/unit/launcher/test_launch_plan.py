"""haptic-launch's plan: the nodes' parameter table (config, ``--set``, ``--record``, ``--pin``),
which nodes share a process, and each process's command line. No process starts."""

from __future__ import annotations

from pathlib import Path

import pytest

from haptic_dob.errors import InputError
from haptic_dob.launcher.node_params import (
    add_command_tokens,
    add_pinning,
    add_recorder,
    resolved_params,
    write_params_file,
)
from haptic_dob.launcher.process_plan import (
    check_pinnable,
    executable,
    groups_for,
    plan,
    select,
)
from haptic_dob.runtime import cpus
from haptic_dob.runtime.params import load_node_params

LOOP = ["environment_node", "observer_node", "controller_node", "device_node"]
ALL = ["recorder_node", *LOOP]


def test_the_loop_shares_a_process_by_default_and_a_recorder_runs_apart(root, tmp_path) -> None:
    params = resolved_params(root / "config" / "slide_sim.yaml", {})
    add_recorder(params, str(tmp_path / "bag"), "mcap")
    names = [n for n in params if n != "/**"]
    specs = plan(params, tmp_path / "p.yaml", "/ns", groups_for(names, False, False, ()))
    assert [s.nodes for s in specs] == [["recorder_node"], LOOP]
    assert [s.off_path for s in specs] == [True, False]  # the recorder leaves --rt-priority
    station = specs[1]
    assert Path(station.executable).parts[-3:] == ("lib", "haptic_dob", "container")
    assert station.args[:4] == LOOP and "__ns:=/ns" in station.args
    assert not any(a.startswith("__node:=") for a in station.args)  # the nodes keep their names
    assert station.label == "the process of " + ", ".join(LOOP)
    alone = plan(params, tmp_path / "p.yaml", "", groups_for(names, False, True, ()))
    assert [s.nodes for s in alone] == [[n] for n in ALL]
    assert all(f"__node:={s.name}" in s.args for s in alone)
    pairs = groups_for(names, False, False, ["device_node,controller_node"])
    assert [s.nodes for s in plan(params, tmp_path / "p.yaml", "", pairs)] == [
        ["recorder_node"],
        ["environment_node"],
        ["observer_node"],
        ["controller_node", "device_node"],
    ]
    everything = plan(params, tmp_path / "p.yaml", "", groups_for(names, True, False, ()))
    assert [s.nodes for s in everything] == [ALL]
    assert not everything[0].off_path  # a recorder sharing the loop's process runs as the loop


def test_a_node_alone_runs_its_own_executable_with_the_params_file(tmp_path) -> None:
    params = {"/**": {}, "device_node": {}, "observer_node": {}}
    specs = plan(params, tmp_path / "p.yaml", "/lab/a")
    assert [s.name for s in specs] == ["observer_node", "device_node"]  # the device's last
    device = specs[1]
    assert Path(device.executable).parts[-3:] == ("lib", "haptic_sim", "device_node")
    assert device.args == [
        "--ros-args",
        "--params-file",
        str(tmp_path / "p.yaml"),
        "-r",
        "__ns:=/lab/a",
        "-r",
        "__node:=device_node",
    ]
    assert device.label == "device_node"


def test_a_group_of_one_started_node_is_no_group(tmp_path) -> None:
    params = {"device_node": {}, "observer_node": {}}
    specs = plan(params, tmp_path / "p.yaml", "", [["device_node", "controller_node"]])
    assert [s.nodes for s in specs] == [["observer_node"], ["device_node"]]


def test_a_config_without_nodes_is_refused(tmp_path) -> None:
    with pytest.raises(InputError, match="the config starts no nodes"):
        plan({"/**": {"rate_hz": 1000.0}}, tmp_path / "p.yaml", "")


def test_an_executable_not_installed_is_one_error() -> None:
    with pytest.raises(InputError, match="package no_such_pkg is not in the ament index"):
        executable("no_such_pkg", "node")
    with pytest.raises(InputError, match="no_such_exe is missing or not executable; reinstall"):
        executable("haptic_dob", "no_such_exe")


def test_groups_follow_the_choice() -> None:
    assert groups_for(ALL, False, False, ()) == [
        ["device_node", "environment_node", "observer_node", "controller_node"]
    ]
    assert groups_for(["recorder_node", "device_node"], False, False, ()) == [["device_node"]]
    assert groups_for(ALL, True, False, ()) == [ALL]
    assert groups_for(ALL, False, True, ()) == []
    given = ["device_node,controller_node", "observer_node,,recorder_node"]
    assert groups_for(LOOP, False, False, given) == [
        ["device_node", "controller_node"],
        ["observer_node"],  # a named node the launch does not start is left out
    ]


@pytest.mark.parametrize(
    ("composed", "processes", "given", "message"),
    [
        (True, True, (), "--composed, --processes and --group are different choices"),
        (True, False, ("device_node",), "--composed, --processes and --group are different"),
        (False, False, ("device_node,pilot_node",), r"--group names unknown node\(s\) pilot_node"),
        (False, False, ("device_node,device_node",), "--group: device_node,"),
        (
            False,
            False,
            ("device_node,controller_node", "device_node"),
            "--group: device_node named in more than one place",
        ),
    ],
)
def test_contradicting_groups_are_refused(composed, processes, given, message: str) -> None:
    with pytest.raises(InputError, match=message):
        groups_for(ALL, composed, processes, given)


def test_only_selects_nodes_the_config_starts() -> None:
    assert select(LOOP, ()) == LOOP
    assert select(LOOP, ("device_node", "observer_node")) == ["observer_node", "device_node"]
    with pytest.raises(InputError, match=r"--only names pilot_node, which the config does not"):
        select(LOOP, ("pilot_node",))


def test_pinning_needs_a_process_per_node() -> None:
    check_pinnable([])
    check_pinnable([["device_node"]])
    with pytest.raises(InputError, match="--pin places node processes on CPUs, and device_node, "):
        check_pinnable([["device_node", "controller_node"]])


def test_sets_override_the_config(root) -> None:
    params = resolved_params(
        root / "config" / "slide_sim.yaml",
        {"controller_node": {"kf": 2.0}, "recorder_node": {"output": "b"}},
    )
    assert params["controller_node"]["kf"] == 2.0
    assert params["recorder_node"] == {"output": "b"}  # a node the config does not start
    assert params["/**"]["slide.mass_kg"] == pytest.approx(0.4193)  # flattened


def test_a_config_naming_an_unknown_node_is_refused(tmp_path) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text("pilot_node:\n  ros__parameters: {kf: 1}\n")
    with pytest.raises(InputError, match=r"names unknown node\(s\) pilot_node; known: "):
        resolved_params(bad, {})


def test_a_recorder_is_added_and_waited_for(tmp_path) -> None:
    params: dict = {"device_node": {"wait_for": ["controller_node"]}}
    add_recorder(params, str(tmp_path / "bag"), "sqlite3")
    assert params["recorder_node"] == {"output": str(tmp_path / "bag"), "storage": "sqlite3"}
    assert params["device_node"]["wait_for"] == ["controller_node", "recorder_node"]
    bare: dict = {}
    add_recorder(bare, str(tmp_path / "bag"), "mcap")
    assert bare["device_node"]["wait_for"] == [
        "environment_node",
        "observer_node",
        "controller_node",
        "recorder_node",
    ]
    (tmp_path / "bag").mkdir()
    with pytest.raises(InputError, match="it exists already; the recorder never overwrites a bag"):
        add_recorder({}, str(tmp_path / "bag"), "mcap")


def test_a_device_and_its_controller_started_together_share_a_fresh_token() -> None:
    params: dict = {"/**": {}, "device_node": {}, "controller_node": {}}
    lines = add_command_tokens(params, LOOP)
    token = params["device_node"]["command_token"]
    assert len(token) == 16 and params["controller_node"]["command_token"] == token
    assert lines == [
        "device_node takes effort_command only from controller_node, by this launch's command token"
    ]
    again: dict = {"device_node": {}, "controller_node": {}}
    add_command_tokens(again, LOOP)
    assert again["device_node"]["command_token"] != token  # fresh at every launch
    assert "command_token" not in params["/**"]


def test_no_token_is_written_where_one_was_given_or_the_controller_starts_elsewhere() -> None:
    given = {"/**": {"command_token": "shared"}, "device_node": {}, "controller_node": {}}
    assert add_command_tokens(given, LOOP) == [
        "device_node takes effort_command only from controller_node, by the command_token given"
    ]
    assert "command_token" not in given["device_node"]
    split: dict = {"device_node": {}, "controller_node": {}}
    (line,) = add_command_tokens(split, ["device_node"])  # --only device_node
    assert "starts elsewhere: by its node name and GID in the graph" in line
    assert "command_token" not in split["device_node"]
    other = {"device_node": {"command_source": "/lab/pilot"}, "controller_node": {}}
    assert "only from /lab/pilot, which starts elsewhere" in add_command_tokens(other, LOOP)[0]
    opened = {"device_node": {"open_command_input": True}, "controller_node": {}}
    assert "from any publisher (open_command_input)" in add_command_tokens(opened, LOOP)[0]
    assert add_command_tokens({"controller_node": {}}, ["controller_node"]) == []  # no device


def test_the_params_file_gives_every_node_its_section(tmp_path) -> None:
    params = {"/**": {"rate_hz": 1000.0}, "device_node": {"seed": 3, "plant.max_force_n": 4.0}}
    path = write_params_file(params, tmp_path)
    assert path == tmp_path / "params.yaml"
    assert "/**/device_node:" in path.read_text(encoding="utf-8")
    assert load_node_params(path) == params


def test_pin_on_one_cpu_is_one_line(monkeypatch) -> None:
    monkeypatch.setattr(cpus, "available_cpus", lambda: [0])
    with pytest.raises(InputError, match="--pin: pinning needs at least 2 CPUs"):
        add_pinning({"device_node": {}, "controller_node": {}})


def test_pin_keeps_an_affinity_the_config_gives(monkeypatch) -> None:
    monkeypatch.setattr(cpus, "available_cpus", lambda: [0, 1])
    params = {"/**": {}, "device_node": {"cpu_affinity": [1]}, "environment_node": {}}
    assert "device_node: 1" in add_pinning(params)
    assert params["device_node"]["cpu_affinity"] == [1]
    assert params["environment_node"]["cpu_affinity"] and "cpu_affinity" not in params["/**"]
    common = {"/**": {"cpu_affinity": [0]}, "device_node": {}, "observer_node": {}}
    assert add_pinning(common) == "device_node: 0, observer_node: 0"  # every node's, kept
    assert "cpu_affinity" not in common["device_node"]


def test_pin_places_the_loop_pairs_on_cpus(monkeypatch) -> None:
    monkeypatch.setattr(cpus, "available_cpus", lambda: [2, 3])
    params: dict = {"/**": {}, "recorder_node": {}, **{n: {} for n in LOOP}}
    assert add_pinning(params) == (
        "device_node: 2, controller_node: 2, environment_node: 3, observer_node: 3"
    )
    assert params["observer_node"]["cpu_affinity"] == [3]
    assert "cpu_affinity" not in params["recorder_node"]


@pytest.mark.parametrize("given", [1, "0", True])
def test_pin_refuses_a_cpu_affinity_that_is_no_list(monkeypatch, given) -> None:
    monkeypatch.setattr(cpus, "available_cpus", lambda: [0, 1])
    with pytest.raises(InputError, match="cpu_affinity of device_node must be a list of CPU"):
        add_pinning({"device_node": {"cpu_affinity": given}})
