"""Run nodes: one context, one executor, our own SIGINT/SIGTERM handling, a clean shutdown.

``spin_once`` with a timeout, in a loop that watches a signal flag (Jazzy's
``EventsExecutor.spin()`` does not return on SIGINT/SIGTERM; docs/running.md). Nodes may ask to
be woken at a time (``next_wakeup``) for real-time ticks, and may say they are ``finished``. An
exception out of any node's callback ends the process, but first every node's ``on_shutdown``
runs (``last_words``): a device or a bridge to a real driver sends its zero.

At a clean stop (``runtime.ros.stop``) an observer first works off the inputs still coming, then
every process waits for its reliable readers' acknowledgements. A device zeroes its effort at
once. A process stops when each of its nodes that ends its run by itself (``finishes_run``) has
finished.
"""

from __future__ import annotations

import cProfile
import gc
import os
import signal
import sys
import time
from collections.abc import Callable, Iterable, Sequence
from typing import Any

import rclpy
from rclpy._rclpy_pybind11 import RCLError, UnknownROSArgsError
from rclpy.context import Context
from rclpy.exceptions import InvalidParameterValueException, ParameterException
from rclpy.executors import Executor, SingleThreadedExecutor
from rclpy.experimental.events_executor import EventsExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.signals import SignalHandlerOptions
from rclpy.time import Time
from rclpy.utilities import try_shutdown

from haptic_dob.runtime.cpu_latency import NO_REQUEST, hold, strictest
from haptic_dob.runtime.cpus import checked_cpus, pin_process
from haptic_dob.runtime.params import ParamSpec
from haptic_dob.runtime.ros.dds_profile import use_default_profile
from haptic_dob.runtime.ros.log import LoopLog
from haptic_dob.runtime.ros.params import ParameterTable
from haptic_dob.runtime.ros.stop import (
    DRAIN_BUDGET_S,
    last_words,
    wait_for_acknowledgements,
    work_off,
)
from haptic_dob.runtime.ros_args import shadow_line, shadowed
from haptic_msgs_py.bus import bus_for

EXECUTORS = ("events", "single")
WORK_OFF_S = 10.0  # ... or, a backstop, after this long
#: while nodes of this process hand the loop around in process (lockstep), the executor (DDS
#: from other processes, services, timers) gets a turn at least this often (s)
SOON_SLICE_S = 0.004


class _LoopTimeOnce:
    """Stands in for a node's clock for one ``now()``: the loop's stamp, then the real clock."""

    def __init__(self, node: Node, real: Any, stamp_ns: int) -> None:
        self.node, self.real, self.stamp_ns = node, real, stamp_ns

    def now(self) -> Time:
        self.node._clock = self.real
        return Time(nanoseconds=self.stamp_ns, clock_type=self.real.clock_type)


class LoopNode(Node):
    """A node the spin loop can wake at a time, tell to shut down, and ask whether it is done.

    Its parameter events are stamped on the loop's timeline: with the stamp of the first sample
    the change applies to (``next_sample_ns``), once the loop runs. A session's analysis then
    splits at that sample however late the event reaches a recorder (a reliable sample lost in
    transit is repaired at the writer's next heartbeat, seconds later). Before the first sample
    the stamp is the node's clock, as for any node.
    """

    finished: bool = False
    exit_code: int = 0
    finishes_run: bool = False  # it ends its run by itself: the process waits for it to finish

    def __init__(self, node_name: str, *, specs: Iterable[ParamSpec] = (), **kwargs: Any) -> None:
        """A node named ``node_name`` (``kwargs``: rclpy's ``Node``'s) that declares ``specs``
        as its parameters (``params``): the subclass reads their start-up values, builds its
        objects, then installs its validator (``params.set_validator``)."""
        super().__init__(node_name, **kwargs)
        #: the logger for the loop's callbacks (rclpy's costs 0.3-90 ms a call: ``log``)
        self.log = LoopLog(self.get_logger())
        self.add_post_set_parameters_callback(self._clock_back)
        self.params = ParameterTable(self, specs, accepted=self._stamp_on_loop_time)

    def next_sample_ns(self) -> int | None:
        """Stamp (ns) of the first sample a parameter change made now applies to (None: the
        loop has not run yet)."""
        return None

    def _stamp_on_loop_time(self, params: list[Parameter]) -> None:
        """An accepted change's event gets the loop's stamp (``ParameterTable``'s ``accepted``:
        called after the node's objects are built, never during the declaration)."""
        stamp = self.next_sample_ns()
        if stamp is not None and not any(p.name == "use_sim_time" for p in params):
            self._clock = _LoopTimeOnce(self, self._clock, stamp)  # type: ignore[assignment]  # a stand-in clock that rclpy's event stamping reads

    def _clock_back(self, _params: list[Parameter]) -> None:
        if isinstance(self._clock, _LoopTimeOnce):
            self._clock = self._clock.real

    def next_wakeup(self) -> float | None:
        """Monotonic time (s) at which ``on_wakeup`` should run, or None."""
        return None

    def on_wakeup(self, now: float) -> None:
        """Called at or after ``next_wakeup``."""

    def on_shutdown(self) -> None:
        """Last work before the node is destroyed (for example: zero the effort)."""

    def drain_marker(self) -> int | None:
        """A value that changes while the node works off inputs; None: do not drain at a stop."""
        return None

    def cpu_affinity(self) -> list[float]:
        """The CPUs its ``cpu_affinity`` parameter asks for ([] = not pinned)."""
        return list(self.params.values.get("cpu_affinity", []))

    def cpu_latency_us(self) -> int:
        """The CPU wake-up bound its ``cpu_latency_us`` parameter asks for (-1 = none), us."""
        return int(self.params.values.get("cpu_latency_us", NO_REQUEST))


def pin_to_asked_cpus(nodes: Sequence[Node]) -> None:
    """Pin this process to the CPUs its loop nodes ask for (their union; none asked: no change).

    ``ValueError`` with the reason when a CPU is not usable.
    """
    asked = [c for n in nodes if isinstance(n, LoopNode) for c in n.cpu_affinity()]
    if not asked:
        return
    cpus = checked_cpus(asked)
    pin_process(cpus)
    nodes[0].get_logger().info(f"process pinned to CPU {', '.join(map(str, cpus))}")


def hold_asked_cpu_latency(nodes: Sequence[Node]) -> int | None:
    """Hold the strictest ``cpu_latency_us`` its loop nodes ask for; the descriptor, or None.

    ``ValueError`` with the reason when the request cannot be made.
    """
    bound = strictest([n.cpu_latency_us() for n in nodes if isinstance(n, LoopNode)])
    if bound == NO_REQUEST:
        return None
    fd = hold(bound)
    nodes[0].get_logger().info(f"CPU wake-up latency held at {bound} us (PM QoS) while it runs")
    return fd


def say_shadowed(nodes: Sequence[Node], argv: Sequence[str]) -> None:
    """Each node says, in one line, which ``-p`` values of ``argv`` a params file's section
    overrode for it, and what to type instead (``haptic_dob.runtime.ros_args``)."""
    for node in nodes:
        fqn = node.get_fully_qualified_name()
        found = shadowed(argv, fqn)
        if found:
            node.get_logger().warning(shadow_line(found, fqn))


def run_over(nodes: Sequence[LoopNode]) -> bool:
    """Whether the spin loop stops: a node finished with an error or without ending a run of its
    own, or every node that ends its run by itself (``finishes_run``) has finished."""
    done = [n for n in nodes if n.finished]
    if not done:
        return False
    if any(n.exit_code or not n.finishes_run for n in done):
        return True
    return all(n.finished for n in nodes if n.finishes_run)


def make_executor(kind: str, context: Context) -> Executor:
    """``events`` (rclpy.experimental.EventsExecutor, the default) or ``single``."""
    if kind == "events":
        return EventsExecutor(context=context)
    if kind == "single":
        return SingleThreadedExecutor(context=context)
    raise ValueError(f"executor must be one of {', '.join(EXECUTORS)}, got {kind!r}")


def run_nodes(
    make_nodes: Callable[[Context], Sequence[Node]],
    args: Sequence[str] | None = None,
    executor: str | None = None,
) -> int:
    """Create the nodes in a fresh context and spin them until a signal or until one finishes.

    Returns the process exit code: 0 after a clean stop (signal or a node finished), a finished
    node's non-zero ``exit_code``, or 2 when a parameter was refused at start-up.
    """
    kind = executor or os.environ.get("HAPTIC_DOB_EXECUTOR", "events")
    use_default_profile()
    context = Context()
    argv = list(args) if args is not None else sys.argv
    try:
        rclpy.init(
            args=argv,
            context=context,
            signal_handler_options=SignalHandlerOptions.NO,
        )
    except RCLError as exc:  # a bad --ros-args (for example a params file that does not parse)
        text = " ".join(str(exc).split()).split(", at /")[0]
        print(f"ERROR: {text}", file=sys.stderr)
        return 2
    except UnknownROSArgsError as exc:  # e.g. --ros-args --help
        print(
            f"ERROR: unknown ROS argument(s) {str(exc).strip('[]')}: after --ros-args come "
            "-p NAME:=VALUE, "
            "--params-file FILE, -r FROM:=TO, --log-level LEVEL ...; --help before --ros-args "
            "lists the parameters",
            file=sys.stderr,
        )
        return 2
    received: list[int] = []

    def on_signal(signum: int, _frame: object) -> None:
        received.append(signum)

    old = {s: signal.signal(s, on_signal) for s in (signal.SIGINT, signal.SIGTERM)}
    nodes: list[Node] = []
    latency_fd: int | None = None
    try:
        try:
            nodes = list(make_nodes(context))
            pin_to_asked_cpus(nodes)
            latency_fd = hold_asked_cpu_latency(nodes)
            say_shadowed(nodes, argv)
        except InvalidParameterValueException as exc:
            text = " ".join(str(exc).split())  # "... Reason: <reason>: <name>"
            reason, _, name = (text.partition("Reason: ")[2] or text).rpartition(": ")
            print(f"ERROR: parameter {name} refused: {reason}", file=sys.stderr)
            return 2
        except (ParameterException, ValueError) as exc:
            print(f"ERROR: {' '.join(str(exc).split())}", file=sys.stderr)
            return 2
        ex = make_executor(kind, context)
        for n in nodes:
            ex.add_node(n)
        loop_nodes = [n for n in nodes if isinstance(n, LoopNode)]
        gc.collect()
        gc.freeze()  # keep the collector off the long-lived objects ...
        gc.set_threshold(50_000, 20, 20)  # ... and run it rarely: the loop makes few cycles
        profile_dir = os.environ.get("HAPTIC_DOB_PROFILE")
        if profile_dir:  # developer aid: per-process cProfile of the spin loop
            prof = cProfile.Profile()
            prof.enable()
        spin_once = ex.spin_once
        monotonic = time.monotonic
        bus = bus_for(context)
        try:
            while not received and context.ok():
                if run_over(loop_nodes):
                    break
                now = monotonic()
                timeout = 0.05
                due_nodes = False
                for n in loop_nodes:
                    due = n.next_wakeup()
                    if due is not None:
                        due_nodes = True
                        timeout = min(timeout, due - now)
                if bus.soon:  # nodes composed here turn the loop over in process (lockstep)
                    bus.run_soon(SOON_SLICE_S)
                    spin_once(timeout_sec=0.0)  # then the executor gets a turn
                elif timeout > 0.0:
                    spin_once(timeout_sec=timeout)
                if due_nodes:
                    now = monotonic()
                    for n in loop_nodes:
                        due = n.next_wakeup()
                        if due is not None and due <= now:
                            n.on_wakeup(now)
        except Exception:
            last_words(loop_nodes)  # an error in any node: a device's zero still goes out
            raise
        if profile_dir:
            prof.disable()
            prof.dump_stats(os.path.join(profile_dir, f"{nodes[0].get_name()}.prof"))
        if loop_nodes and all(n.drain_marker() is not None for n in loop_nodes):
            work_off(spin_once, loop_nodes, monotonic() + WORK_OFF_S)
        for n in loop_nodes:
            n.on_shutdown()
        wait_for_acknowledgements(nodes, monotonic() + DRAIN_BUDGET_S)
        ex.shutdown(timeout_sec=1.0)
        codes = [n.exit_code for n in loop_nodes if n.finished and n.exit_code]
        return codes[0] if codes else 0
    finally:
        for n in nodes:
            n.destroy_node()
        try_shutdown(context=context)
        if latency_fd is not None:  # the request ends with the loop
            os.close(latency_fd)
        for s, h in old.items():
            signal.signal(s, h)
