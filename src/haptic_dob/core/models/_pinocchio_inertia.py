"""The inertial parameters of a pinocchio arm (pinocchio's API stays here): its bodies, their
ten parameters each, and the joint-torque regressor that is linear in them.

A body is what one joint moves: the joint's child link with every link fixed (or locked) to it.
Its parameters are pinocchio's dynamic parameters ``m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz,
Iyz, Izz`` (kg, kg m, kg m^2): the mass, its first moment and the rotational inertia about the
joint frame's origin, in the joint frame's axes. The regressor ``Y(q, q', q'')`` (dof, 10 per
body) gives the rigid-body effort ``Y theta`` (pinocchio's ``computeJointTorqueRegressor``), in
our joint order; armature and friction are not in it. With mimic joints (a parallelogram), which
that function refuses, a body's columns are RNEA's differences: RNEA is linear in ``theta``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from haptic_dob.core.models._pinocchio import PinocchioModel
from haptic_dob.core.models.base import Mat, Vec

#: the ten parameters of a body, in pinocchio's order
BODY_PARAMETERS = ("m", "mx", "my", "mz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz")
_BODY = pin.FrameType.BODY
_JOINT = pin.FrameType.JOINT


@dataclass(frozen=True)
class Body:
    """One moving body: its joint, the links it merges and the points it carries.

    ``links`` are the URDF links of the body with each link frame's pose in the joint frame (4x4),
    the joint's child link first; ``points`` (k, 3) are the origins of the joints and frames the
    body carries, in the joint frame (m): with the link frame's origin, where the body reaches.
    """

    joint: str
    links: tuple[tuple[str, Mat], ...]
    points: Mat

    @property
    def link(self) -> str:
        """The joint's child link (the body's name)."""
        return self.links[0][0]


#: each body's parameters where the mimic regressor's differences start (a unit mass, no lever)
_REFERENCE = np.array([1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 1.0])


def _checked(model: PinocchioModel) -> pin.Model:
    """The pinocchio model."""
    m: pin.Model = model._model
    return m


def bodies(model: PinocchioModel) -> list[Body]:
    """The model's moving bodies, in pinocchio's joint order (the regressor's column blocks)."""
    m = _checked(model)
    out = []
    for j in range(1, m.njoints):
        links: list[tuple[str, Mat]] = []
        for f in m.frames:
            if f.type != _BODY or f.parentJoint != j:
                continue
            entry = (f.name, f.placement.homogeneous.copy())
            if m.frames[f.parentFrame].type == _JOINT:  # the joint's child link
                links.insert(0, entry)
            else:
                links.append(entry)
        children = [
            m.jointPlacements[k].translation for k in range(1, m.njoints) if m.parents[k] == j
        ]
        frames = [f.placement.translation for f in m.frames if f.parentJoint == j]
        points = np.array([np.zeros(3), *children, *frames], dtype=np.float64)
        out.append(Body(m.names[j], tuple(links), points))
    return out


def body_parameters(model: PinocchioModel) -> Mat:
    """Every body's ten parameters, (bodies, 10)."""
    m = _checked(model)
    return np.array([m.inertias[j].toDynamicParameters() for j in range(1, m.njoints)])


def torque_regressor(model: PinocchioModel, q: Vec, qd: Vec, qdd: Vec) -> Mat:
    """``Y`` (dof, 10 per body) with ``Y theta`` the rigid-body effort at ``q, q', q''``."""
    m = _checked(model)
    d = model._data
    qt, vt, at = model._conf(q), model._vel(qd), model._vel(qdd)
    if model._mimic:
        Y = _mimic_regressor(m, d, qt, vt, at)
    else:
        Y = pin.computeJointTorqueRegressor(m, d, qt, vt, at)
    out: Mat = Y.copy() if model._S is None else model._St @ Y
    return out


def _mimic_regressor(m: pin.Model, d: pin.Data, q: Vec, qd: Vec, qdd: Vec) -> Mat:
    """``Y`` by RNEA's differences (it is linear in each body's ten parameters): every body at
    ``_REFERENCE``, one parameter up by one at a time; the model's inertias are put back."""
    saved = [pin.Inertia(m.inertias[j]) for j in range(m.njoints)]
    reference = pin.Inertia.FromDynamicParameters(_REFERENCE)
    try:
        for j in range(1, m.njoints):
            m.inertias[j] = reference
        base = pin.rnea(m, d, q, qd, qdd).copy()
        Y = np.empty((m.nv, 10 * (m.njoints - 1)))
        for j in range(1, m.njoints):
            for i in range(10):
                m.inertias[j] = pin.Inertia.FromDynamicParameters(_REFERENCE + np.eye(10)[i])
                Y[:, 10 * (j - 1) + i] = pin.rnea(m, d, q, qd, qdd) - base
            m.inertias[j] = reference
    finally:
        for j, inertia in enumerate(saved):
            m.inertias[j] = inertia
    return Y


def parameters_of(mass: float, com: Vec, inertia_com: Mat) -> Vec:
    """A body's ten parameters from its mass (kg), centre of mass (m) and inertia about it."""
    inertia = pin.Inertia(float(mass), np.asarray(com), np.asarray(inertia_com))
    out: Vec = inertia.toDynamicParameters()
    return out


def moved(pose: Mat, mass: float, com: Vec, inertia_com: Mat) -> Vec:
    """The ten parameters, in the frame ``pose`` (4x4) is given in, of a link whose frame has that
    pose and whose mass, centre of mass and inertia about it are given in its own frame."""
    inertia = pin.Inertia(float(mass), np.asarray(com), np.asarray(inertia_com))
    out: Vec = pin.SE3(pose).act(inertia).toDynamicParameters()
    return out
