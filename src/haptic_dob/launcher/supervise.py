"""The launch's processes at run time: the scheduling and wake-up latency they start with, then
start, watch (a failed node stops the graph, and so does the end of the run once every device
finished its own; one that runs until stopped is not waited for), forward Ctrl-C, SIGTERM and
SIGHUP, and stop them all (the device's first), killing what outlives the stop timeout. Should
the launcher itself die, each process gets SIGTERM (``runtime.entry.follow_launcher``)."""

from __future__ import annotations

import functools
import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Collection

from haptic_dob.errors import InputError
from haptic_dob.launcher.process_plan import ProcessSpec
from haptic_dob.runtime.cpu_latency import hold
from haptic_dob.runtime.entry import LAUNCHER_PID

#: what stops the graph in order: Ctrl-C, SIGTERM, and the terminal closing (SIGHUP: the nodes
#: run in sessions of their own, so only the launcher hears it)
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
RT_PRIORITIES = range(1, 100)  # SCHED_FIFO priorities Linux accepts
#: nodes whose finished run ends the graph: a device's (lockstep) run, a bridge's duration_s
RUN_ENDS = ("device_node", "bridge_node")


def set_rt_priority(priority: int) -> None:
    """Run this process (and the processes and threads it starts) with ``SCHED_FIFO``.

    Raises ``InputError`` with the reason when the system does not allow it.
    """
    if priority not in RT_PRIORITIES:
        raise InputError(f"--rt-priority {priority}: must be 1 to 99 (SCHED_FIFO priorities)")
    if not hasattr(os, "sched_setscheduler"):
        raise InputError("--rt-priority: this system has no SCHED_FIFO scheduling (Linux only)")
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
    except PermissionError as exc:
        raise InputError(
            f"--rt-priority {priority}: not permitted ({exc.strerror}); it needs root, "
            "CAP_SYS_NICE, or an rtprio limit (limits.conf) of at least that priority"
        ) from None


def off_path_scheduling() -> Callable[[], None] | None:
    """What a process off the command's path runs before its program starts, when this process
    runs under ``SCHED_FIFO`` (``--rt-priority``, which node processes inherit): back to normal
    scheduling. At the loop's priority such a process (a recorder writing its bag) held a CPU
    from the driver and the loop for milliseconds at a time. None otherwise."""
    if not hasattr(os, "sched_getscheduler") or os.sched_getscheduler(0) != os.SCHED_FIFO:
        return None
    # made here: the child only makes the call (a preexec_fn runs between fork and exec)
    return functools.partial(os.sched_setscheduler, 0, os.SCHED_OTHER, os.sched_param(0))


def check_cpu_latency_request(latency_us: int) -> None:
    """Make the request once and withdraw it: a launch that cannot make it stops before any
    node starts, with the reason (``InputError``)."""
    try:
        os.close(hold(latency_us))
    except ValueError as exc:
        raise InputError(f"--cpu-latency {latency_us}: {exc}") from None


def launch(
    specs: list[ProcessSpec],
    stop_timeout: float,
    duration: float | None,
    env: dict[str, str] | None = None,
    endless: Collection[str] = (),
) -> int:
    """Start the processes, supervise them, forward signals, stop them all cleanly.

    Returns the exit code: 0 for a stop asked for (a signal, ``duration`` s, the device's
    finished run), 1 when a process ended by itself otherwise. ``endless``: device or bridge
    nodes that run until stopped (``duration_s`` 0), whose processes no finished run waits for.
    """
    stop: list[int] = []

    def on_signal(signum: int, _frame: object) -> None:
        stop.append(signum)

    old = {s: signal.signal(s, on_signal) for s in STOP_SIGNALS}
    procs: dict[str, subprocess.Popen[bytes]] = {}
    labels = {s.name: s.label for s in specs}
    devices = {
        s.name
        for s in specs
        if any(n.rsplit("/", 1)[-1] in RUN_ENDS and n not in endless for n in s.nodes)
    }
    code = 0
    normal = off_path_scheduling()
    try:
        for spec in specs:
            procs[spec.name] = subprocess.Popen(
                [spec.executable, *spec.args],
                start_new_session=True,
                env={**os.environ, **(env or {}), LAUNCHER_PID: str(os.getpid())},
                preexec_fn=normal if spec.off_path else None,
            )
        t_end = None if duration is None else time.monotonic() + duration
        while not stop:
            done = {n: p.returncode for n, p in procs.items() if p.poll() is not None}
            failed = [(n, rc) for n, rc in done.items() if n not in devices or rc != 0]
            if failed:
                name, rc = failed[0]
                print(
                    f"ERROR: {labels[name]} exited with code {rc}; stopping the graph",
                    file=sys.stderr,
                )
                code = 1
                break
            if done and devices <= set(done):  # every device finished its run (a teleop: two)
                print(
                    "haptic-launch: the device (or bridge) finished its run; stopping the graph",
                    file=sys.stderr,
                )
                break
            if t_end is not None and time.monotonic() >= t_end:
                break
            time.sleep(0.05)
    finally:
        _stop_all(procs, stop_timeout, devices)
        for s, h in old.items():
            signal.signal(s, h)
    return code


def _stop_all(procs: dict[str, subprocess.Popen[bytes]], timeout: float, first: set[str]) -> None:
    """SIGTERM to every live process (the ``first`` ones first: the devices), wait up to
    ``timeout`` s, then SIGKILL what is left.

    A node that runs handles SIGTERM as Ctrl-C (``run_nodes``); one still importing its modules
    ends quietly, where SIGINT would print a ``KeyboardInterrupt`` traceback.
    """
    order = sorted(procs, key=lambda n: n not in first)
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
