"""Helpers every node executable shares: ``--help``, ``main``, the graph's missing nodes.

The parameter groups the loop nodes share are ``haptic_dob.nodes.settings``.
"""

from __future__ import annotations

import os
import sys
import textwrap
from collections.abc import Iterable

from haptic_dob.runtime.params import ParamSpec


def usage(node_class: type, specs: list[ParamSpec]) -> str:
    """``--help`` of a node executable: how to run it, what it does, its parameters."""
    module = sys.modules[node_class.__module__]
    doc = (module.__doc__ or "").strip().split("\n\n")[0]
    spec = getattr(module, "__spec__", None)  # ``python -m``: the module is __main__
    dotted = spec.name if spec is not None else node_class.__module__
    name, package = dotted.rsplit(".", 1)[-1], dotted.split(".", 1)[0]
    lines = [
        f"usage: ros2 run {package} {name} [--ros-args [-p NAME:=VALUE] [--params-file FILE] ...]",
        "",
        textwrap.fill(" ".join(doc.replace("``", "").split()), 100),
        "",
        "parameters (NAME = default, when it may change; ros2 param describe shows the same):",
    ]
    for spec in specs:
        when = "at start-up" if spec.read_only else "at run time"
        default = repr(spec.default) if isinstance(spec.default, str) else spec.default
        head = f"  {spec.name} = {default}" + (f" {spec.unit}" if spec.unit else "")
        if spec.min is not None or spec.max is not None:
            low = "-inf" if spec.min is None else f"{spec.min:g}"
            high = "inf" if spec.max is None else f"{spec.max:g}"
            head += f", in [{low}, {high}]"
        if spec.choices:
            head += ", one of " + " | ".join(spec.choices)
        lines.append(f"{head}, {when}")
        lines += textwrap.wrap(
            spec.description, 100, initial_indent=" " * 6, subsequent_indent=" " * 6
        )
    return "\n".join(lines)


def own_args(argv: list[str]) -> list[str]:
    """The arguments of ``argv`` (``argv[0]`` the program) outside ``--ros-args ... [--]``, as rcl
    splits them; none is parsed here (rcl reports a bad ROS argument itself). rclpy would drop a
    bare ``name:=value`` as a deprecated remap rule: it counts as the node's own here."""
    own, in_ros = [], False
    for arg in argv[1:]:
        if arg == "--ros-args":
            in_ros = True
        elif in_ros and arg == "--":
            in_ros = False
        elif not in_ros:
            own.append(arg)
    return own


def main_for(node_class: type, args: list[str] | None, specs: list[ParamSpec]) -> int:
    """``main()`` of a single-node executable: spin it until Ctrl-C/SIGTERM. ``--help`` prints
    ``usage`` with ``specs``; any other argument before ``--ros-args`` is refused (exit 2)."""
    argv = list(sys.argv if args is None else args)
    own = own_args(argv)
    if own[:1] in (["-h"], ["--help"]):
        try:
            print(usage(node_class, specs), flush=True)
        except BrokenPipeError:  # the reader went away (``| head``): stop quietly
            sys.stdout = open(os.devnull, "w")  # noqa: SIM115 - nothing more may reach the pipe
        return 0
    if own:
        print(
            f"ERROR: unexpected argument {own[0]!r}: parameters go after --ros-args "
            "(-p NAME:=VALUE or --params-file FILE); --help lists them",
            file=sys.stderr,
        )
        return 2
    # lazy: usage and missing_nodes stay rclpy-free (unit tests, --help)
    from haptic_dob.runtime.ros.spin import run_nodes
    from haptic_msgs_py.ament import ensure_ament_prefix

    ensure_ament_prefix()
    return run_nodes(lambda ctx: [node_class(context=ctx)], argv)


def missing_nodes(
    wait_for: Iterable[str], graph: Iterable[tuple[str, str]], namespace: str
) -> list[str]:
    """The ``wait_for`` entries that are not up in ``graph`` ((name, namespace) of each node): a
    plain name is a node of ``namespace``, one starting with ``/`` a fully qualified name (a
    recorder elsewhere, such as ``ros2 bag record``'s ``/rosbag2_recorder``)."""
    here, everywhere = set(), set()
    for name, space in graph:
        everywhere.add(f"{space.rstrip('/')}/{name}")
        if space == namespace:
            here.add(name)
    return [w for w in wait_for if w not in (everywhere if w.startswith("/") else here)]
