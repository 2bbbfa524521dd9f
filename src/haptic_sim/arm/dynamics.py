"""The rigid-body dynamics the simulated arm (``haptic_sim.arm.device``) integrates, from any model.

- ``mass_and_bias``: ``D(q)`` and the bias effort ``h(q, q')`` (Coriolis, gravity, friction)
  from the model's one-pass ``_mass_and_bias`` (pinocchio models) or its two separate methods;
- ``dynamics_and_tip``: those plus the end-effector point ``p``, its Jacobian ``J`` and
  ``J' q'``, from the model's one-pass ``_dynamics_and_tip`` where it has one, else ``J' q'`` by
  central differences of ``J`` along ``q'``;
- ``solve``: the linear solve of the accelerations, a 3x3 system by cofactors;
- ``coulomb_smoothing``: the model's Coulomb friction and the speeds over which the simulated arm
  smooths its sign (``haptic_sim.arm.device``), chosen so that RK4 steps over the turn without
  chatter.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import cast

import numpy as np

from haptic_dob.core.models.base import DeviceModel, Mat, Vec

#: (q, q') -> (D, h)
MassAndBias = Callable[[Vec, Vec], tuple[Mat, Vec]]
#: (q, q') -> (D, h, p, J, J' q')
DynamicsAndTip = Callable[[Vec, Vec], tuple[Mat, Vec, Vec, Mat, Vec]]


def mass_and_bias(model: DeviceModel) -> MassAndBias:
    """``(q, q') -> (D, h)`` of ``model``: its one-pass method when it has one."""
    one_pass: MassAndBias | None = getattr(model, "_mass_and_bias", None)
    return one_pass or (lambda q, qd: (model._mass_matrix(q), model._bias_effort(q, qd)))


def dynamics_and_tip(model: DeviceModel) -> DynamicsAndTip:
    """``(q, q') -> (D, h, p, J, J' q')`` of ``model``: its one-pass method when it has one."""
    one_pass: DynamicsAndTip | None = getattr(model, "_dynamics_and_tip", None)
    if one_pass is not None:
        return one_pass
    dyn = mass_and_bias(model)

    def generic(q: Vec, v: Vec) -> tuple[Mat, Vec, Vec, Mat, Vec]:
        """D, h, p, J and J' q' for a model without a one-pass method (J' q' by differences)."""
        D, h = dyn(q, v)
        J = model._jacobian(q)
        speed = float(np.linalg.norm(v))
        if speed == 0.0:
            return D, h, model._forward_kinematics(q), J, np.zeros(3)
        eps = 1e-6 / speed
        dJ = (model._jacobian(q + eps * v) - model._jacobian(q - eps * v)) / (2.0 * eps)
        return D, h, model._forward_kinematics(q), J, dJ @ v

    return generic


#: how stiff the smoothed turn may make one physics step for one joint: ``h Fc / eps`` times the
#: joint's inverse inertia, at most this at every configuration checked
STEP_STIFFNESS = 0.5
#: ... and for the arm: the largest eigenvalue of ``h D^-1 diag(Fc / eps)`` (coupled joints add
#: up), at most this (RK4's stages overshoot and chatter from about 2; the 7-DOF slave's coupled
#: shoulder reached 8.2 with ``D``'s diagonal alone)
STEP_LIMIT = 1.5
#: configurations checked: the start and this many drawn within ``SPREAD`` of it in every joint
#: (rad, or m for a prismatic joint; a fixed draw)
SAMPLES = 100
SPREAD = 0.5


def coulomb_smoothing(
    model: DeviceModel, dyn: MassAndBias, q0: Vec, h: float
) -> tuple[Vec | None, Vec]:
    """The model's Coulomb friction (None without) and, per joint, the speed ``eps`` (rad/s or
    m/s) over which the simulated arm turns it, ``Fc tanh(q' / eps)``.

    The turn's slope ``Fc / eps`` is a stiffness RK4 must step over: ``eps`` is the smallest
    (at least 1 mrad/s) for which ``h Fc / eps`` times the joint's inverse inertia (the diagonal
    of ``D^-1``: the inertia the joint moves with while the others are free, far below ``D``'s
    diagonal where joints are coupled) stays at most ``STEP_STIFFNESS`` at ``q0`` and at
    ``SAMPLES`` configurations within ``SPREAD`` of it; all of them larger by the same factor if
    the coupled stiffness, the largest eigenvalue of ``h D^-1 diag(Fc / eps)``, passes
    ``STEP_LIMIT`` at one of those configurations. ``ValueError`` for a model whose Coulomb
    friction turns over a speed of its own (``coulomb_speed``, an observer's).
    """
    speed = getattr(model, "coulomb_speed", None)
    if speed is not None and np.any(np.asarray(speed) > 0.0):
        raise ValueError(
            "a simulated arm smooths its Coulomb friction over its physics step: "
            "a Coulomb turn (urdf.coulomb_speed_rad_per_s, or the URDF's haptic_dob:dynamics "
            "coulomb_speed) is for an observer's model: set urdf.coulomb_speed_rad_per_s to [0.0]"
        )
    fc = getattr(model, "coulomb", None)
    if fc is None or not np.any(np.asarray(fc) > 0.0):
        return None, np.ones(model.dof)
    fc = np.asarray(fc, dtype=np.float64)
    rng = np.random.default_rng(0)
    zero = np.zeros(model.dof)
    spread = rng.uniform(-SPREAD, SPREAD, (SAMPLES, model.dof))
    inverses = [np.linalg.inv(dyn(q, zero)[0]) for q in (q0, *(q0 + spread))]
    inverse_inertia = np.max([np.diag(m) for m in inverses], axis=0)
    eps = np.maximum(fc * h * inverse_inertia / STEP_STIFFNESS, 1e-3)
    slope = h * fc / eps
    coupled = max(float(np.max(np.linalg.eigvals(m * slope).real)) for m in inverses)
    return fc, eps * max(1.0, coupled / STEP_LIMIT)


def solve(A: Mat, b: Vec) -> Vec:
    """``A x = b``; a 3x3 system by cofactors in floats (several times faster than LAPACK here)."""
    if A.shape != (3, 3):
        return cast(Vec, np.linalg.solve(A, b))
    (a, b_, c), (d, e, f), (g, h, i) = A.tolist()
    c00, c01, c02 = e * i - f * h, f * g - d * i, d * h - e * g
    det = a * c00 + b_ * c01 + c * c02
    if det == 0.0 or not math.isfinite(det):
        return cast(Vec, np.linalg.solve(A, b))
    r = 1.0 / det
    x0, x1, x2 = b.tolist()
    return np.array(
        (
            (c00 * x0 + (c * h - b_ * i) * x1 + (b_ * f - c * e) * x2) * r,
            (c01 * x0 + (a * i - c * g) * x1 + (c * d - a * f) * x2) * r,
            (c02 * x0 + (b_ * g - a * h) * x1 + (a * e - b_ * d) * x2) * r,
        )
    )
