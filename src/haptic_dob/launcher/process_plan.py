"""What runs where: which of a launch's nodes start, which share a process (composition groups),
and each process's command line through the ``ros2 run`` contract, in start order."""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ament_index_python.packages import PackageNotFoundError, get_package_prefix

from haptic_dob.errors import InputError
from haptic_dob.nodes.registry import CONTAINER, LOOP_NODES, NODES, OFF_PATH_NODES, START_ORDER
from haptic_msgs_py.ament import ensure_ament_prefix


@dataclass
class ProcessSpec:
    """One process to start: its nodes, the executable and its arguments.

    ``name`` is the node's name, or the nodes' names joined by ``, `` for a composed group.
    """

    name: str
    nodes: list[str]
    executable: str
    args: list[str]

    @property
    def label(self) -> str:
        """How messages name the process."""
        return self.name if len(self.nodes) == 1 else f"the process of {self.name}"

    @property
    def off_path(self) -> bool:
        """Every node of the process is off the command's path (``OFF_PATH_NODES``; a teleop's
        namespaced names by their last part)."""
        return all(n.rsplit("/", 1)[-1] in OFF_PATH_NODES for n in self.nodes)


def executable(package: str, name: str) -> str:
    """``<prefix>/lib/<package>/<name>`` from the ament index: what ``ros2 run`` executes."""
    ensure_ament_prefix()
    try:
        path = Path(get_package_prefix(package)) / "lib" / package / name
    except PackageNotFoundError:
        raise InputError(f"package {package} is not in the ament index; reinstall") from None
    if not os.access(path, os.X_OK):
        raise InputError(f"{path} is missing or not executable; reinstall")
    return str(path)


def select(names: Sequence[str], only: Sequence[str]) -> list[str]:
    """The nodes named in ``only`` (all when empty); a name the config does not start is an
    error."""
    if not only:
        return list(names)
    unknown = [n for n in only if n not in names]
    if unknown:
        raise InputError(
            f"--only names {', '.join(unknown)}, which the config does not start "
            f"(it starts {', '.join(sorted(names))})"
        )
    return [n for n in names if n in only]


def groups_for(
    names: Sequence[str], composed: bool, processes: bool, given: Sequence[str]
) -> list[list[str]]:
    """Which of ``names`` share a process: ``--composed`` all, ``--processes`` none,
    ``--group A,B`` (repeatable) the named ones, by default the loop's nodes."""
    if sum((composed, processes, bool(given))) > 1:
        raise InputError("--composed, --processes and --group are different choices: pick one")
    if processes:
        return []
    if composed:
        return [list(names)]
    if not given:
        return [[n for n in LOOP_NODES if n in names]]
    groups, seen = [], set()
    for text in given:
        group = [n for n in text.split(",") if n]
        unknown = [n for n in group if n not in NODES]
        if unknown:
            raise InputError(f"--group names unknown node(s) {', '.join(unknown)}")
        twice = [n for n in group if n in seen]
        if twice or len(set(group)) != len(group):
            raise InputError(f"--group: {', '.join(twice or group)} named in more than one place")
        seen.update(group)
        groups.append([n for n in group if n in names])
    return groups


def check_pinnable(groups: Sequence[Sequence[str]]) -> None:
    """``--pin`` places node processes on CPUs: ``InputError`` when nodes share a process."""
    shared = [g for g in groups if len(g) > 1]
    if shared:
        raise InputError(
            f"--pin places node processes on CPUs, and {', '.join(shared[0])} share one "
            "(the loop is composed by default): add --processes"
        )


def plan(
    params: dict[str, Any],
    params_file: Path,
    namespace: str,
    groups: Sequence[Sequence[str]] = (),
) -> list[ProcessSpec]:
    """The processes the parameters ask for, in start order (the device's last), each with its
    nodes and arguments; nodes of one group share a process (the container)."""
    names = [n for n in START_ORDER if n in params]
    if not names:
        raise InputError("the config starts no nodes")
    ros = ["--ros-args", "--params-file", str(params_file)]
    if namespace:
        ros += ["-r", f"__ns:={namespace}"]
    out: list[ProcessSpec] = []
    grouped = [[n for n in START_ORDER if n in g and n in names] for g in groups]
    grouped = [g for g in grouped if len(g) > 1]
    for name in names:
        group = next((g for g in grouped if name in g), None)
        if group is None:
            entry = NODES[name]
            exe = executable(entry.package, entry.executable)
            out.append(ProcessSpec(name, [name], exe, [*ros, "-r", f"__node:={name}"]))
        elif name == group[-1]:  # the group starts where its last node would
            exe = executable(*CONTAINER)
            out.append(ProcessSpec(", ".join(group), group, exe, [*group, *ros]))
    return out
