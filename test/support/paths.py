"""The repository, the installed tools, and what this test run may do on the machine."""

from __future__ import annotations

import os
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


def can_request_cpu_latency() -> bool:
    """Whether this test run may make PM QoS requests: the device opens for writing (root, and
    no container rule against it). An open without a write makes no request."""
    try:
        os.close(os.open(PM_QOS_PATH, os.O_RDWR))
    except OSError:
        return False
    return True
