"""``haptic-launch``: bring up a session's node graph from one ``ros__parameters`` YAML.

Each node section starts through the ``ros2 run`` contract (``<prefix>/lib/<pkg>/<exe>`` found
with ``ament_index_python``) with ``--ros-args --params-file CONFIG`` and the namespace. By
default the loop (device, environment, observer, controller) shares one process and a recorder
runs apart; ``--processes``, ``--composed`` and ``--group`` choose otherwise. The device's
process starts last. Ctrl-C or SIGTERM goes to every process as SIGTERM, what is alive after
``--stop-timeout`` is killed, and the end of a lockstep run (``duration_s``) stops the others.
Discovery stays on this host unless ``--network subnet`` (``--peers``: named hosts; ``--only``:
a subset). A device and its controller started together share a fresh ``command_token``; the
launch says it, and the domain and discovery range. A teleoperation YAML (``/master/...``,
``/slave/...`` sections): ``haptic_dob.launcher.teleop``. Guide: docs/running.md.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

from haptic_dob.cli.common import ArgumentParser, run
from haptic_dob.errors import InputError
from haptic_dob.launcher import robot_description
from haptic_dob.launcher.node_params import (
    add_command_tokens,
    add_cpu_latency,
    add_pinning,
    add_recorder,
    resolved_params,
    write_params_file,
)
from haptic_dob.launcher.options import (
    NETWORKS,
    LaunchOptions,
    comma_list,
    network_env,
    normalize_namespace,
    parse_sets,
    say_session,
)
from haptic_dob.launcher.process_plan import check_pinnable, groups_for, plan, select
from haptic_dob.launcher.supervise import check_cpu_latency_request, launch, set_rt_priority
from haptic_dob.launcher.teleop import teleop_command
from haptic_dob.nodes.registry import START_ORDER
from haptic_dob.runtime.configs import resolve_config
from haptic_dob.runtime.params import load_sections
from haptic_dob.teleop.graph import is_teleop, load_teleop_sections


def command(opts: LaunchOptions) -> int:
    """Resolve, plan and run; raises ``InputError`` on bad input."""
    path = resolve_config(opts.config)
    sections = load_sections(path)
    if is_teleop(sections):
        if opts.overlays:
            raise InputError("--params lays a file over a one-device config, not a teleoperation")
        return teleop_command(opts, load_teleop_sections(path))
    namespace = normalize_namespace(opts.namespace)
    overlays = [resolve_config(o) for o in opts.overlays]
    params = resolved_params(path, parse_sets(opts.sets), overlays)
    if opts.robot_description:
        urdf = robot_description.fetch(
            opts.robot_description, network_env(opts.network, opts.peers)
        )
        robot_description.fill(params, urdf)
    if opts.record:
        add_recorder(params, opts.record, opts.record_storage)
    names = select([n for n in START_ORDER if n in params], opts.only)
    groups = groups_for(names, opts.composed, opts.processes, opts.groups)
    if opts.pin:
        check_pinnable(groups)
        print(f"haptic-launch: CPUs {add_pinning(params)}", file=sys.stderr)
    if opts.cpu_latency_us is not None:
        add_cpu_latency(params, opts.cpu_latency_us)
        check_cpu_latency_request(opts.cpu_latency_us)
    net = network_env(opts.network, opts.peers)
    if opts.rt_priority is not None:  # the nodes started below inherit the policy
        set_rt_priority(opts.rt_priority)
    if opts.executor:
        net["HAPTIC_DOB_EXECUTOR"] = opts.executor
    say_session(net, add_command_tokens(params, names))
    with tempfile.TemporaryDirectory(prefix="haptic-launch-") as tmp:
        chosen = {n: v for n, v in params.items() if n == "/**" or n in names}
        specs = plan(chosen, write_params_file(params, Path(tmp)), namespace, groups)
        for spec in specs:
            if len(spec.nodes) > 1:
                print(f"haptic-launch: {', '.join(spec.nodes)} in one process", file=sys.stderr)
        return launch(specs, opts.stop_timeout, opts.duration, net)


def build_parser() -> ArgumentParser:
    """The command line of ``haptic-launch``."""
    p = ArgumentParser(prog="haptic-launch", description=__doc__.split("\n\n")[0])
    p.add_argument("config", help="session YAML (a path, or an installed name like slide_sim)")
    p.add_argument("--namespace", default="", help="namespace of every node (one device per ns)")
    p.add_argument(
        "--composed", action="store_true", help="run every node in one process (one executor)"
    )
    p.add_argument(
        "--processes",
        action="store_true",
        help="run every node in a process of its own (default: the loop's four nodes share one, "
        "their messages handed over in process; a recorder runs apart)",
    )
    p.add_argument(
        "--group",
        action="append",
        default=[],
        metavar="NODE,NODE[,...]",
        help="these nodes share a process (repeatable; nodes in no group run alone; for a "
        "teleoperation graph: master, slave or NS/NODE)",
    )
    p.add_argument(
        "--params",
        action="append",
        default=[],
        metavar="FILE",
        help="lay this ros__parameters file over the config (repeatable, in order, before "
        "--set): a model haptic-identify wrote, an excitation like excite/forcedimension",
    )
    p.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NODE:PARAM=VALUE",
        help="override a parameter of one node (repeatable)",
    )
    p.add_argument(
        "--duration",
        type=float,
        metavar="S",
        help="stop the graph after this many wall-clock seconds",
    )
    p.add_argument(
        "--stop-timeout",
        type=float,
        default=5.0,
        metavar="S",
        help="how long nodes get to stop cleanly before they are killed (default 5)",
    )
    p.add_argument(
        "--executor",
        choices=["events", "single"],
        help="rclpy executor of the nodes (default events)",
    )
    p.add_argument(
        "--only",
        default="",
        metavar="NODE[,NODE...]",
        help="start only these nodes of the config (split a session across hosts; for a "
        "teleoperation graph: master, slave or NS/NODE)",
    )
    p.add_argument(
        "--network",
        choices=sorted(NETWORKS),
        default="localhost",
        help="discovery range of the nodes: localhost (default) or subnet (a lab network)",
    )
    p.add_argument(
        "--peers",
        default="",
        metavar="HOST[,HOST...]",
        help="other hosts to discover directly (ROS_STATIC_PEERS; needs --network subnet)",
    )
    p.add_argument(
        "--record",
        metavar="BAG",
        help="record the session into this new bag (a recorder_node the device waits for)",
    )
    p.add_argument(
        "--record-storage", choices=["mcap", "sqlite3"], default="mcap", help="default mcap"
    )
    p.add_argument(
        "--rt-priority",
        type=int,
        metavar="P",
        help="run the nodes with real-time scheduling, SCHED_FIFO priority P (1-99; Linux, needs "
        "root or CAP_SYS_NICE): fewer late commands in real time (BENCHMARKS.md); a recorder "
        "alone in its process stays at normal scheduling",
    )
    p.add_argument(
        "--pin",
        action="store_true",
        help="pin each loop node's process to a CPU (its cpu_affinity): device and controller "
        "on one, environment and observer on another (one each with 4+ CPUs); faster lockstep, "
        "fewer late commands on an otherwise idle machine (BENCHMARKS.md)",
    )
    p.add_argument(
        "--cpu-latency",
        type=int,
        metavar="US",
        help="while the nodes run, CPUs use only idle states whose advertised exit latency is at "
        "most US microseconds (their cpu_latency_us; Linux PM QoS, needs root): 0 makes idle CPUs "
        "poll, which speeds up every hand-over (BENCHMARKS.md) and costs power; on a virtual "
        "machine only 0 helps",
    )
    p.add_argument(
        "--robot-description",
        metavar="TOPIC",
        help="read the URDF a driver latches on TOPIC (robot_state_publisher's "
        "robot_description) and give it to every node whose model is urdf",
    )
    return p


def parse_options(argv: list[str] | None = None) -> LaunchOptions:
    """``argv`` (``sys.argv[1:]`` when None) as options; bad arguments exit 2 (argparse)."""
    a = build_parser().parse_args(argv)
    return LaunchOptions(
        config=a.config,
        namespace=a.namespace,
        sets=tuple(a.set),
        overlays=tuple(a.params),
        composed=a.composed,
        processes=a.processes,
        groups=tuple(a.group),
        stop_timeout=a.stop_timeout,
        duration=a.duration,
        executor=a.executor,
        only=comma_list(a.only),
        network=a.network,
        peers=comma_list(a.peers),
        record=a.record,
        record_storage=a.record_storage,
        rt_priority=a.rt_priority,
        pin=a.pin,
        cpu_latency_us=a.cpu_latency,
        robot_description=a.robot_description,
    )


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``haptic-launch``."""
    opts = parse_options(argv)
    return run(lambda: command(opts))
