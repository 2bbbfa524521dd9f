"""The suite's nodes: name -> ROS package, executable and class; which of them form the loop.

Tools that start nodes (``haptic-launch``, the container, the launch file) look them up here by
name; the classes are imported only when a process hosts them (``node_class``), so the control
side never imports the simulator unless a simulated device runs in the process.
"""

from __future__ import annotations

import importlib
from typing import NamedTuple


class NodeEntry(NamedTuple):
    """Where a node lives: its ROS package, its executable there, its class (``module:Class``)."""

    package: str
    executable: str
    cls: str


NODES: dict[str, NodeEntry] = {
    "environment_node": NodeEntry(
        "haptic_dob", "environment_node", "haptic_dob.nodes.environment_node:EnvironmentNode"
    ),
    "observer_node": NodeEntry(
        "haptic_dob", "observer_node", "haptic_dob.nodes.observer_node:ObserverNode"
    ),
    "controller_node": NodeEntry(
        "haptic_dob", "controller_node", "haptic_dob.nodes.controller_node:ControllerNode"
    ),
    "channel_node": NodeEntry(
        "haptic_dob", "channel_node", "haptic_dob.nodes.channel_node:ChannelNode"
    ),
    "slave_controller_node": NodeEntry(
        "haptic_dob",
        "slave_controller_node",
        "haptic_dob.nodes.slave_controller_node:SlaveControllerNode",
    ),
    "recorder_node": NodeEntry(
        "haptic_dob", "recorder_node", "haptic_dob.nodes.recorder_node:RecorderNode"
    ),
    "device_node": NodeEntry(
        "haptic_sim", "device_node", "haptic_sim.nodes.device_node:DeviceNode"
    ),
}

#: the order nodes start in: a recorder first, the device (which waits for the rest) last
START_ORDER = (
    "recorder_node",
    "environment_node",
    "observer_node",
    "controller_node",
    "channel_node",
    "slave_controller_node",
    "device_node",
)

#: the nodes that close the loop: composed in one process by default (``haptic-launch``)
LOOP_NODES = ("device_node", "environment_node", "observer_node", "controller_node")

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
