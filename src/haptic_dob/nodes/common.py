"""Parameters and helpers every loop node shares (rate, frames, loop mode)."""

from __future__ import annotations

from collections.abc import Iterable

from haptic_dob.runtime.params import ParamSpec
from haptic_msgs_py.topics import DEFAULT_BASE_FRAME, INPUT_RELIABILITY

CLOCK_MODES = ("lockstep", "realtime")


def loop_specs() -> list[ParamSpec]:
    """``rate_hz`` and the base frame: the same on every node of a session (YAML ``/**``)."""
    return [
        ParamSpec("rate_hz", 1000.0, "control rate of the loop", "Hz", 1.0, 1e5, read_only=True),
        ParamSpec(
            "base_frame", DEFAULT_BASE_FRAME, "frame of poses, twists and wrenches", read_only=True
        ),
    ]


def input_specs(default: str) -> list[ParamSpec]:
    """How a node with loop inputs subscribes to them: ``default`` is ``reliable`` for a command
    input (the device's ``effort_command``), ``best_effort`` for sensor streams (environment,
    controller), as ROS 2 treats commands and sensor data."""
    return [
        ParamSpec(
            "input_reliability",
            default,
            "QoS reliability of this node's loop inputs: reliable (a one-off message such as "
            "ros2 topic pub --once is asked for again and arrives while its publisher lives; "
            "the default of the device's effort_command) "
            "or best_effort (no acknowledgements, the default of the sensor streams: nodes in "
            "separate processes cycle faster, see BENCHMARKS.md, and a message sent before the "
            "reader matched its writer can be lost). Nodes sharing a process hand values over "
            "in process either way",
            choices=INPUT_RELIABILITY,
            read_only=True,
        )
    ]


def command_authority_specs() -> list[ParamSpec]:
    """Who may command a device end (the simulated device node, the device bridge): the command
    source, the session's token, the bench switch (``haptic_dob.core.command_authority``)."""
    return [
        ParamSpec(
            "command_source",
            "controller_node",
            "the node whose effort_command moves the device from another process: a name in "
            "this namespace, or fully qualified (commands handed over in this process, the loop "
            "composed, always do)",
            read_only=True,
        ),
        ParamSpec(
            "command_token",
            "",
            "this session's command token: a command from another process moves the device only "
            "when its layout label carries it (effort@<stamp>#<token>); haptic-launch writes a "
            "fresh one for a device and its controller at every launch. '' = the token of "
            "command_source's commands, taken while the graph shows that node (name and GID) as "
            "the only publisher. Not a secret from anyone on the network (docs/safety.md)",
            read_only=True,
        ),
        ParamSpec(
            "open_command_input",
            False,
            "take effort_command from any publisher (bench work: ros2 topic pub, a tool of your "
            "own); false: only command_source's, the others refused, counted in /diagnostics and "
            "named once each in the log. At start-up only: no one on the network can open it "
            "with ros2 param set",
            read_only=True,
        ),
    ]


def command_token_spec() -> ParamSpec:
    """The token a command source's ``effort_command`` carries (the controllers)."""
    return ParamSpec(
        "command_token",
        "",
        "the token this node's effort_command carries in its layout label "
        "(effort@<stamp>#<token>), by which the device takes commands from another process; "
        "haptic-launch writes the session's; '' = a fresh random one at every start",
        read_only=True,
    )


def process_specs() -> list[ParamSpec]:
    """Per-process settings of a loop node (``cpu_affinity``, ``cpu_latency_us``)."""
    return [
        ParamSpec(
            "cpu_affinity",
            [],
            "CPUs this node's process runs on, every thread (as ros2_control's cpu_affinity); "
            "[] = wherever the system schedules it. haptic-launch --pin fills it per node",
            read_only=True,
            items=int,
        ),
        ParamSpec(
            "cpu_latency_us",
            -1,
            "while this process runs, CPUs use only idle states whose advertised exit latency "
            "is at most this (Linux PM QoS request on /dev/cpu_dma_latency, held open; needs "
            "write access to it, root as a rule; a node that cannot make it does not start): "
            "0 = idle CPUs poll and wake at once (costs power; on a virtual machine only 0 "
            "helps). -1 = no request. haptic-launch --cpu-latency sets it on every loop node",
            unit="us",
            min=-1,
            max=1_000_000,
            read_only=True,
        ),
    ]


def usage(node_class: type, specs: list[ParamSpec]) -> str:
    """``--help`` of a node executable: how to run it, what it does, its parameters."""
    import sys
    import textwrap

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
    import os
    import sys

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
