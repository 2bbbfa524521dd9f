"""The suite's nodes: name -> ROS package, executable and class; which of them form the loop.

Tools that start nodes (``haptic-launch``, the container, the launch file) look them up here by
name. Packages register their nodes as entry points (``ENTRY_POINT_GROUP``, in the project's
metadata); the classes are imported only when a process hosts them (``node_class``), so the
control side neither names nor imports the simulator unless a simulated device runs there.
"""

from __future__ import annotations

import importlib
from importlib.metadata import entry_points
from typing import NamedTuple


class NodeEntry(NamedTuple):
    """Where a node lives: its ROS package, its executable there, its class (``module:Class``)."""

    package: str
    executable: str
    cls: str


#: the order nodes start in: a recorder first, the device or the bridge to a driver (which waits
#: for the rest) last
START_ORDER = (
    "recorder_node",
    "environment_node",
    "observer_node",
    "controller_node",
    "channel_node",
    "slave_controller_node",
    "bridge_node",
    "device_node",
)

#: the entry-point group where each package registers its nodes (``name = "module:Class"``):
#: the simulator registers its device node there, so the control side never names it
ENTRY_POINT_GROUP = "haptic_dob.nodes"


def _registered() -> dict[str, NodeEntry]:
    """Every node a package registered: the ROS package is the class's top-level package and
    the executable is the node's name (``ros/lib/<package>/<name>``)."""
    found = {
        ep.name: NodeEntry(ep.value.split(".", 1)[0], ep.name, ep.value)
        for ep in entry_points(group=ENTRY_POINT_GROUP)
    }
    order = {n: i for i, n in enumerate(START_ORDER)}
    return dict(sorted(found.items(), key=lambda item: (order.get(item[0], len(order)), item[0])))


NODES: dict[str, NodeEntry] = _registered()

#: the nodes that close the loop: composed in one process by default (``haptic-launch``); a
#: foreign driver's bridge takes the simulated device's place (the driver is its own process)
LOOP_NODES = ("device_node", "bridge_node", "environment_node", "observer_node", "controller_node")

#: nodes off the command's path: a process of these alone keeps normal scheduling under
#: ``haptic-launch --rt-priority`` (at the loop's priority a recorder's bursts held a CPU from
#: the driver and the loop, docs/running.md)
OFF_PATH_NODES = ("recorder_node",)

#: the executable that hosts several nodes in one process (``ros2 run haptic_dob container``)
CONTAINER = ("haptic_dob", "container")


def node_class(name: str) -> type:
    """The class of node ``name`` (``ValueError`` naming the known ones for another name)."""
    entry = NODES.get(name)
    if entry is None:
        raise ValueError(f"unknown node {name!r}; nodes: {', '.join(NODES)}")
    module, _, cls = entry.cls.partition(":")
    found: type = getattr(importlib.import_module(module), cls)
    return found
