"""Settings of the simulated arm (``haptic_sim.arm.device``): actuators (and the effort limits
they give), encoders, start, hand, force.

Defaults are the PHANToM Premium 1.5's: ``max_force_n`` 8.5 N, the peak ("maximum exertable")
force SensAble specifies at its nominal position (continuous force is about 1.4 N; the thesis
rounds it to 10 N, section 5.2), and ``encoder_resolution_rad`` 1.5e-4 rad, SensAble's 0.03 mm
nominal tip resolution over the PHANToM 1.5's ~0.2 m links (0 = ideal encoders).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import cast

import numpy as np

from haptic_dob.core.models.base import DeviceModel, Vec
from haptic_dob.core.validation import nonnegative, positive, unit_vector, vector
from haptic_dob.runtime.params import param

#: SensAble PHANToM Premium 1.5: maximum exertable force at the nominal position (N)
PHANTOM_15_PEAK_FORCE_N = 8.5
#: PHANToM 1.5 joint resolution: 0.03 mm nominal tip resolution over ~0.2 m links (rad)
PHANTOM_15_ENCODER_RAD = 1.5e-4
#: where the reported joint velocity comes from
VELOCITY_SOURCES = ("difference", "exact")


@dataclass(frozen=True)
class ArmDeviceParams:
    """The simulated arm's actuators, encoders, start, hand geometry and external force."""

    max_force_n: float = field(
        default=PHANTOM_15_PEAK_FORCE_N,
        metadata=param(
            description="tip force the joint limits are derived from (PHANToM 1.5 peak)",
            unit="N",
            bounds=(1e-3, 1e4),
        ),
    )
    joint_effort_limits: list[float] | tuple[float, ...] = field(
        default_factory=list,
        metadata=param(
            description="per-joint effort limits; [] = from the model or max_force_n", unit="N m"
        ),
    )
    encoder_resolution_rad: float = field(
        default=PHANTOM_15_ENCODER_RAD,
        metadata=param(
            description="joint encoder resolution; 0 = ideal", unit="rad", bounds=(0.0, 0.1)
        ),
    )
    encoder_matrix: list[float] | tuple[float, ...] = field(
        default_factory=list,
        metadata=param(
            description="encoders' rows over the joints, flattened; [] = one per joint",
        ),
    )
    initial_position: list[float] | tuple[float, ...] = field(
        default_factory=list,
        metadata=param(
            description="joint angles at start; [] = the model's home (PHANToM) or zeros",
            unit="rad",
        ),
    )
    hand_direction: tuple[float, float, float] = field(
        default=(0.0, 0.0, -1.0),
        metadata=param(description="direction of the hand's push (unit 3-vector, base frame)"),
    )
    hand_lateral_amplitude_m: float = field(
        default=0.0,
        metadata=param(
            description="std of the semi-random hand motion across the push",
            unit="m",
            bounds=(0.0, 1.0),
        ),
    )
    external_force_n: tuple[float, float, float] = field(
        default=(0.0, 0.0, 0.0),
        metadata=param(description="known external force on the end effector (x, y, z)", unit="N"),
    )
    external_force_at_s: float = field(
        default=0.0,
        metadata=param(description="time the external force steps on", unit="s", bounds=(0.0, 1e6)),
    )
    velocity: str = field(
        default="difference",
        metadata=param(
            description=(
                "joint velocity reported: backward difference of the encoders, or the exact one"
            ),
            choices=VELOCITY_SOURCES,
        ),
    )

    def __post_init__(self) -> None:
        positive("max_force_n", self.max_force_n)
        for i, v in enumerate(self.joint_effort_limits):
            positive(f"joint_effort_limits[{i}]", v)
        nonnegative("encoder_resolution_rad", self.encoder_resolution_rad)
        vector("initial_position", list(self.initial_position), len(self.initial_position))
        unit_vector("hand_direction", self.hand_direction)
        nonnegative("hand_lateral_amplitude_m", self.hand_lateral_amplitude_m)
        vector("external_force_n", self.external_force_n, 3)
        nonnegative("external_force_at_s", self.external_force_at_s)
        if self.velocity not in VELOCITY_SOURCES:
            raise ValueError(
                f"velocity must be one of {', '.join(VELOCITY_SOURCES)}, got {self.velocity!r}"
            )


def effort_limits(device: ArmDeviceParams, model: DeviceModel, q0: Vec) -> Vec:
    """Each joint's effort limit (N m or N): ``joint_effort_limits``, else the model's own
    limits, else the effort that gives ``max_force_n`` at the tip at the start pose ``q0``."""
    n = model.dof
    if device.joint_effort_limits:
        return vector("joint_effort_limits", list(device.joint_effort_limits), n)
    own = getattr(model, "effort_limits", None)
    if own is not None and len(own) == n and all(v > 0.0 for v in own):
        return np.array(own, dtype=np.float64)
    J = model._jacobian(q0)
    return cast(Vec, device.max_force_n * np.maximum(np.linalg.norm(J, axis=0), 0.01))
