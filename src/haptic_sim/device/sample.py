"""What every simulated device gives the loop: one ``DeviceSample`` per control cycle.

Cycle contract: ``sample()`` returns sample k (stamp ``k * period_ns``); ``apply(effort)`` holds
that effort over [k, k+1) (zero-order hold), integrates the physics and moves to k+1. The sample's
``effort`` is what the actuators applied over [k-1, k) after saturation (zero at k = 0): exactly
what the observer needs with sample k.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

from haptic_dob.core.models.base import DeviceModel

Vec3 = tuple[float, float, float]


@dataclass(frozen=True, slots=True)
class DeviceSample:
    """Everything a device reports at sample k (SI units; tuples of floats)."""

    k: int
    stamp_ns: int
    q: tuple[float, ...]
    qd: tuple[float, ...]
    effort: tuple[float, ...]
    ee_position: Vec3
    ee_velocity: Vec3
    wrench_measured: Vec3
    hand_force: Vec3


class SimulatedDevice(Protocol):
    """A simulated device stepping in the cycle contract."""

    model: DeviceModel
    period_ns: int
    dof: int
    max_effort: tuple[float, ...]  # actuator saturation per joint (N or N m)

    @property
    def k(self) -> int: ...

    def sample(self) -> DeviceSample: ...

    def apply(self, effort: list[float] | tuple[float, ...]) -> None: ...

    def prepare(self) -> None:
        """Optional work ahead of the next ``apply`` (changes no sample; a real-time device calls it
        while it waits for a command)."""
