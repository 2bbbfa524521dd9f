"""The thesis's 1-DOF slide: a mass with viscous and Coulomb friction on a linear guide."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from haptic_dob.core.models.base import DeviceModel, Mat, Vec
from haptic_dob.core.validation import nonnegative, positive, unit_vector
from haptic_dob.runtime.params import param

#: identified parameters of the thesis's slide (thesis table 4.1)
SLIDE_MASS_KG = 0.416
SLIDE_VISCOUS_N_S_PER_M = 1.272
SLIDE_COULOMB_N = 0.24


class SlideModel(DeviceModel):
    """``m x'' + b x' + Fc sgn(x') = F_a + F_h`` along ``axis`` (unit 3-vector, default +x).

    Args:
        mass_kg: moving mass m (kg), > 0.
        viscous_n_s_per_m: viscous friction b (N s/m), >= 0.
        coulomb_n: Coulomb friction Fc (N), >= 0.
        axis: direction of the slide in the base frame; the end effector is at ``q * axis``.
        joint_name: name of the single joint.
    """

    dof = 1
    constant_jacobian = True
    constant_mass_matrix = True

    def __init__(
        self,
        mass_kg: float = SLIDE_MASS_KG,
        viscous_n_s_per_m: float = SLIDE_VISCOUS_N_S_PER_M,
        coulomb_n: float = SLIDE_COULOMB_N,
        axis: ArrayLike = (1.0, 0.0, 0.0),
        joint_name: str = "slide",
    ) -> None:
        self.mass_kg = positive("mass_kg", mass_kg)
        self.viscous_n_s_per_m = nonnegative("viscous_n_s_per_m", viscous_n_s_per_m)
        self.coulomb_n = nonnegative("coulomb_n", coulomb_n)
        self.axis = unit_vector("axis", axis)
        self.joint_names = (str(joint_name),)
        self._axis_col = self.axis.reshape(3, 1)

    def __repr__(self) -> str:
        return (
            f"SlideModel(mass_kg={self.mass_kg}, viscous_n_s_per_m={self.viscous_n_s_per_m}, "
            f"coulomb_n={self.coulomb_n}, axis={self.axis.tolist()})"
        )

    def friction_scalar(self, qd: float) -> float:
        """Friction b qd + Fc sgn(qd) (N) for a float velocity qd (m/s): the loop's fast path."""
        if qd > 0.0:
            return self.viscous_n_s_per_m * qd + self.coulomb_n
        if qd < 0.0:
            return self.viscous_n_s_per_m * qd - self.coulomb_n
        return 0.0

    def _mass_matrix(self, q: Vec) -> Mat:
        return np.array([[self.mass_kg]])

    def _coriolis_vector(self, q: Vec, qd: Vec) -> Vec:
        return np.zeros(1)

    def _gravity(self, q: Vec) -> Vec:
        return np.zeros(1)

    def _friction(self, qd: Vec) -> Vec:
        return np.array([self.friction_scalar(float(qd[0]))])

    def _jacobian(self, q: Vec) -> Mat:
        return self._axis_col.copy()

    def _forward_kinematics(self, q: Vec) -> Vec:
        return self.axis * float(q[0])


@dataclass(frozen=True)
class SlideParams:
    """Settings of a ``SlideModel`` (defaults: the thesis's identified slide)."""

    mass_kg: float = field(
        default=SLIDE_MASS_KG,
        metadata=param(description="moving mass of the slide", unit="kg", bounds=(1e-3, 100.0)),
    )
    viscous_n_s_per_m: float = field(
        default=SLIDE_VISCOUS_N_S_PER_M,
        metadata=param(
            description="viscous friction of the slide", unit="N s/m", bounds=(0.0, 1e3)
        ),
    )
    coulomb_n: float = field(
        default=SLIDE_COULOMB_N,
        metadata=param(description="Coulomb friction of the slide", unit="N", bounds=(0.0, 100.0)),
    )
    axis: tuple[float, float, float] = field(
        default=(1.0, 0.0, 0.0),
        metadata=param(description="slide direction in the base frame (unit 3-vector)"),
    )

    def model(self) -> SlideModel:
        """The ``SlideModel`` with these settings (validates them)."""
        return SlideModel(self.mass_kg, self.viscous_n_s_per_m, self.coulomb_n, self.axis)
