"""``haptic-launch`` of a teleoperation YAML: the master's and the slave's nodes in their
namespaces (``haptic_dob.teleop.graph``), all in one process by default.

A YAML with ``/master/...`` or ``/slave/...`` sections is a teleoperation graph: each node's
parameters are its sections overlaid (``node_values``), written to a params file under the
node's full name; ``--set NS/NODE:PARAM=VALUE`` overrides one node's, ``**/NODE:`` the node of
both sides. ``--composed`` (the default) runs all nodes in one container, ``--processes`` one
process each, ``--group`` names groups (``master``, ``slave`` or ``NS/NODE`` items: ``--group
master --group slave`` gives each side a process and each device a CPU; the devices'
``start_with`` starts their clocks together). ``--only`` starts the named sides or nodes (the
slave on another host, with ``--network subnet``). ``--record BAG`` adds a ``recorder_node`` in
the root namespace, in a process of its own, recording both sides' and the channel's topics
(``recorded_topics``) and snapshotting ``/master`` and ``/slave``; both devices wait for it.
``--namespace``, ``--pin`` and ``--cpu-latency`` are refused. Guide: docs/teleoperation.md.
"""

from __future__ import annotations

import sys
import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import yaml

from haptic_dob.errors import InputError
from haptic_dob.launcher.node_params import add_command_tokens
from haptic_dob.launcher.options import LaunchOptions, network_env, say_session
from haptic_dob.launcher.process_plan import ProcessSpec, executable
from haptic_dob.launcher.robot_description import fetch, fill
from haptic_dob.launcher.supervise import RUN_ENDS, launch, set_rt_priority
from haptic_dob.nodes.registry import CONTAINER, NODES
from haptic_dob.runtime.params_file import dump_params
from haptic_dob.teleop.graph import (
    NAMESPACES,
    RECORDER,
    SIDE_NODES,
    check_sections,
    device_of,
    graph_nodes,
    node_values,
    recorded_topics,
)

#: the slave device's commands come from its slave controller
SLAVE_SOURCE = "slave_controller_node"


def teleop_params(
    sections: Mapping[str, Mapping[str, Any]], sets: Sequence[str]
) -> dict[str, dict[str, Any]]:
    """``{"master/device_node": {param: value}, ...}`` for every node, ``--set`` applied; a side
    whose device runs in real time gets ``wait_for_peer: false`` on its channel end unless given
    (waiting for the peer's messages is lockstep's), and the slave's device end (its device or
    bridge) takes its commands from the slave controller unless told otherwise."""
    try:
        check_sections(sections)
    except ValueError as exc:
        raise InputError(str(exc)) from None
    out = {f"{ns}/{node}": node_values(sections, ns, node) for ns, node in graph_nodes(sections)}
    for item in sets:
        target, sep, assignment = item.partition(":")
        param, eq, text = assignment.partition("=")
        ns, _, node = target.partition("/")
        names = [f"{n}/{node}" for n in NAMESPACES] if ns == "**" else [target]
        names = [n for n in names if n in out]
        if not (sep and eq and param and names):
            raise InputError(
                f"--set needs NS/NODE:PARAM=VALUE with a node of the graph ({', '.join(out)}; "
                f"**/NODE for both sides), got {item!r}"
            )
        try:
            value = yaml.safe_load(text)
        except yaml.YAMLError:
            raise InputError(f"--set {item!r}: the value is not valid YAML") from None
        for name in names:
            out[name][param] = value
    for ns in NAMESPACES:  # a real-time side's channel end uses what has come (no lockstep wait)
        device = device_of(sections, ns)  # a bridge to a driver is real time
        if device != "device_node" or out[f"{ns}/{device}"].get("clock_mode") == "realtime":
            out[f"{ns}/channel_node"].setdefault("wait_for_peer", False)
    out[f"slave/{device_of(sections, 'slave')}"].setdefault("command_source", SLAVE_SOURCE)
    return out


def write_teleop_params(params: Mapping[str, Mapping[str, Any]], directory: Path) -> Path:
    """The params file: every node's parameters under its full name (``/master/device_node``)."""
    doc = {f"/{name}": {"ros__parameters": dict(values)} for name, values in params.items()}
    path = directory / "params.yaml"
    path.write_text(dump_params(doc), encoding="utf-8")
    return path


def add_teleop_recorder(params: dict[str, dict[str, Any]], output: str, storage: str) -> None:
    """``--record``: a recorder of both sides (``RECORDER``), and both devices waiting for it."""
    if Path(output).exists():
        raise InputError(
            f"--record {output}: it exists already; the recorder never overwrites a bag"
        )
    params[RECORDER.lstrip("/")] = {
        "output": output,
        "storage": storage,
        "topics": recorded_topics(),
        "namespaces": [f"/{ns}" for ns in NAMESPACES],
        "rate_hz": params.get("master/device_node", params.get("master/bridge_node", {})).get(
            "rate_hz", 1000.0
        ),
    }
    for ns in NAMESPACES:
        name = f"{ns}/device_node" if f"{ns}/device_node" in params else f"{ns}/bridge_node"
        device = params[name]
        default = [n for n in SIDE_NODES[ns] if n != "device_node"]
        device["wait_for"] = [*device.get("wait_for", default), RECORDER]


def _expand(item: str, names: Sequence[str], flag: str) -> list[str]:
    """A side (``master``, ``slave``) -> its nodes; ``NS/NODE`` -> itself; ``InputError`` else."""
    if item in NAMESPACES:
        return [n for n in names if n.startswith(f"{item}/")]
    if item in names:
        return [item]
    raise InputError(
        f"{flag} names {item!r}: give a side (master, slave) or a node of the graph "
        f"({', '.join(names)})"
    )


def select_nodes(names: Sequence[str], only: Sequence[str]) -> list[str]:
    """``--only``: the named sides' or nodes' (all when empty), in start order."""
    if not only:
        return list(names)
    chosen = {n for item in only for n in _expand(item, names, "--only")}
    return [n for n in names if n in chosen]


def teleop_groups(
    names: Sequence[str], composed: bool, processes: bool, given: Sequence[str]
) -> list[list[str]]:
    """Which nodes share a process: ``--processes`` none, ``--group`` (``master``, ``slave`` or
    ``NS/NODE`` items) the named ones, else (``--composed``, the default) all."""
    if sum((composed, processes, bool(given))) > 1:
        raise InputError("--composed, --processes and --group are different choices: pick one")
    if processes:
        return []
    if not given:
        return [list(names)]
    groups: list[list[str]] = []
    seen: set[str] = set()
    for text in given:
        group = [n for item in text.split(",") if item for n in _expand(item, names, "--group")]
        twice = sorted({n for n in group if n in seen or group.count(n) > 1})
        if twice:
            raise InputError(f"--group: {', '.join(twice)} named in more than one place")
        seen.update(group)
        groups.append(group)
    return groups


def endless_devices(params: Mapping[str, Mapping[str, Any]]) -> set[str]:
    """The devices and bridges that run until stopped (``duration_s`` 0): a side's process that
    holds one never ends the graph, so the other side's finished run does (with ``--group``
    as in one process)."""
    return {
        name
        for name, values in params.items()
        if name.rsplit("/", 1)[-1] in RUN_ENDS and float(values.get("duration_s", -1.0)) == 0.0
    }


def teleop_plan(
    params: Mapping[str, Any], params_file: Path, groups: Sequence[Sequence[str]]
) -> list[ProcessSpec]:
    """The processes, in start order: a recorder (root namespace) first and alone, then each
    group in one container and every other node alone, the devices' processes last."""
    ros = ["--ros-args", "--params-file", str(params_file)]
    out = []
    names = [n for n in params if "/" in n]
    for name in (n for n in params if "/" not in n):
        entry = NODES[name]
        out.append(ProcessSpec(name, [name], executable(entry.package, entry.executable), ros))
    shared = [[n for n in names if n in g] for g in groups]
    shared = [g for g in shared if len(g) > 1]
    for name in names:  # a process starts where its last node would: devices last
        group = next((g for g in shared if name in g), None)
        if group is None:
            ns, _, node = name.partition("/")
            entry = NODES[node]
            args = [*ros, "-r", f"__ns:=/{ns}", "-r", f"__node:={node}"]
            out.append(ProcessSpec(name, [name], executable(entry.package, entry.executable), args))
        elif name == group[-1]:
            out.append(ProcessSpec(", ".join(group), group, executable(*CONTAINER), [*group, *ros]))
    return out


REFUSED = {
    "namespace": "--namespace",
    "pin": "--pin",
    "cpu_latency_us": "--cpu-latency",
}


def teleop_command(opts: LaunchOptions, sections: Mapping[str, Mapping[str, Any]]) -> int:
    """Plan and run a teleoperation graph; ``InputError`` on bad input."""
    given = [flag for field, flag in REFUSED.items() if getattr(opts, field)]
    if given:
        raise InputError(
            f"{', '.join(given)}: not for a teleoperation graph (its namespaces are "
            "/master and /slave)"
        )
    params = teleop_params(sections, opts.sets)
    if opts.robot_description:
        env = network_env(opts.network, opts.peers)
        fill(params, fetch(opts.robot_description, env))
    names = select_nodes([n for n in params if "/" in n], opts.only)
    groups = teleop_groups(names, opts.composed, opts.processes, opts.groups)
    if opts.record and opts.only:
        raise InputError(
            "--record with --only: both sides' devices wait for the recorder, so record where "
            "the whole graph starts (or run haptic-record and add it to each device's wait_for)"
        )
    if opts.record:
        add_teleop_recorder(params, opts.record, opts.record_storage)
    params = {n: v for n, v in params.items() if n in names or "/" not in n}
    net = network_env(opts.network, opts.peers)
    if opts.rt_priority is not None:
        set_rt_priority(opts.rt_priority)
    if opts.executor:
        net["HAPTIC_DOB_EXECUTOR"] = opts.executor
    say_session(net, add_command_tokens(params, names))
    with tempfile.TemporaryDirectory(prefix="haptic-launch-") as tmp:
        specs = teleop_plan(params, write_teleop_params(params, Path(tmp)), groups)
        for spec in specs:
            if len(spec.nodes) > 1:
                print(f"haptic-launch: {spec.name} in one process", file=sys.stderr)
        return launch(specs, opts.stop_timeout, opts.duration, net, endless_devices(params))
