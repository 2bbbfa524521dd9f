"""A tree of revolute joints with point-like bodies as a pinocchio ``Model`` (the PHANToM's open
tree): ``TreeJoint`` rows, ``tree_model``. SI units; pinocchio's default gravity is replaced by
the device model (``_pinocchio.PinocchioModel``)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin


@dataclass(frozen=True)
class TreeJoint:
    """One revolute joint of a tree and the rigid body it carries.

    Args:
        name: joint name (unique).
        parent: name of the parent joint, or None for the base (world).
        axis: ``"z"``: about +z of the joint frame; ``"y"``: about +y of the joint frame.
        xyz: joint origin in the parent joint's frame (m).
        flip: turn the joint frame by pi about the parent's x axis (so +y becomes -y: a joint
            "about -y" as theory.md section 5 writes the PHANToM's elevation joints).
        mass: body mass (kg), >= 0.
        com: centre of mass in the joint frame (m).
        inertia: principal moments (Ixx, Iyy, Izz) about the centre of mass, in the joint frame's
            axes (kg m^2).
    """

    name: str
    parent: str | None
    axis: str
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    flip: bool = False
    mass: float = 0.0
    com: tuple[float, float, float] = (0.0, 0.0, 0.0)
    inertia: tuple[float, float, float] = (0.0, 0.0, 0.0)


def tree_model(
    joints: Sequence[TreeJoint], tip_joint: str, tip_xyz: Sequence[float], tip_name: str = "tip"
) -> tuple[pin.Model, int]:
    """A pinocchio model of revolute ``joints`` and a tip frame on ``tip_joint`` at ``tip_xyz``.

    Returns the model and the tip frame's id. Joints must come parents first.
    """
    model = pin.Model()
    ids: dict[str, int] = {}
    flip = pin.SE3(np.diag([1.0, -1.0, -1.0]), np.zeros(3))
    for j in joints:
        parent = 0 if j.parent is None else ids[j.parent]
        placement = pin.SE3(np.eye(3), np.asarray(j.xyz, dtype=np.float64))
        if j.flip:
            placement = placement * flip
        kind = {"z": pin.JointModelRZ, "y": pin.JointModelRY}.get(j.axis)
        if kind is None:
            raise ValueError(f"joint {j.name}: axis must be 'y' or 'z', got {j.axis!r}")
        jid = model.addJoint(parent, kind(), placement, j.name)
        inertia = pin.Inertia(
            float(j.mass), np.asarray(j.com, dtype=np.float64), np.diag(np.asarray(j.inertia))
        )
        model.appendBodyToJoint(jid, inertia, pin.SE3.Identity())
        ids[j.name] = jid
    tip = pin.SE3(np.eye(3), np.asarray(tip_xyz, dtype=np.float64))
    fid = model.addFrame(pin.Frame(tip_name, ids[tip_joint], 0, tip, pin.FrameType.OP_FRAME))
    return model, fid
