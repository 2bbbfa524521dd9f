"""What ``haptic-launch`` is asked for (``LaunchOptions``) and the checks that turn option values
into launch inputs: the namespace, the ``--set`` overrides, the discovery environment (and the
line that says which domain and range the nodes get)."""

from __future__ import annotations

import os
import re
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import yaml

from haptic_dob.errors import InputError
from haptic_dob.nodes.registry import NODES
from haptic_dob.runtime.discovery import Discovery


@dataclass(frozen=True)
class LaunchOptions:
    """What ``haptic-launch`` was asked for (its command line, parsed); times in s."""

    config: str
    namespace: str = ""
    sets: Sequence[str] = ()
    composed: bool = False
    processes: bool = False
    groups: Sequence[str] = ()
    stop_timeout: float = 5.0
    duration: float | None = None
    executor: str | None = None
    only: Sequence[str] = ()
    network: str = "localhost"
    peers: Sequence[str] = ()
    record: str | None = None
    record_storage: str = "mcap"
    rt_priority: int | None = None
    pin: bool = False
    cpu_latency_us: int | None = None
    robot_description: str | None = None


def comma_list(text: str) -> tuple[str, ...]:
    """``a,b,`` -> ``("a", "b")`` (``--only``, ``--peers``): empty items dropped."""
    return tuple(item for item in text.split(",") if item)


def normalize_namespace(namespace: str) -> str:
    """``slide1`` -> ``/slide1`` (ROS wants it absolute); ``InputError`` for an invalid name."""
    ns = namespace.strip()
    if not ns:
        return ""
    ns = "/" + ns.strip("/")
    if not re.fullmatch(r"(/[A-Za-z_][A-Za-z0-9_]*)+", ns):
        raise InputError(
            f"--namespace {namespace!r} is not a valid ROS namespace (letters, digits and _ "
            "separated by /, each part not starting with a digit)"
        )
    return ns


#: parameters a node no longer takes, and what to set instead
MOVED = {
    ("device_node", f"slide.{name}"): (
        f"the simulated slide's physics is plant.{name}; slide.* is the model the observer "
        "and the controller assume"
    )
    for name in ("mass_kg", "viscous_n_s_per_m", "coulomb_n")
}


def parse_sets(items: Sequence[str]) -> dict[str, dict[str, Any]]:
    """``NODE:PARAM=VALUE`` (VALUE in YAML syntax) -> {node: {param: value}}."""
    out: dict[str, dict[str, Any]] = {}
    for item in items:
        node, sep, assignment = item.partition(":")
        param, eq, text = assignment.partition("=")
        if not (sep and eq and node and param):
            raise InputError(f"--set needs NODE:PARAM=VALUE, got {item!r}")
        if node not in NODES:
            raise InputError(f"--set names unknown node {node!r}; nodes: {', '.join(NODES)}")
        moved = MOVED.get((node, param))
        if moved:
            raise InputError(f"--set {node}:{param}: {moved}")
        try:
            value = yaml.safe_load(text)
        except yaml.YAMLError:
            raise InputError(f"--set {item!r}: the value is not valid YAML") from None
        out.setdefault(node, {})[param] = value
    return out


#: ``--network`` -> ``ROS_AUTOMATIC_DISCOVERY_RANGE``
NETWORKS = {"localhost": "LOCALHOST", "subnet": "SUBNET"}


def network_env(network: str, peers: Sequence[str]) -> dict[str, str]:
    """The discovery variables for ``--network`` and ``--peers``."""
    if network not in NETWORKS:
        raise InputError(f"--network must be one of {', '.join(NETWORKS)}, got {network!r}")
    env = {"ROS_AUTOMATIC_DISCOVERY_RANGE": NETWORKS[network]}
    if peers:
        if network == "localhost":
            raise InputError("--peers needs --network subnet (peers are other hosts)")
        env["ROS_STATIC_PEERS"] = ";".join(peers)
    return env


def say_session(net: dict[str, str], authority: Sequence[str]) -> None:
    """Print (stderr) the DDS domain and discovery range the nodes get (``net`` over this
    process's environment), then how each device takes its commands (``authority``)."""
    print(f"haptic-launch: {Discovery.of({**os.environ, **net}).describe()}", file=sys.stderr)
    for line in authority:
        print(f"haptic-launch: {line}", file=sys.stderr)
