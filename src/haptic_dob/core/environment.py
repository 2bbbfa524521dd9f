"""Virtual environments: a unilateral spring-damper wall, 1-D and as a half-space in 3-D.

The wall is the plane through ``position`` (m, 3-vector) with unit ``normal`` pointing from free
space into the wall. Penetration ``delta = (p - position) . normal``; while ``delta > 0`` the wall
pushes back along ``-normal`` with ``K delta + B delta'`` (never pulls: a damper leaving the wall
fast gives zero, not an attracting force):

    F_w = -max(K delta + B delta', 0) normal        (delta > 0),   0 otherwise

``two_sided`` makes it a spring-damper on both sides of the plane, ``F_w = -(K delta + B delta')
normal`` everywhere: the virtual spring that holds the device during identification (thesis 4.2).

For the slide along +x with the wall at x_w this is the thesis's ``F_w = -K (x - x_w) - B x'``.
Forces are tuples of floats (N), the loop's allocation-free form.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from haptic_dob.core.validation import finite_scalar, nonnegative, unit_vector, vector
from haptic_dob.runtime.params import param

Vec3 = tuple[float, float, float]


@dataclass(frozen=True)
class VirtualWall:
    """A unilateral wall (or a two-sided spring): stiffness K (N/m), damping B (N s/m), plane
    point (m), unit normal."""

    stiffness_n_per_m: float = field(
        default=800.0, metadata=param(description="wall stiffness K", unit="N/m", bounds=(0.0, 1e6))
    )
    damping_n_s_per_m: float = field(
        default=0.0, metadata=param(description="wall damping B", unit="N s/m", bounds=(0.0, 1e4))
    )
    position: Vec3 = field(
        default=(0.0, 0.0, 0.0),
        metadata=param(description="a point on the wall plane (x, y, z)", unit="m"),
    )
    normal: Vec3 = field(
        default=(1.0, 0.0, 0.0),
        metadata=param(
            description="normal pointing into the wall (x, y, z), non-zero",
            details="From free space into the wall; of any length but zero (it is normalised).",
        ),
    )
    two_sided: bool = field(
        default=False,
        metadata=param(
            description="a spring on both sides of the plane (pulls too): identification's spring"
        ),
    )
    _n: Vec3 = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(
            self, "stiffness_n_per_m", nonnegative("stiffness_n_per_m", self.stiffness_n_per_m)
        )
        object.__setattr__(
            self, "damping_n_s_per_m", nonnegative("damping_n_s_per_m", self.damping_n_s_per_m)
        )
        p = vector("position", self.position, 3)
        n = unit_vector("normal", self.normal)
        object.__setattr__(self, "position", (float(p[0]), float(p[1]), float(p[2])))
        object.__setattr__(self, "normal", (float(n[0]), float(n[1]), float(n[2])))
        object.__setattr__(self, "_n", self.normal)

    @classmethod
    def along_axis(
        cls,
        stiffness_n_per_m: float,
        damping_n_s_per_m: float = 0.0,
        position_m: float = 0.0,
        axis: ArrayLike = (1.0, 0.0, 0.0),
    ) -> VirtualWall:
        """1-D wall at ``position_m`` along ``axis``, penetrated when moving along +axis."""
        a = unit_vector("axis", axis)
        x = finite_scalar("position_m", position_m)
        p = a * x
        point = (float(p[0]), float(p[1]), float(p[2]))
        return cls(
            stiffness_n_per_m, damping_n_s_per_m, point, (float(a[0]), float(a[1]), float(a[2]))
        )

    def penetration(self, p: ArrayLike) -> float:
        """Signed penetration depth (m): > 0 inside the wall."""
        p3 = vector("p", p, 3)
        return float(np.dot(p3 - np.asarray(self.position), np.asarray(self.normal)))

    def force(self, p: Vec3, v: Vec3) -> Vec3:
        """Wall force on the hand (N) at end-effector position ``p`` (m) and velocity ``v`` (m/s).

        Inputs are 3-sequences of floats; no validation (the loop's path). ``force_checked``
        validates.
        """
        n = self._n
        o = self.position
        delta = (p[0] - o[0]) * n[0] + (p[1] - o[1]) * n[1] + (p[2] - o[2]) * n[2]
        two_sided = self.two_sided
        if delta <= 0.0 and not two_sided:
            return (0.0, 0.0, 0.0)
        rate = v[0] * n[0] + v[1] * n[1] + v[2] * n[2]
        mag = self.stiffness_n_per_m * delta + self.damping_n_s_per_m * rate
        if mag <= 0.0 and not two_sided:
            return (0.0, 0.0, 0.0)
        return (-mag * n[0], -mag * n[1], -mag * n[2])

    def force_checked(self, p: ArrayLike, v: ArrayLike) -> Vec3:
        """``force`` with shape and finiteness checks (``ValueError`` names the argument)."""
        p3, v3 = vector("p", p, 3), vector("v", v, 3)
        return self.force(tuple(p3.tolist()), tuple(v3.tolist()))
