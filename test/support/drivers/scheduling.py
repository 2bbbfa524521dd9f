"""The loop's real-time set-up where this machine allows it, as docs/devices.md tells a lab.

``haptic-launch --rt-priority 50`` (the test driver's priority, as a controller manager's
thread) on two CPUs or more, and ``--cpu-latency 0`` (idle CPUs poll: a virtual machine's halted
CPU waits for its host to wake); each where this process could make the request, else left out
(``launch_args``), and said in a test's figures (``described``).
"""

from __future__ import annotations

import functools
import os

from support.drivers.run import DRIVER_RT_PRIORITY
from support.paths import can_request_cpu_latency, can_use_fifo


@functools.cache
def priority_args() -> tuple[str, ...]:
    """``--rt-priority`` where this machine allows it now (a teleoperation's launch takes no
    ``--cpu-latency``)."""
    if len(os.sched_getaffinity(0)) < 2:  # on one CPU a FIFO loop would hold the driver off
        return ()
    return ("--rt-priority", str(DRIVER_RT_PRIORITY)) if can_use_fifo(DRIVER_RT_PRIORITY) else ()


def launch_args() -> tuple[str, ...]:
    """``haptic-launch`` options of the loop's real-time set-up this machine allows now."""
    return priority_args() + (("--cpu-latency", "0") if can_request_cpu_latency() else ())


def described() -> str:
    """How the loop runs, for a test's figures."""
    args = launch_args()
    return f"the loop under {' '.join(args)}" if args else "the loop under default scheduling"
