"""The device-model interface every observer, controller and simulator in the suite uses.

Joint-space rigid-body model ``D(q) q'' + C(q, q') q' + G(q) + friction(q') = tau + d``, plus the
end-effector point's forward kinematics and linear Jacobian. SI units: metres or radians, newtons
or newton-metres, kilograms.

Public methods validate their arguments (shape, finiteness) and raise ``ValueError`` naming the
argument; the underscore methods skip the checks and are what the 1 kHz loop calls after
validating once.
"""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np
from numpy.typing import ArrayLike, NDArray

from haptic_dob.core.validation import vector

Vec = NDArray[np.float64]
Mat = NDArray[np.float64]


class DeviceModel(ABC):
    """A rigid-body device with ``dof`` joints and a point end effector."""

    #: number of joints
    dof: int
    #: joint names in the order of every joint-space vector
    joint_names: tuple[str, ...]
    #: True when J does not depend on q (a controller then needs no joint positions)
    constant_jacobian: bool = False
    #: True when D does not depend on q (the observer then makes its step's matrices once)
    constant_mass_matrix: bool = False

    # --- public, validated -------------------------------------------------------------------
    def mass_matrix(self, q: ArrayLike) -> Mat:
        """Joint-space inertia D(q), (dof, dof), kg or kg m^2."""
        return self._mass_matrix(self._q(q))

    def coriolis_vector(self, q: ArrayLike, qd: ArrayLike) -> Vec:
        """Coriolis and centrifugal effort C(q, q') q', (dof,)."""
        return self._coriolis_vector(self._q(q), self._qd(qd))

    def gravity(self, q: ArrayLike) -> Vec:
        """Gravity effort G(q), (dof,)."""
        return self._gravity(self._q(q))

    def friction(self, qd: ArrayLike) -> Vec:
        """Modelled joint friction effort (viscous + Coulomb), (dof,)."""
        return self._friction(self._qd(qd))

    def jacobian(self, q: ArrayLike) -> Mat:
        """Linear Jacobian of the end-effector point, (3, dof), in the base frame."""
        return self._jacobian(self._q(q))

    def forward_kinematics(self, q: ArrayLike) -> Vec:
        """End-effector point in the base frame, (3,), metres."""
        return self._forward_kinematics(self._q(q))

    def bias_effort(self, q: ArrayLike, qd: ArrayLike) -> Vec:
        """C(q, q') q' + G(q) + friction(q'): everything but inertia and the inputs, (dof,)."""
        q_, qd_ = self._q(q), self._qd(qd)
        return self._bias_effort(q_, qd_)

    # --- implementations ---------------------------------------------------------------------
    @abstractmethod
    def _mass_matrix(self, q: Vec) -> Mat: ...

    @abstractmethod
    def _coriolis_vector(self, q: Vec, qd: Vec) -> Vec: ...

    @abstractmethod
    def _gravity(self, q: Vec) -> Vec: ...

    @abstractmethod
    def _friction(self, qd: Vec) -> Vec: ...

    @abstractmethod
    def _jacobian(self, q: Vec) -> Mat: ...

    @abstractmethod
    def _forward_kinematics(self, q: Vec) -> Vec: ...

    def _bias_effort(self, q: Vec, qd: Vec) -> Vec:
        return self._coriolis_vector(q, qd) + self._gravity(q) + self._friction(qd)

    def _mass_and_momentum_bias(self, q: Vec, qd: Vec) -> tuple[Mat, Vec]:
        """D(q) and the momentum observer's bias ``G + friction - C^T q'`` (``p' = tau + d -
        bias``, ``p = D q'``): ``h - D' q'`` with ``D' q'`` by central differences along ``q'``
        (``D' = C + C^T``). Models with a Coriolis matrix at hand compute it directly."""
        D = self._mass_matrix(q)
        h = self._bias_effort(q, qd)
        speed = float(np.linalg.norm(qd))
        if speed == 0.0:
            return D, h
        eps = 1e-6 / speed
        dD = (self._mass_matrix(q + eps * qd) - self._mass_matrix(q - eps * qd)) / (2.0 * eps)
        bias: Vec = h - dD @ qd
        return D, bias

    # --- helpers -------------------------------------------------------------------------------
    def _q(self, q: ArrayLike) -> Vec:
        return vector("q", q, self.dof)

    def _qd(self, qd: ArrayLike) -> Vec:
        return vector("qd", qd, self.dof)
