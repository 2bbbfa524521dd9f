"""The teleoperation graph's shape: its namespaces, the nodes of each side, and how a node's
parameters come out of one YAML's sections.

Sections are keyed by namespace: ``/master/<node>`` and ``/slave/<node>``, with ``/**``,
``/master/**``, ``/slave/**`` and ``/**/<node>`` for what several nodes share. A node's
parameters are those sections overlaid from the general to the specific: ``/**``, ``/<ns>/**``,
``/**/<node>``, ``/<ns>/<node>``. The nodes: on both sides ``device_node``, ``observer_node`` and
the channel's end ``channel_node``; the master's ``controller_node`` (the haptic law rendering the
channel's force) and the slave's ``slave_controller_node`` (the joint impedance). The batch runner
(``haptic_sim.teleop.config``) and ``haptic-launch`` read a file the same way.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from haptic_dob.runtime.configs import urdf_beside
from haptic_dob.runtime.params import load_sections
from haptic_msgs_py.topics import PARAMETER_EVENTS, POSE_DESIRED, SESSION_TOPICS, WRENCH_DESIRED

NAMESPACES = ("master", "slave")
#: the nodes of each side, in start order (the device last)
SIDE_NODES = {
    "master": ("observer_node", "controller_node", "channel_node", "device_node"),
    "slave": ("observer_node", "slave_controller_node", "channel_node", "device_node"),
}
#: what may stand in a side's device's place: a bridge to a real driver (``bridge_node``)
BRIDGE = "bridge_node"
#: the channel's link between the ends (absolute: it joins the two namespaces)
TO_SLAVE = "/teleop/to_slave"
TO_MASTER = "/teleop/to_master"
#: the recorder of a teleoperation graph (root namespace: it records both sides)
RECORDER = "/recorder_node"
_JOINT_STATE = "sensor_msgs/msg/JointState"
_POSE = "geometry_msgs/msg/PoseStamped"


def recorded_topics() -> list[str]:
    """What a teleoperation graph's recorder records (``NAME:pkg/msg/Type``): every session
    topic of both sides (but the slave's ``wrench_desired``: it has no wall), the slave's
    ``pose_desired``, the channel's link both ways and the parameter events (each node's
    parameters)."""
    out = [
        f"/{ns}/{topic}:{kind}"
        for ns in NAMESPACES
        for topic, kind in SESSION_TOPICS.items()
        if not (ns == "slave" and topic == WRENCH_DESIRED)  # the slave has no wall
    ]
    out += [f"/slave/{POSE_DESIRED}:{_POSE}", f"{TO_SLAVE}:{_JOINT_STATE}"]
    out += [f"{TO_MASTER}:{_JOINT_STATE}", PARAMETER_EVENTS]
    return out


def node_values(sections: Mapping[str, Mapping[str, Any]], ns: str, node: str) -> dict[str, Any]:
    """The parameters node ``/<ns>/<node>`` gets from ``sections`` (general to specific)."""
    out: dict[str, Any] = {}
    for key in ("/**", f"/{ns}/**", f"/**/{node}", f"/{ns}/{node}"):
        out.update(sections.get(key, {}))
    return out


def load_teleop_sections(path: str | Path) -> dict[str, dict[str, Any]]:
    """The YAML's sections, a relative ``urdf_path`` or ``slave.trajectory_path`` taken from the
    YAML's own directory (the installed ``teleop_sim.yaml`` names ``urdf/arm7.urdf`` beside it)."""
    sections = load_sections(path)
    urdf_beside(sections, path)
    here = Path(path).resolve().parent
    for values in sections.values():
        given = values.get("slave.trajectory_path")
        if isinstance(given, str) and given and not Path(given).is_absolute():
            values["slave.trajectory_path"] = str(here / given)
    return sections


def is_teleop(sections: Mapping[str, Any]) -> bool:
    """Whether a YAML's sections describe a teleoperation graph (a ``/master/`` or ``/slave/``
    section)."""
    return any(k.startswith(("/master/", "/slave/")) for k in sections)


def device_of(sections: Mapping[str, Any], ns: str) -> str:
    """The node in side ``ns``'s device's place: ``bridge_node`` when the YAML has a
    ``/<ns>/bridge_node`` section (the side is a real driver, in real time), else
    ``device_node``."""
    return BRIDGE if f"/{ns}/{BRIDGE}" in sections else "device_node"


def check_sections(sections: Mapping[str, Any]) -> None:
    """``ValueError`` for a section that names no node of a teleoperation graph."""
    known = {"/**", *(f"/{ns}/**" for ns in NAMESPACES)}
    known |= {f"/**/{n}" for nodes in SIDE_NODES.values() for n in (*nodes, BRIDGE)}
    known |= {f"/{ns}/{n}" for ns, nodes in SIDE_NODES.items() for n in (*nodes, BRIDGE)}
    unknown = sorted(set(sections) - known)
    if unknown:
        sides = ", ".join(f"/{ns}/{{{','.join(SIDE_NODES[ns])}}}" for ns in NAMESPACES)
        raise ValueError(
            f"section(s) {', '.join(unknown)} name no node of the teleoperation graph ({sides})"
        )


def graph_nodes(sections: Mapping[str, Any] | None = None) -> list[tuple[str, str]]:
    """(namespace, node) of every node, in start order: each side's, the devices last (a side's
    ``bridge_node`` in its device's place, ``device_of``)."""
    first = [(ns, n) for ns in NAMESPACES for n in SIDE_NODES[ns] if n != "device_node"]
    return [*first, *((ns, device_of(sections or {}, ns)) for ns in NAMESPACES)]
