"""The loop's real-time set-up where this machine allows it, as docs/devices.md tells a lab.

``haptic-launch --rt-priority 50`` (the test driver's priority, as a controller manager's
thread) on two CPUs or more, and ``--cpu-latency 0`` (idle CPUs poll: a virtual machine's halted
CPU waits for its host to wake); each where this process could make the request, else left out
(``launch_args``), and said in a test's figures (``described``).
"""

from __future__ import annotations

import functools
import os
import subprocess
import sys

from support.drivers.run import DRIVER_RT_PRIORITY
from support.paths import can_request_cpu_latency


@functools.cache
def priority_args() -> tuple[str, ...]:
    """``--rt-priority`` where this machine allows it now (a teleoperation's launch takes no
    ``--cpu-latency``)."""
    if len(os.sched_getaffinity(0)) < 2:  # on one CPU a FIFO loop would hold the driver off
        return ()
    probe = (
        f"import os; os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param({DRIVER_RT_PRIORITY}))"
    )
    tried = subprocess.run([sys.executable, "-c", probe], capture_output=True, timeout=60)
    return ("--rt-priority", str(DRIVER_RT_PRIORITY)) if tried.returncode == 0 else ()


def launch_args() -> tuple[str, ...]:
    """``haptic-launch`` options of the loop's real-time set-up this machine allows now."""
    return priority_args() + (("--cpu-latency", "0") if can_request_cpu_latency() else ())


def described() -> str:
    """How the loop runs, for a test's figures."""
    args = launch_args()
    return f"the loop under {' '.join(args)}" if args else "the loop under default scheduling"
