"""``haptic-launch``: bring up a session's node graph from one ``ros__parameters`` YAML.

Every node section of the YAML (``device_node``, ``environment_node``, ``observer_node``,
``controller_node``, ``recorder_node``) starts through the ``ros2 run`` contract
(``<prefix>/lib/<pkg>/<exe>`` found with ``ament_index_python``), with
``--ros-args --params-file CONFIG`` and the namespace. Composition groups say which nodes share a
process (``<prefix>/lib/haptic_dob/container``, where the loop's messages are handed over in
process): by default the loop (device, environment, observer, controller) shares one and a
recorder runs apart; ``--processes`` gives every node its own, ``--composed`` puts all in one,
``--group`` names groups. The device's process starts last. Ctrl-C or SIGTERM is forwarded to
every process as SIGTERM (each shuts down cleanly: the device zeroes its effort; a node still
starting up ends quietly, with no Python traceback as SIGINT would give) and the launcher waits
for them, killing what is still alive after ``--stop-timeout``. When the device finishes a
lockstep run (``duration_s``) the others are stopped too.

Network: by default every node's discovery stays on this host
(``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``), so a simulated session never reaches a lab network
by accident. ``--network subnet`` lets them discover across the subnet, ``--peers`` adds named
hosts (``ROS_STATIC_PEERS``), and ``--only`` starts a subset: the device on one host and the rest
on another (see the README's lab-network section).
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from haptic_dob.cli import ArgumentParser, CliError, run
from haptic_dob.configs import resolve_config
from haptic_dob.nodes.registry import CONTAINER, LOOP_NODES, NODES, START_ORDER
from haptic_dob.runtime.params import load_node_params

__all__ = ["NODES", "START_ORDER", "command", "main", "plan", "resolved_params"]


@dataclass
class ProcessSpec:
    """One process to start: its nodes, the executable and its arguments.

    ``name`` is the node's name, or the nodes' names joined by ``, `` for a composed group.
    """

    @property
    def label(self) -> str:
        """How messages name the process."""
        return self.name if len(self.nodes) == 1 else f"the process of {self.name}"

    name: str
    nodes: list[str]
    executable: str
    args: list[str]


def executable(package: str, name: str) -> str:
    """``<prefix>/lib/<package>/<name>`` from the ament index: what ``ros2 run`` executes."""
    from ament_index_python.packages import PackageNotFoundError, get_package_prefix

    from haptic_msgs_py.ament import ensure_ament_prefix

    ensure_ament_prefix()
    try:
        path = Path(get_package_prefix(package)) / "lib" / package / name
    except PackageNotFoundError:
        raise CliError(f"package {package} is not in the ament index; reinstall") from None
    if not os.access(path, os.X_OK):
        raise CliError(f"{path} is missing or not executable; reinstall")
    return str(path)


def parse_sets(items: Sequence[str]) -> dict[str, dict[str, Any]]:
    """``NODE:PARAM=VALUE`` (VALUE in YAML syntax) -> {node: {param: value}}."""
    out: dict[str, dict[str, Any]] = {}
    for item in items:
        node, sep, assignment = item.partition(":")
        param, eq, text = assignment.partition("=")
        if not (sep and eq and node and param):
            raise CliError(f"--set needs NODE:PARAM=VALUE, got {item!r}")
        if node not in NODES:
            raise CliError(f"--set names unknown node {node!r}; nodes: {', '.join(NODES)}")
        try:
            value = yaml.safe_load(text)
        except yaml.YAMLError:
            raise CliError(f"--set {item!r}: the value is not valid YAML") from None
        out.setdefault(node, {})[param] = value
    return out


def resolved_params(config: Path, sets: dict[str, dict[str, Any]]) -> dict[str, Any]:
    """The config's node sections (flattened, ``--set`` applied), keyed by node name."""
    out = load_node_params(config)
    unknown = [n for n in out if n != "/**" and n not in NODES]
    if unknown:
        raise CliError(
            f"{config} names unknown node(s) {', '.join(unknown)}; known: {', '.join(NODES)}"
        )
    for node, values in sets.items():
        out.setdefault(node, {}).update(values)
    return out


def add_recorder(params: dict[str, Any], output: str, storage: str) -> None:
    """A ``recorder_node`` writing ``output``, and the device waiting for it (loses nothing)."""
    if Path(output).exists():
        raise CliError(f"--record {output}: it exists already; the recorder never overwrites a bag")
    params.setdefault("recorder_node", {}).update(output=output, storage=storage)
    device = params.setdefault("device_node", {})
    wait = list(device.get("wait_for", ["environment_node", "observer_node", "controller_node"]))
    if "recorder_node" not in wait:
        device["wait_for"] = [*wait, "recorder_node"]


def add_pinning(params: dict[str, Any]) -> str:
    """``--pin``: each loop node's ``cpu_affinity`` from the critical-path placement
    (``haptic_dob.runtime.cpus``), unless the config (its node section or ``/**``) or ``--set`` gave
    one; returns the plan's text."""
    from haptic_dob.runtime.cpus import available_cpus, describe, placement

    try:
        assigned = placement([n for n in params if n != "/**"], available_cpus())
    except ValueError as exc:
        raise CliError(f"--pin: {exc}") from None
    common = params.get("/**", {}).get("cpu_affinity")
    for name, cpus in assigned.items():
        given = params[name].get("cpu_affinity", common)
        if given is not None and not isinstance(given, list):
            raise CliError(f"cpu_affinity of {name} must be a list of CPU numbers, got {given!r}")
        if given:
            assigned[name] = given
        else:
            params[name]["cpu_affinity"] = cpus
    return describe(assigned)


def add_cpu_latency(params: dict[str, Any], latency_us: int) -> None:
    """``--cpu-latency``: each loop node's ``cpu_latency_us``, unless the config or ``--set``
    gave a request (its node section or ``/**``; -1, no request, counts as not given)."""
    from haptic_dob.runtime.cpu_latency import NO_REQUEST
    from haptic_dob.runtime.cpus import PAIRS

    if not 0 <= latency_us <= 1_000_000:
        raise CliError(f"--cpu-latency {latency_us}: must be 0 to 1000000 us (0: idle CPUs poll)")
    common = params.get("/**", {}).get("cpu_latency_us")
    for name in (n for pair in PAIRS for n in pair if n in params):
        if params[name].get("cpu_latency_us", common) in (None, NO_REQUEST):
            params[name]["cpu_latency_us"] = latency_us


def check_cpu_latency_request(latency_us: int) -> None:
    """Make the request once and withdraw it: a launch that cannot make it stops before any
    node starts, with the reason (``CliError``)."""
    from haptic_dob.runtime.cpu_latency import hold

    try:
        os.close(hold(latency_us))
    except ValueError as exc:
        raise CliError(f"--cpu-latency {latency_us}: {exc}") from None


def write_params_file(params: dict[str, Any], directory: Path) -> Path:
    """A ``ros__parameters`` file any namespace matches (``/**/<node>`` keys), for this launch."""
    doc = {}
    for name, values in params.items():
        key = "/**" if name == "/**" else f"/**/{name}"
        doc[key] = {"ros__parameters": values}
    path = directory / "params.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")
    return path


def groups_for(
    names: Sequence[str], composed: bool, processes: bool, given: Sequence[str]
) -> list[list[str]]:
    """Which of ``names`` share a process: ``--composed`` all, ``--processes`` none,
    ``--group A,B`` (repeatable) the named ones, by default the loop's nodes."""
    if sum((composed, processes, bool(given))) > 1:
        raise CliError("--composed, --processes and --group are different choices: pick one")
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
            raise CliError(f"--group names unknown node(s) {', '.join(unknown)}")
        twice = [n for n in group if n in seen]
        if twice or len(set(group)) != len(group):
            raise CliError(f"--group: {', '.join(twice or group)} named in more than one place")
        seen.update(group)
        groups.append([n for n in group if n in names])
    return groups


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
        raise CliError("the config starts no nodes")
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


NETWORKS = {"localhost": "LOCALHOST", "subnet": "SUBNET"}


def network_env(network: str, peers: Sequence[str]) -> dict[str, str]:
    """The discovery variables for ``--network`` and ``--peers``."""
    if network not in NETWORKS:
        raise CliError(f"--network must be one of {', '.join(NETWORKS)}, got {network!r}")
    env = {"ROS_AUTOMATIC_DISCOVERY_RANGE": NETWORKS[network]}
    if peers:
        if network == "localhost":
            raise CliError("--peers needs --network subnet (peers are other hosts)")
        env["ROS_STATIC_PEERS"] = ";".join(peers)
    return env


def select(names: Sequence[str], only: Sequence[str]) -> list[str]:
    """The nodes named in ``only`` (all when empty); a name the config does not start is an
    error."""
    if not only:
        return list(names)
    unknown = [n for n in only if n not in names]
    if unknown:
        raise CliError(
            f"--only names {', '.join(unknown)}, which the config does not start "
            f"(it starts {', '.join(sorted(names))})"
        )
    return [n for n in names if n in only]


def launch(
    specs: list[ProcessSpec],
    stop_timeout: float,
    duration: float | None,
    env: dict[str, str] | None = None,
) -> int:
    """Start the processes, supervise them, forward signals, stop them all cleanly."""
    stop: list[int] = []

    def on_signal(signum: int, _frame: object) -> None:
        stop.append(signum)

    old = {s: signal.signal(s, on_signal) for s in (signal.SIGINT, signal.SIGTERM)}
    procs: dict[str, subprocess.Popen] = {}
    labels = {s.name: s.label for s in specs}
    device = next((s.name for s in specs if "device_node" in s.nodes), None)
    code = 0
    try:
        for spec in specs:
            procs[spec.name] = subprocess.Popen(
                [spec.executable, *spec.args],
                start_new_session=True,
                env={**os.environ, **(env or {})},
            )
        t_end = None if duration is None else time.monotonic() + duration
        while not stop:
            done = {n: p.returncode for n, p in procs.items() if p.poll() is not None}
            if done:
                name, rc = next(iter(done.items()))
                if name == device and rc == 0:
                    print(
                        "haptic-launch: device_node finished its run; stopping the graph",
                        file=sys.stderr,
                    )
                else:
                    print(
                        f"ERROR: {labels[name]} exited with code {rc}; stopping the graph",
                        file=sys.stderr,
                    )
                    code = 1
                break
            if t_end is not None and time.monotonic() >= t_end:
                break
            time.sleep(0.05)
    finally:
        _stop_all(procs, stop_timeout, device)
        for s, h in old.items():
            signal.signal(s, h)
    return code


def _stop_all(procs: dict[str, subprocess.Popen], timeout: float, first: str | None) -> None:
    """SIGTERM to every live process (the device's first), wait, then SIGKILL what is left.

    A node that runs handles SIGTERM as Ctrl-C (``run_nodes``); one still importing its modules
    ends quietly, where SIGINT would print a ``KeyboardInterrupt`` traceback.
    """
    order = sorted(procs, key=lambda n: n != first)
    for name in order:
        p = procs[name]
        if p.poll() is None:
            p.send_signal(signal.SIGTERM)
    deadline = time.monotonic() + timeout
    for name in order:
        p = procs[name]
        try:
            p.wait(max(0.0, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            print(
                f"haptic-launch: {name} did not stop within {timeout:g} s; killing it",
                file=sys.stderr,
            )
            p.kill()
            p.wait()


def normalize_namespace(namespace: str) -> str:
    """``slide1`` -> ``/slide1`` (ROS wants it absolute); ``CliError`` for an invalid name."""
    ns = namespace.strip()
    if not ns:
        return ""
    ns = "/" + ns.strip("/")
    if not re.fullmatch(r"(/[A-Za-z_][A-Za-z0-9_]*)+", ns):
        raise CliError(
            f"--namespace {namespace!r} is not a valid ROS namespace (letters, digits and _ "
            "separated by /, each part not starting with a digit)"
        )
    return ns


RT_PRIORITIES = range(1, 100)  # SCHED_FIFO priorities Linux accepts


def set_rt_priority(priority: int) -> None:
    """Run this process (and the processes and threads it starts) with ``SCHED_FIFO``.

    Raises ``CliError`` with the reason when the system does not allow it.
    """
    if priority not in RT_PRIORITIES:
        raise CliError(f"--rt-priority {priority}: must be 1 to 99 (SCHED_FIFO priorities)")
    if not hasattr(os, "sched_setscheduler"):
        raise CliError("--rt-priority: this system has no SCHED_FIFO scheduling (Linux only)")
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
    except PermissionError as exc:
        raise CliError(
            f"--rt-priority {priority}: not permitted ({exc.strerror}); it needs root, "
            "CAP_SYS_NICE, or an rtprio limit (limits.conf) of at least that priority"
        ) from None


@dataclass(frozen=True)
class LaunchOptions:
    """What ``haptic-launch`` was asked for (its command line, parsed)."""

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


def command(opts: LaunchOptions) -> int:
    """Resolve, plan and run; raises ``CliError`` on bad input."""
    import tempfile

    namespace = normalize_namespace(opts.namespace)
    path = resolve_config(opts.config)
    params = resolved_params(path, parse_sets(opts.sets))
    if opts.record:
        add_recorder(params, opts.record, opts.record_storage)
    names = select([n for n in START_ORDER if n in params], opts.only)
    groups = groups_for(names, opts.composed, opts.processes, opts.groups)
    if opts.pin:
        shared = [g for g in groups if len(g) > 1]
        if shared:
            raise CliError(
                f"--pin places node processes on CPUs, and {', '.join(shared[0])} share one "
                "(the loop is composed by default): add --processes"
            )
        print(f"haptic-launch: CPUs {add_pinning(params)}", file=sys.stderr)
    if opts.cpu_latency_us is not None:
        add_cpu_latency(params, opts.cpu_latency_us)
        check_cpu_latency_request(opts.cpu_latency_us)
    net = network_env(opts.network, opts.peers)
    if opts.rt_priority is not None:  # the nodes started below inherit the policy
        set_rt_priority(opts.rt_priority)
    if opts.executor:
        net["HAPTIC_DOB_EXECUTOR"] = opts.executor
    with tempfile.TemporaryDirectory(prefix="haptic-launch-") as tmp:
        chosen = {n: v for n, v in params.items() if n == "/**" or n in names}
        specs = plan(chosen, write_params_file(params, Path(tmp)), namespace, groups)
        for spec in specs:
            if len(spec.nodes) > 1:
                print(f"haptic-launch: {', '.join(spec.nodes)} in one process", file=sys.stderr)
        return launch(specs, opts.stop_timeout, opts.duration, net)


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``haptic-launch``."""
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
        help="these nodes share a process (repeatable; nodes in no group run alone)",
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
        help="start only these nodes of the config (split a session across hosts)",
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
        "root or CAP_SYS_NICE): fewer late commands in real time (BENCHMARKS.md)",
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
    a = p.parse_args(argv)
    only = [n for n in a.only.split(",") if n]
    peers = [h for h in a.peers.split(",") if h]
    return run(
        lambda: command(
            LaunchOptions(
                config=a.config,
                namespace=a.namespace,
                sets=a.set,
                composed=a.composed,
                processes=a.processes,
                groups=a.group,
                stop_timeout=a.stop_timeout,
                duration=a.duration,
                executor=a.executor,
                only=only,
                network=a.network,
                peers=peers,
                record=a.record,
                record_storage=a.record_storage,
                rt_priority=a.rt_priority,
                pin=a.pin,
                cpu_latency_us=a.cpu_latency,
            )
        )
    )


if __name__ == "__main__":
    sys.exit(main())
