"""A Cartesian point mass per axis: Force Dimension devices (Omega, Falcon) as drivers see them.

The "joints" are the end effector's x, y and z in metres (``forcedimension_ros2``: ``fd_x, fd_y,
fd_z``, prismatic, effort = force in N along the base frame's axes). Each axis is a mass with
viscous and Coulomb friction of its own, uncoupled::

    m_i x_i'' + b_i x_i' + Fc_i sgn(x_i') = F_a,i + F_h,i        (i = x, y, z)

No gravity: the devices' SDK compensates it (what it leaves shows in the estimate, as a hand's
force would). ``D = diag(m)``, ``C = 0``, ``G = 0``, ``J = I``, the end-effector point is ``q``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from haptic_dob.core.models.base import DeviceModel, Mat, Vec
from haptic_dob.core.validation import vector
from haptic_dob.runtime.params import param

#: the joints ``forcedimension_ros2`` publishes (metres, the end effector's x, y and z)
FD_JOINTS = ("fd_x", "fd_y", "fd_z")


def _per_axis(name: str, value: ArrayLike, positive: bool) -> Vec:
    """Three finite values (one scalar for all three); > 0 when ``positive``, else >= 0."""
    v = np.asarray(value, dtype=np.float64)
    v = np.full(3, float(v)) if v.ndim == 0 else vector(name, v, 3)
    if not np.all(np.isfinite(v)) or np.any(v <= 0.0 if positive else v < 0.0):
        bound = "> 0" if positive else ">= 0"
        raise ValueError(f"{name} must be finite and {bound} on every axis, got {v.tolist()}")
    return v


class PointMassModel(DeviceModel):
    """Three uncoupled axes, each ``m x'' + b x' + Fc sgn(x') = F`` (SI units).

    Args:
        mass_kg: moving mass per axis (kg), > 0; one value for all three or three.
        viscous_n_s_per_m: viscous friction per axis (N s/m), >= 0.
        coulomb_n: Coulomb friction per axis (N), >= 0.
        joint_names: the three axes' joint names (default ``fd_x, fd_y, fd_z``).
    """

    dof = 3
    constant_jacobian = True
    constant_mass_matrix = True

    def __init__(
        self,
        mass_kg: float | Sequence[float] = 0.2,
        viscous_n_s_per_m: float | Sequence[float] = 0.0,
        coulomb_n: float | Sequence[float] = 0.0,
        joint_names: Sequence[str] = FD_JOINTS,
    ) -> None:
        self.mass_kg = _per_axis("mass_kg", mass_kg, positive=True)
        self.viscous_n_s_per_m = _per_axis("viscous_n_s_per_m", viscous_n_s_per_m, False)
        self.coulomb_n = _per_axis("coulomb_n", coulomb_n, positive=False)
        names = tuple(str(n) for n in joint_names)
        if len(names) != 3 or len(set(names)) != 3 or not all(names):
            raise ValueError(f"joint_names must be three different names, got {list(names)}")
        self.joint_names = names
        self._D = np.diag(self.mass_kg)
        self._has_coulomb = bool(np.any(self.coulomb_n > 0.0))

    def __repr__(self) -> str:
        return (
            f"PointMassModel(mass_kg={self.mass_kg.tolist()}, "
            f"viscous_n_s_per_m={self.viscous_n_s_per_m.tolist()}, "
            f"coulomb_n={self.coulomb_n.tolist()}, joint_names={list(self.joint_names)})"
        )

    def _mass_matrix(self, q: Vec) -> Mat:
        return self._D.copy()

    def _coriolis_vector(self, q: Vec, qd: Vec) -> Vec:
        return np.zeros(3)

    def _gravity(self, q: Vec) -> Vec:
        return np.zeros(3)

    def _friction(self, qd: Vec) -> Vec:
        f: Vec = self.viscous_n_s_per_m * qd
        if self._has_coulomb:
            f += self.coulomb_n * np.sign(qd)
        return f

    def _bias_effort(self, q: Vec, qd: Vec) -> Vec:
        return self._friction(qd)

    def _mass_and_bias(self, q: Vec, qd: Vec) -> tuple[Mat, Vec]:
        """D and the bias effort (friction alone) in one call (the observer's fast path)."""
        return self._D.copy(), self._friction(qd)

    def _jacobian(self, q: Vec) -> Mat:
        return np.eye(3)

    def _forward_kinematics(self, q: Vec) -> Vec:
        return q.copy()


@dataclass(frozen=True)
class PointMassParams:
    """Settings of a ``PointMassModel`` (parameter group ``point_mass.``), one value per axis.

    The defaults are a starting guess, not a device's values: identify them (``haptic-identify
    --axes``) and load the YAML it writes.
    """

    mass_kg: tuple[float, float, float] = field(
        default=(0.2, 0.2, 0.2),
        metadata=param(
            description="moving mass per axis (x, y, z)", unit="kg", bounds=(1e-3, 100.0)
        ),
    )
    viscous_n_s_per_m: tuple[float, float, float] = field(
        default=(0.0, 0.0, 0.0),
        metadata=param(
            description="viscous friction per axis (x, y, z)", unit="N s/m", bounds=(0.0, 1e3)
        ),
    )
    coulomb_n: tuple[float, float, float] = field(
        default=(0.0, 0.0, 0.0),
        metadata=param(
            description="Coulomb friction per axis (x, y, z)", unit="N", bounds=(0.0, 100.0)
        ),
    )
    joint_names: tuple[str, str, str] = field(
        default=FD_JOINTS,
        metadata=param(description="the axes' joint names in joint_states (x, y, z)"),
    )

    def model(self) -> PointMassModel:
        """The ``PointMassModel`` with these settings (validates them)."""
        return PointMassModel(
            self.mass_kg, self.viscous_n_s_per_m, self.coulomb_n, self.joint_names
        )
