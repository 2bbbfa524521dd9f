"""The remote environment a simulated arm touches: a wall inside the arm's physics (teleoperation).

The simulated arm (``haptic_sim.arm.device``) integrates its dynamics in sub-steps; with a
``TipContact`` every integration stage adds the wall's force at the end-effector point and its
velocity, ``F = wall.force(p, J q')`` (``haptic_dob.core.environment.VirtualWall``: a unilateral
spring-damper, force only while penetrating, never pulling), to the tip force. It is the true
contact a slave arm meets, apart from anything a controller renders: an observer on the arm's
joints sees it only through the arm's motion and efforts, a wrist sensor through the tip force.

``force_at`` gives the true contact force at a state (the arm reports it at every sample for
evaluation); ``depth`` the penetration (m, > 0 inside).
"""

from __future__ import annotations

import numpy as np

from haptic_dob.core.environment import VirtualWall
from haptic_dob.core.models.base import DeviceModel, Vec


class TipContact:
    """A wall the arm's end-effector point touches (``wall.stiffness_n_per_m`` > 0).

    Args:
        wall: the wall (plane point, normal from free space into it, stiffness, damping).
    """

    __slots__ = ("_force", "wall")

    def __init__(self, wall: VirtualWall) -> None:
        if wall.stiffness_n_per_m <= 0.0:
            raise ValueError("a contact needs a wall stiffness > 0 N/m")
        if wall.two_sided:
            raise ValueError("a contact is one-sided: a wall that pulls is no contact")
        self.wall = wall
        self._force = wall.force

    def force(self, p: Vec, v: Vec) -> Vec:
        """The wall's force on the end effector (N, (3,)) at point ``p`` (m) and velocity ``v``."""
        f = self._force(p, v)  # type: ignore[arg-type]  # (3,) arrays index as 3-tuples
        return np.array(f)

    def force_at(self, model: DeviceModel, q: Vec, qd: Vec) -> Vec:
        """The contact force (N, (3,)) at joint state ``q``, ``qd`` of ``model``."""
        return self.force(model._forward_kinematics(q), model._jacobian(q) @ qd)

    def depth(self, p: Vec) -> float:
        """Penetration of point ``p`` (m): > 0 inside the wall."""
        return self.wall.penetration(p)


def contact_of(wall: VirtualWall | None) -> TipContact | None:
    """The contact of ``wall``; None for no wall or a wall of zero stiffness (nothing to touch)."""
    if wall is None or wall.stiffness_n_per_m <= 0.0:
        return None
    return TipContact(wall)
