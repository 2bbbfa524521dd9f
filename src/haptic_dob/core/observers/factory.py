"""Build an observer from its settings: the disturbance observer or the momentum observer."""

from __future__ import annotations

from dataclasses import dataclass, field

from haptic_dob.core.models.base import DeviceModel
from haptic_dob.core.observers.disturbance import DEFAULT_GAIN, DisturbanceObserver
from haptic_dob.core.observers.momentum import MomentumObserver
from haptic_dob.core.validation import nonnegative, positive
from haptic_dob.runtime.params import param

#: the observers: the disturbance observer (this module), the generalized-momentum observer
#: (``haptic_dob.core.observers.momentum``)
OBSERVER_KINDS = ("dob", "momentum")


@dataclass(frozen=True)
class ObserverSettings:
    """Observer kind, gain and output clip, as the observer node and batch runs take them."""

    gain: float = field(
        default=DEFAULT_GAIN,
        metadata=param(
            description=(
                "observer gain: dob c (N s/m prismatic, N m s/rad revolute), momentum K (1/s)"
            ),
            bounds=(1e-6, 1e6),
        ),
    )
    output_limit: float = field(
        default=0.0,
        metadata=param(
            description="clip of the estimated joint effort; 0 = no clip",
            unit="N or N m",
            bounds=(0.0, 1e6),
            details="The slide sessions use the thesis's 4 N.",
        ),
    )
    kind: str = field(
        default="dob",
        metadata=param(
            description=(
                "observer: dob (lag D/c per joint) or momentum (lag 1/gain on every joint)"
            ),
            choices=OBSERVER_KINDS,
            read_only=True,
            details=("dob: the disturbance observer; momentum: the generalized-momentum observer."),
        ),
    )

    def __post_init__(self) -> None:
        if self.kind not in OBSERVER_KINDS:
            raise ValueError(f"kind must be one of {', '.join(OBSERVER_KINDS)}, got {self.kind!r}")
        positive("gain", self.gain)
        nonnegative("output_limit", self.output_limit)

    def build(self, model: DeviceModel, dt: float) -> DisturbanceObserver:
        """The observer for ``model`` at period ``dt`` (s)."""
        if self.kind == "momentum":
            return MomentumObserver(model, self.gain, dt, self.output_limit or None)
        return DisturbanceObserver(model, self.gain, dt, self.output_limit or None)
