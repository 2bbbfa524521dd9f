"""The impedance control laws of the thesis (sections 2.2, 6.3) in one sign convention.

``F_w`` is the force the virtual environment should exert on the hand and ``F_h`` the force the
hand applies to the device (+ into the wall); ideal rendering means ``F_h = -F_w``.

- OL  (open-loop impedance):        ``F_a = F_w``
- CL  (force feedback, sensor):     ``F_a = F_w + Kf (F_w + F_h_measured)``
- DOB (disturbance-observer based): ``F_a = F_w + Kf (F_w + F_h_estimated)``

The Cartesian command is limited to ``max_force_n`` (norm, direction kept) and mapped to the joints
with ``tau = J(q)^T F_a``; the device saturates each joint on its own side. Forces are 3-tuples of
floats (N) so the 1 kHz loop runs without array allocation.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, field
from enum import Enum, StrEnum

import numpy as np
from numpy.typing import ArrayLike

from haptic_dob.core.models.base import DeviceModel
from haptic_dob.core.models.slide import SlideModel
from haptic_dob.core.validation import nonnegative, positive, vector
from haptic_dob.runtime.params import param

Force = tuple[float, float, float]
ZERO_FORCE: Force = (0.0, 0.0, 0.0)


class ControlMode(StrEnum):
    """Which hand force, if any, closes the force loop."""

    OL = "OL"
    CL = "CL"
    DOB = "DOB"

    @classmethod
    def parse(cls, value: object) -> ControlMode:
        """Return the mode named by ``value`` (case-insensitive) or raise ``ValueError``."""
        if isinstance(value, ControlMode):
            return value
        name = str(value).strip().upper()
        try:
            return cls(name)
        except ValueError:
            choices = ", ".join(m.value for m in cls)
            raise ValueError(f"mode must be one of {choices}, got {value!r}") from None


class HandForce(Enum):
    """The hand-force input a law feeds back, by the topic it comes on."""

    MEASURED = "wrench_measured"  # the force sensor's (CL)
    ESTIMATED = "wrench_estimate"  # the observer's (DOB)


@dataclass(frozen=True)
class ImpedanceLaw:
    """One consistent snapshot of the law's settings: mode, force gain Kf and force limit.

    Args:
        mode: OL, CL or DOB.
        kf: force-feedback gain Kf (dimensionless), >= 0; ignored in OL.
        max_force_n: limit on the norm of the commanded Cartesian force (N), > 0.
    """

    mode: ControlMode = field(
        default=ControlMode.OL,
        metadata=param(description="control law", choices=tuple(m.value for m in ControlMode)),
    )
    kf: float = field(
        default=0.0, metadata=param(description="force-feedback gain Kf", bounds=(0.0, 1e4))
    )
    max_force_n: float = field(
        default=4.0,
        metadata=param(
            description="limit on the commanded force's norm", unit="N", bounds=(1e-3, 1e3)
        ),
    )

    def __post_init__(self) -> None:
        object.__setattr__(self, "mode", ControlMode.parse(self.mode))
        object.__setattr__(self, "kf", nonnegative("kf", self.kf))
        object.__setattr__(self, "max_force_n", positive("max_force_n", self.max_force_n))

    @property
    def needs(self) -> HandForce | None:
        """The hand-force input this mode waits for (None in OL)."""
        if self.mode is ControlMode.CL:
            return HandForce.MEASURED
        if self.mode is ControlMode.DOB:
            return HandForce.ESTIMATED
        return None

    def force(self, f_wall: Force, f_measured: Force, f_estimated: Force) -> Force:
        """Commanded actuator force F_a (N) before joint mapping, norm-limited to max_force_n."""
        if self.mode is ControlMode.OL:
            fx, fy, fz = f_wall
        else:
            fh = f_measured if self.mode is ControlMode.CL else f_estimated
            kf = self.kf
            fx = f_wall[0] + kf * (f_wall[0] + fh[0])
            fy = f_wall[1] + kf * (f_wall[1] + fh[1])
            fz = f_wall[2] + kf * (f_wall[2] + fh[2])
        return limit_norm((fx, fy, fz), self.max_force_n)


def limit_norm(f: Force, limit: float) -> Force:
    """Scale ``f`` down to norm ``limit`` if it is longer (direction kept)."""
    n2 = f[0] * f[0] + f[1] * f[1] + f[2] * f[2]
    if n2 <= limit * limit:
        return f
    s = limit / math.sqrt(n2)
    return (f[0] * s, f[1] * s, f[2] * s)


def joint_effort(jacobian: np.ndarray, force: Force) -> list[float]:
    """``tau = J^T F`` for a (3, dof) linear Jacobian; a list of dof floats (N or N m)."""
    dof = jacobian.shape[1]
    if dof == 1:
        return [jacobian[0, 0] * force[0] + jacobian[1, 0] * force[1] + jacobian[2, 0] * force[2]]
    tau: list[float] = (jacobian.T @ np.asarray(force)).tolist()
    return tau


def saturate(effort: Iterable[float], limit: float | Iterable[float]) -> list[float]:
    """Clip each joint effort (N or N m) to +-limit: one limit for every joint, or one per joint.

    The suite's one saturation: the device node's command guard clips every command with it.
    Plain floats, no arrays (it runs on every command of a 1 kHz loop). A non-finite effort, a
    limit that is not finite and > 0, or per-joint limits of another length: ``ValueError``.
    """
    e = [float(x) for x in effort]
    lim = [float(x) for x in limit] if isinstance(limit, Iterable) else [float(limit)] * len(e)
    if not all(map(math.isfinite, e)):
        raise ValueError(f"effort must be finite, got {e}")
    if not all(0.0 < x < math.inf for x in lim):
        raise ValueError(f"limit must be finite and > 0, got {lim}")
    if len(lim) != len(e):
        raise ValueError(f"need one limit per joint effort ({len(e)}), got {len(lim)}")
    return [x if -m <= x <= m else (m if x > 0.0 else -m) for x, m in zip(e, lim, strict=True)]


class ImpedanceController:
    """The law mapped to joint efforts through the device model's Jacobian.

    ``law`` may be replaced at any time by a new ``ImpedanceLaw`` (one atomic snapshot); the next
    ``command`` uses it, and nothing else carries state, so a switch is bumpless by construction.
    """

    def __init__(self, model: DeviceModel, law: ImpedanceLaw | None = None) -> None:
        self.model = model
        self.law = law or ImpedanceLaw()
        self._axis: np.ndarray | None = model.axis if isinstance(model, SlideModel) else None

    def command(
        self,
        q: ArrayLike,
        f_wall: Force,
        f_measured: Force = ZERO_FORCE,
        f_estimated: Force = ZERO_FORCE,
    ) -> list[float]:
        """Joint efforts (N or N m) for sample ``q`` and the three forces (N) of the same sample."""
        force = self.law.force(f_wall, f_measured, f_estimated)
        if self._axis is not None:
            a = self._axis
            return [a[0] * force[0] + a[1] * force[1] + a[2] * force[2]]
        J = self.model._jacobian(vector("q", q, self.model.dof))
        return joint_effort(J, force)
