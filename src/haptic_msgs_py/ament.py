"""Make the ament index of this Python environment visible without exporting anything.

The ROS 2 wheels on PyPI install their ``share/ament_index`` into ``sys.prefix`` but never set
``AMENT_PREFIX_PATH``; without it ``ament_index_python`` (and so ``ros2 run``) finds nothing.
``ensure_ament_prefix`` appends ``sys.prefix`` when it is missing and keeps whatever a sourced
ROS installation already put there. The project's ``.pth`` file calls it at interpreter start.
"""

from __future__ import annotations

import os
import sys


def ensure_ament_prefix(prefix: str | None = None) -> str:
    """Append ``prefix`` (default ``sys.prefix``) to ``AMENT_PREFIX_PATH``; return the new value."""
    prefix = prefix or sys.prefix
    parts = [p for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    if prefix not in parts:
        parts.append(prefix)
    value = os.pathsep.join(parts)
    os.environ["AMENT_PREFIX_PATH"] = value
    return value
