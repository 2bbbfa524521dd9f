"""What the simulated device's loop needs from its node (``LoopPort``) and where it says what it
does (``Log``): the seam between ``haptic_sim.device.loop`` and the ROS node around it."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol

from haptic_sim.device.sample import DeviceSample


class LoopPort(Protocol):
    """What the loop needs from its node: the topics, deferred work and the ROS graph."""

    def publish(self, sample: DeviceSample) -> None:
        """Send sample k to every topic."""

    def call_soon(self, work: Callable[[], None]) -> None:
        """Run ``work`` once the publishes under way have returned (at once when none is)."""

    def waiting_for(self) -> str:
        """What the start still waits for in the graph ('' when nothing)."""

    def recorders(self) -> int:
        """How many recorders report their progress."""

    def cycled(self) -> None:
        """One cycle ran (for the loop rate in the diagnostics)."""

    def finish(self) -> None:
        """The run is over: the node may stop."""


class Log(Protocol):
    """Where the loop says what it does (a ROS logger: ``throttle_duration_sec`` and so on)."""

    def info(self, message: str, **kwargs: Any) -> Any: ...

    def warning(self, message: str, **kwargs: Any) -> Any: ...
