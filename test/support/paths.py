"""The repository, the installed tools, and what this test run may do on the machine."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from haptic_dob.runtime.cpu_latency import PM_QOS_PATH

ROOT = Path(__file__).resolve().parents[2]
BIN = Path(sys.executable).parent


def tool(name: str) -> str:
    """Path of a console script installed next to the running interpreter."""
    path = BIN / name
    assert path.exists(), f"{name} is not installed in {BIN}"
    return str(path)


def can_use_fifo(priority: int) -> bool:
    """Whether a process started now may run under ``SCHED_FIFO`` at ``priority`` (root,
    CAP_SYS_NICE or an rtprio limit; tried in a process of its own)."""
    if not hasattr(os, "sched_setscheduler"):
        return False
    probe = f"import os; os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param({priority}))"
    return (
        subprocess.run([sys.executable, "-c", probe], capture_output=True, timeout=60).returncode
        == 0
    )


def can_request_cpu_latency() -> bool:
    """Whether this test run may make PM QoS requests: the device opens for writing (root, and
    no container rule against it). An open without a write makes no request."""
    try:
        os.close(os.open(PM_QOS_PATH, os.O_RDWR))
    except OSError:
        return False
    return True
