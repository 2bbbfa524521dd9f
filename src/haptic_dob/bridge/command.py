"""The loop's joint efforts in the driver's command space and back, and the command's limits.

``CommandMap`` takes the model's joint efforts (N or N m, model order) to the driver's command
elements (SI, before ``command.scale``): joint efforts in the controller's ``joints`` order
with each joint's sign (a joint the model lacks gets 0), or a force in the base frame, ``J(q)^-T
tau`` by damped least squares (``core.tip_force``), on the driver's axes with their signs. Its
``back`` is what those elements apply in the model's joints (``J^T F`` for a force), so the loop
learns the effort that was actually commanded after clamping. ``CommandLimiter`` clamps each
element and limits its change per period; a stop to zero is never slowed (``zero``).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from haptic_dob.bridge.driver_settings import DriverSettings
from haptic_dob.bridge.settings import per_element
from haptic_dob.core.models.base import DeviceModel
from haptic_dob.core.tip_force import tip_force

#: damped least squares of J^-T: exact while J's smallest singular value is at least this (m),
#: damped up to the same below it (as the observer's tip force)
DLS_THRESHOLD_M = 1e-2
DLS_DAMPING_M = 1e-2


class CommandMap:
    """Model joint efforts <-> the driver's command elements (``DriverSettings``)."""

    def __init__(
        self, driver: DriverSettings, model: DeviceModel, driver_joints: Sequence[str]
    ) -> None:
        self.model = model
        self.cartesian = driver.cartesian
        n = model.dof
        self.signs = per_element("state.signs", driver.state.signs, n, positive=False)
        if self.cartesian:
            self.axes = tuple(driver.frame.axes)
            self.axis_signs = tuple(float(s) for s in driver.frame.signs)
            self.size = 3
            self.unsent: tuple[str, ...] = ()
            return
        names = [j for j in driver.command.joints if j] or list(driver_joints)
        if len(set(names)) != len(names):
            raise ValueError(f"command.joints names a joint twice: {names}")
        where = {j: i for i, j in enumerate(names)}
        #: the command element of each model joint (None: the controller does not command it)
        self.slot = [where.get(j) for j in driver_joints]
        self.unsent = tuple(j for j, s in zip(driver_joints, self.slot, strict=True) if s is None)
        self.size = len(names)

    def forward(
        self, tau: Sequence[float], q: Sequence[float], J: NDArray[np.float64] | None = None
    ) -> tuple[float, ...]:
        """The driver's command elements (SI) for model efforts ``tau`` at joint positions ``q``
        (``J``: the tip's Jacobian there, when known)."""
        if self.cartesian:
            if J is None:
                J = self.model._jacobian(np.asarray(q, dtype=np.float64))
            F = tip_force(J, np.asarray(tau, dtype=np.float64), DLS_THRESHOLD_M, DLS_DAMPING_M)
            out = [0.0, 0.0, 0.0]
            for i, (a, s) in enumerate(zip(self.axes, self.axis_signs, strict=True)):
                out[a] = s * float(F[i])
            return tuple(out)
        out = [0.0] * self.size
        for i, (slot, s) in enumerate(zip(self.slot, self.signs, strict=True)):
            if slot is not None:
                out[slot] = s * float(tau[i])
        return tuple(out)

    def back(
        self, u: Sequence[float], q: Sequence[float], J: NDArray[np.float64] | None = None
    ) -> tuple[float, ...]:
        """The model joint efforts the command elements ``u`` (SI) apply at ``q`` (``J``: the
        tip's Jacobian there, when known)."""
        if self.cartesian:
            F = [s * u[a] for a, s in zip(self.axes, self.axis_signs, strict=True)]
            if J is None:
                J = self.model._jacobian(np.asarray(q, dtype=np.float64))
            return tuple((J.T @ np.asarray(F)).tolist())
        return tuple(
            0.0 if slot is None else s * u[slot]
            for slot, s in zip(self.slot, self.signs, strict=True)
        )


class CommandLimiter:
    """Clamps each command element to its limit and its change to ``rate * period``.

    Args:
        limits: the clamp of each element (N or N m), each > 0.
        rates: the largest change of each element per second (0: none).
        period_s: the driver's period (s): the rate limit's step.
    """

    def __init__(self, limits: Sequence[float], rates: Sequence[float], period_s: float) -> None:
        self.limits = tuple(float(x) for x in limits)
        self.steps = tuple(r * period_s if r > 0.0 else float("inf") for r in rates)
        self.last = tuple(0.0 for _ in self.limits)  # the newest element values sent
        self.clamped = 0  # commands the clamp changed
        self.slowed = 0  # commands the rate limit changed

    def limit(self, u: Sequence[float]) -> tuple[float, ...]:
        """``u`` clamped, then moved from the last sent values by at most a step each."""
        clamped = [max(-lim, min(lim, x)) for x, lim in zip(u, self.limits, strict=True)]
        if clamped != list(u):
            self.clamped += 1
        out = tuple(
            max(p - step, min(p + step, x))
            for x, p, step in zip(clamped, self.last, self.steps, strict=True)
        )
        if list(out) != clamped:
            self.slowed += 1
        self.last = out
        return out

    def zero(self) -> tuple[float, ...]:
        """Zero on every element, at once."""
        self.last = tuple(0.0 for _ in self.limits)
        return self.last
