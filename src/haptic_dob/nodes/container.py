"""``ros2 run haptic_dob container [NODE ...] --ros-args ...``: several nodes, one process.

The nodes are the same nodes as their own executables start (parameters, services, diagnostics,
topics), with their default names, under one executor; the loop's messages between them are
handed over in process (``haptic_msgs_py.bus``) and reach DDS only for readers elsewhere.
``--ros-args`` apply to every node (a params file keyed by node name, ``-r __ns:=``; not
``__node``, which would give them all one name). A node named ``NS/NODE`` runs in namespace
``/NS`` (a teleoperation graph: ``master/device_node slave/device_node ...``). Without names the
container runs the nodes its ``--params-file`` sections name (``ros_args.configured_nodes``; a
recorder only when named).
"""

from __future__ import annotations

import sys

from haptic_dob.nodes.registry import NODES, START_ORDER, node_class
from haptic_dob.runtime.ros.spin import run_nodes
from haptic_dob.runtime.ros_args import configured_nodes
from haptic_msgs_py.ament import ensure_ament_prefix

USAGE = (
    "usage: container [NODE ...] [--ros-args [--params-file FILE] ...]\n"
    "Runs the named nodes in this one process (nodes: " + ", ".join(NODES) + "); without names,\n"
    "the nodes the params files' sections name (a recorder only when named)."
)


def split_name(item: str) -> tuple[str | None, str]:
    """``NS/NODE`` -> (``/NS``, ``NODE``); ``NODE`` -> (None, ``NODE``)."""
    ns, _, node = item.rpartition("/")
    return ("/" + ns.strip("/") if ns else None), node


def parse(argv: list[str]) -> tuple[list[str], list[str]]:
    """(node names in start order, the ROS arguments); ``ValueError`` with the reason."""
    split = argv.index("--ros-args") if "--ros-args" in argv else len(argv)
    names, ros_args = argv[:split], argv[split:]
    if not names:
        names = configured_nodes(ros_args, [n for n in NODES if n != "recorder_node"])
    if not names:
        raise ValueError(
            "name at least one node to run, or give a --params-file whose sections name them "
            "(after --ros-args)"
        )
    unknown = [n for n in names if split_name(n)[1] not in NODES]
    if unknown:
        raise ValueError(f"unknown node(s) {', '.join(unknown)}; nodes: {', '.join(NODES)}")
    if len(set(names)) != len(names):
        raise ValueError(f"a node is named twice: {' '.join(names)}")
    if any(a.startswith("__node:=") for a in ros_args):
        raise ValueError("__node:= would give every node one name; the nodes keep their own")
    return sorted(names, key=lambda n: START_ORDER.index(split_name(n)[1])), ros_args


def main(args: list[str] | None = None) -> int:
    """Entry point of the container executable."""
    argv = list(sys.argv[1:] if args is None else args)
    if argv[:1] in (["-h"], ["--help"]):
        print(USAGE)
        return 0
    try:
        names, ros_args = parse(argv)
        classes = [(*split_name(n), node_class(split_name(n)[1])) for n in names]
    except ValueError as exc:
        print(f"ERROR: {exc}", file=sys.stderr)
        return 2
    ensure_ament_prefix()
    return run_nodes(
        lambda ctx: [cls(context=ctx, name=name, namespace=ns) for ns, name, cls in classes],
        ["container", *ros_args],
    )


if __name__ == "__main__":
    sys.exit(main())
