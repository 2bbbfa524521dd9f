"""The simulated arm's joint acceleration at one integration stage (``haptic_sim.arm.device``).

``D(q) q'' + C(q, q') q' + G(q) + friction(q') = tau + J^T F_tip``, with the Coulomb term
smoothed to ``Fc tanh(q' / eps)`` (``coulomb_smoothing``). ``F_tip`` sums the hand's grip (a
spring and damper to its reference, ``k_h (x_r - p) + b_h (x_r' - J q') + f_ff``, the hand's
mass ``m_h`` moving with the handle: ``D + m_h J^T J``), a known external force and the
contact's (``haptic_sim.arm.contact``). Pinocchio's ABA where the model has it and no hand's
mass rides on the handle; else the mass matrix and a solve.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, cast

import numpy as np

from haptic_dob.core.models.base import DeviceModel, Mat, Vec
from haptic_sim.arm.dynamics import MassAndBias, dynamics_and_tip, solve

_ZERO3 = np.zeros(3)
_NO_J = np.zeros((3, 0))  # the Jacobian slot of ``last`` on the ABA path (unused there)

#: (p, p') -> the contact's force on the tip (N)
ContactForce = Callable[[Vec, Vec], Vec]


class ArmAcceleration:
    """``q''`` of the arm at a stage; with tip forces, ``last`` holds (grip, J, J' q', f_ext).

    Args:
        model: the arm's true physics.
        dyn: its ``(q, q') -> (D, h)`` (``mass_and_bias``).
        coulomb: each joint's Coulomb friction (None: none) and ``eps``, the smoothing speeds.
        contact: the contact's force at the tip's point and velocity (None: no contact).
        needs_tip: whether any tip force acts (a hand, an external force, a contact).
        grip: the hand's stiffness (N/m), damping (N s/m) and moving mass (kg; 0: none).
    """

    def __init__(
        self,
        model: DeviceModel,
        dyn: MassAndBias,
        coulomb: tuple[Vec | None, Vec],
        contact: ContactForce | None,
        needs_tip: bool,
        grip: tuple[float, float, float],
    ) -> None:
        self._dyn = dyn
        self._dyn_tip = dynamics_and_tip(model)
        # pinocchio's ABA where the model has it (no mass matrix, no solve): the free arm and an
        # arm under tip forces (contact, an external force), not one with a hand's mass on it
        self._aba = bool(getattr(model, "_has_forward_dynamics", False))
        if self._aba:
            self._fd = cast(Any, model)._forward_dynamics
            self._tip_motion = cast(Any, model)._tip_motion
        self._viscous = np.asarray(getattr(model, "viscous", np.zeros(model.dof)), dtype=np.float64)
        self._coulomb, self._eps = coulomb
        self._contact = contact
        self._needs_tip = needs_tip
        self._kh, self._bh, self._mh = grip
        self.last: tuple[Vec, Mat, Vec, Vec] = (_ZERO3, _NO_J, _ZERO3, _ZERO3)

    def __call__(
        self, q: Vec, v: Vec, tau: Vec, f_ext: Vec, ref: tuple[Vec, Vec, Vec] | None
    ) -> Vec:
        """Joint acceleration at (q, v) under ``tau``, ``f_ext`` on the tip and the hand's
        reference ``ref`` (``k_h x_r + b_h x_r' + f_ff``, x_r, x_r'; None: no hand)."""
        if self._aba and ref is None:  # b q' + Fc tanh(q' / eps) in one go, then ABA
            if self._coulomb is not None:
                tau = tau - self._viscous * v - self._coulomb * np.tanh(v / self._eps)
            else:
                tau = tau - self._viscous * v
            if not self._needs_tip:
                a: Vec = self._fd(q, v, tau, None)
                return a
            if self._contact is not None:
                f_ext = f_ext + self._contact(*self._tip_motion(q, v))
            self.last = (_ZERO3, _NO_J, _ZERO3, f_ext)  # J unused without a hand's grip
            a = self._fd(q, v, tau, f_ext)
            return a
        if self._coulomb is not None:  # the model's Fc sgn(q') -> Fc tanh(q' / eps)
            tau = tau - self._coulomb * (np.tanh(v / self._eps) - np.sign(v))
        if not self._needs_tip:
            D, h = self._dyn(q, v)
            return solve(D, tau - h)
        D, h, p, J, jdv = self._dyn_tip(q, v)
        if self._contact is not None:
            f_ext = f_ext + self._contact(p, J @ v)
        Jt = J.T
        if ref is None:
            self.last = (_ZERO3, J, jdv, f_ext)
            return solve(D, tau - h + Jt @ f_ext)
        # grip = k_h (x_r - p) + b_h (x_r' - J q') + f_ff, with ref[0] = k_h x_r + b_h x_r' + f_ff
        grip = ref[0] - self._kh * p - self._bh * (J @ v)
        self.last = (grip, J, jdv, f_ext)
        if self._mh > 0.0:
            return solve(D + self._mh * (Jt @ J), tau - h + Jt @ (grip + f_ext - self._mh * jdv))
        return solve(D, tau - h + Jt @ (grip + f_ext))


__all__ = ["ArmAcceleration", "ContactForce"]
