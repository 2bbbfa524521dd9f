"""A node's health as its ``/diagnostics`` reports it, without ROS (``runtime.ros.diagnostics``
publishes it): a warning or not, a one-line message, the values."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Status:
    """One node's status: ``warning`` (else OK), what it says, the values it reports."""

    warning: bool
    message: str
    values: Mapping[str, Any]
