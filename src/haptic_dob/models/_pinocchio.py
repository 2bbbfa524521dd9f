"""The one module that talks to pinocchio (its camelCase API stays here).

``PinocchioModel`` is a ``DeviceModel`` whose terms come from one pinocchio ``Model``/``Data`` pair
built up front; the loop calls pinocchio's free functions (``crba``, ``rnea``,
``computeGeneralizedGravity``, ``computeFrameJacobian``...) on it. A constant linear map ``S``
(``q_t = S q``, ``q'_t = S q'``) lets a closed-loop mechanism whose loop closure is linear in the
angles (the PHANToM's parallelogram) be computed on its open tree::

    D = S^T M_t(S q) S,   C q' + G = S^T rnea(S q, S q', 0),   J = J_t(S q) S

Two builders make the pinocchio models: ``tree_model`` (a tree of revolute joints with point-like
bodies, declared with ``TreeJoint`` rows) and ``urdf_model`` (a URDF string or file, reduced to
the chosen joints). SI units throughout; gravity is 9.81 m/s^2 along -z.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from haptic_dob.models.base import DeviceModel, Mat, Vec
from haptic_dob.validation import vector

#: standard gravity (m/s^2), pointing along -z of the base frame
GRAVITY_M_S2 = 9.81
_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


# --- building models ---------------------------------------------------------------------------
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


@dataclass(frozen=True)
class UrdfArm:
    """A URDF arm reduced to its chosen joints (what ``urdf_model`` returns)."""

    model: pin.Model
    frame_id: int
    joint_names: tuple[str, ...]  # the DeviceModel's joint order
    S: np.ndarray | None  # pinocchio velocity order from ours (a permutation), None = same
    effort_limits: tuple[float, ...]  # from the URDF's <limit effort>, N m or N (0 = none)


def read_urdf(urdf: str | Path) -> str:
    """The URDF XML: ``urdf`` itself when it is XML text, else the file it names."""
    text = str(urdf)
    if text.lstrip().startswith("<"):
        return text
    path = Path(text).expanduser()
    if not path.is_file():
        raise ValueError(f"urdf: no such file {text!r} (and not URDF XML text)")
    return path.read_text(encoding="utf-8")


def urdf_model(
    urdf: str | Path, tip_frame: str, joint_names: Sequence[str] | None = None
) -> UrdfArm:
    """Parse a URDF (string or path) and keep ``joint_names`` (default: the chain to the tip).

    Every other joint is locked at its neutral position. Revolute, prismatic and continuous
    joints are accepted (a continuous joint is used through its angle). Raises ``ValueError``
    with a clear message for a bad URDF, an unknown tip frame or joint, or a joint type the
    model cannot use.
    """
    xml = read_urdf(urdf)
    try:
        full = pin.buildModelFromXML(xml)
    except (RuntimeError, ValueError) as exc:
        raise ValueError(f"urdf: cannot parse the URDF: {exc}") from None
    if not full.existFrame(tip_frame):
        names = ", ".join(f.name for f in full.frames if f.name != "universe")
        raise ValueError(f"tip_frame {tip_frame!r} is not a frame of the URDF (it has: {names})")
    tip_parent = full.frames[full.getFrameId(tip_frame)].parentJoint
    movable = [full.names[i] for i in range(1, full.njoints)]
    if joint_names:
        wanted = [str(n) for n in joint_names]
        unknown = [n for n in wanted if n not in movable]
        if unknown:
            raise ValueError(
                f"joint_names: {', '.join(unknown)} not movable joints of the URDF "
                f"(it has: {', '.join(movable)})"
            )
        if len(set(wanted)) != len(wanted):
            raise ValueError(f"joint_names lists a joint twice: {wanted}")
    else:
        wanted = [full.names[i] for i in full.supports[tip_parent] if i != 0]
        if not wanted:
            raise ValueError(f"tip_frame {tip_frame!r} is not moved by any joint")
    lock = [i for i in range(1, full.njoints) if full.names[i] not in wanted]
    model = pin.buildReducedModel(full, lock, pin.neutral(full)) if lock else full
    for i in range(1, model.njoints):
        jm = model.joints[i]
        if jm.nv != 1 or jm.nq != 1:
            raise ValueError(
                f"joint {model.names[i]} ({jm.shortname()}) is not a 1-DOF revolute or prismatic "
                "joint; continuous and multi-DOF joints are not supported"
            )
    order = [model.names[i] for i in range(1, model.njoints)]
    idx = [order.index(n) for n in wanted]
    S = None
    if idx != list(range(len(idx))):
        S = np.zeros((len(idx), len(idx)))
        for ours, theirs in enumerate(idx):
            S[theirs, ours] = 1.0
    limits = tuple(float(model.effortLimit[model.joints[order.index(n) + 1].idx_v]) for n in wanted)
    limits = tuple(v if math.isfinite(v) and v > 0.0 else 0.0 for v in limits)
    return UrdfArm(model, model.getFrameId(tip_frame), tuple(wanted), S, limits)


# --- the device model on a pinocchio model -----------------------------------------------------
class PinocchioModel(DeviceModel):
    """A ``DeviceModel`` computed by pinocchio on ``model`` (one ``Data``, built here).

    Args:
        model: the pinocchio model (this object owns it from now on).
        frame_id: id of the end-effector frame (its origin is the end-effector point).
        joint_names: names of the joint-space coordinates, in order.
        S: constant map from our coordinates to pinocchio's (``q_t = S q``), None = identity.
        gravity: False leaves gravity out (G = 0), e.g. for an observer's model (thesis 5.2.1).
        viscous: viscous joint friction b (N m s/rad or N s/m), scalar or per joint, >= 0.
    """

    def __init__(
        self,
        model: pin.Model,
        frame_id: int,
        joint_names: Sequence[str],
        S: np.ndarray | None = None,
        *,
        gravity: bool = True,
        viscous: float | Sequence[float] = 0.0,
    ) -> None:
        self.dof = len(joint_names)
        self.joint_names = tuple(joint_names)
        self.gravity_enabled = bool(gravity)
        self._model = model
        self._model.gravity = pin.Motion(
            np.array([0.0, 0.0, -GRAVITY_M_S2 if gravity else 0.0]), np.zeros(3)
        )
        self._data = model.createData()
        self._fid = int(frame_id)
        if S is not None:
            S = np.ascontiguousarray(S, dtype=np.float64)
            if S.shape != (model.nv, self.dof):
                raise ValueError(f"S must have shape ({model.nv}, {self.dof}), got {S.shape}")
        elif model.nv != self.dof:
            raise ValueError(f"the pinocchio model has {model.nv} joints, names give {self.dof}")
        self._S = S
        # S^T (unused without a selection: empty, so the type stays an array)
        self._St: Mat = np.empty((0, 0)) if S is None else np.ascontiguousarray(S.T)
        self._zero_t = np.zeros(model.nv)
        visc = np.asarray(viscous, dtype=np.float64)
        visc = (
            np.full(self.dof, float(visc)) if visc.ndim == 0 else vector("viscous", visc, self.dof)
        )
        if np.any(visc < 0.0) or not np.all(np.isfinite(visc)):
            raise ValueError(f"viscous must be finite and >= 0, got {visc.tolist()}")
        self.viscous = visc
        self._has_friction = bool(np.any(visc > 0.0))

    # --- one pass for the observer and the simulator -------------------------------------------
    def mass_and_bias(self, q: Vec, qd: Vec) -> tuple[Mat, Vec]:
        """D(q) and C(q, q') q' + G(q) + friction(q') from one pinocchio pass (validated)."""
        return self._mass_and_bias(self._q(q), self._qd(qd))

    def _mass_and_bias(self, q: Vec, qd: Vec) -> tuple[Mat, Vec]:
        m, d, S = self._model, self._data, self._S
        if S is None:
            D = pin.crba(m, d, q).copy()
            h = pin.rnea(m, d, q, qd, self._zero_t).copy()
        else:
            qt = S @ q
            D = self._St @ pin.crba(m, d, qt) @ S
            h = self._St @ pin.rnea(m, d, qt, S @ qd, self._zero_t)
        if self._has_friction:
            h += self.viscous * qd
        return D, h

    # --- DeviceModel ---------------------------------------------------------------------------
    def _mass_matrix(self, q: Vec) -> Mat:
        m, d, S = self._model, self._data, self._S
        M: Mat = pin.crba(m, d, q if S is None else S @ q)
        return M.copy() if S is None else self._St @ M @ S

    def _rnea(self, q: Vec, qd: Vec) -> Vec:
        m, d, S = self._model, self._data, self._S
        if S is None:
            h: Vec = pin.rnea(m, d, q, qd, self._zero_t)
            return h.copy()
        hs: Vec = pin.rnea(m, d, S @ q, S @ qd, self._zero_t)
        return self._St @ hs

    def _coriolis_vector(self, q: Vec, qd: Vec) -> Vec:
        return self._rnea(q, qd) - self._gravity(q)

    def _gravity(self, q: Vec) -> Vec:
        m, d, S = self._model, self._data, self._S
        g: Vec = pin.computeGeneralizedGravity(m, d, q if S is None else S @ q)
        return g.copy() if S is None else self._St @ g

    def _friction(self, qd: Vec) -> Vec:
        return self.viscous * qd

    def _bias_effort(self, q: Vec, qd: Vec) -> Vec:
        h = self._rnea(q, qd)
        if self._has_friction:
            h += self.viscous * qd
        return h

    def _jacobian(self, q: Vec) -> Mat:
        m, d, S = self._model, self._data, self._S
        J: Mat = pin.computeFrameJacobian(m, d, q if S is None else S @ q, self._fid, _LWA)[:3]
        return J.copy() if S is None else J @ S

    def _forward_kinematics(self, q: Vec) -> Vec:
        m, d, S = self._model, self._data, self._S
        pin.forwardKinematics(m, d, q if S is None else S @ q)
        x: Vec = pin.updateFramePlacement(m, d, self._fid).translation.copy()
        return x

    def _tip_state(self, q: Vec, qd: Vec) -> tuple[Vec, Mat, Vec]:
        """End-effector point p (m), linear Jacobian J (3, dof) and ``J' q'`` (m/s^2).

        ``J' q'`` is the point's acceleration at zero joint acceleration (the classical
        acceleration, centripetal terms included): what a point mass at the tip adds to the bias.
        """
        m, d, S = self._model, self._data, self._S
        qt, vt = (q, qd) if S is None else (S @ q, S @ qd)
        pin.forwardKinematics(m, d, qt, vt, self._zero_t)
        p = pin.updateFramePlacement(m, d, self._fid).translation.copy()
        acc = pin.getFrameClassicalAcceleration(m, d, self._fid, _LWA).linear.copy()
        pin.computeJointJacobians(m, d, qt)
        Jt = pin.getFrameJacobian(m, d, self._fid, _LWA)[:3]
        return p, (Jt.copy() if S is None else Jt @ S), acc

    def _dynamics_and_tip(self, q: Vec, qd: Vec) -> tuple[Mat, Vec, Vec, Mat, Vec]:
        """D, bias effort, end-effector point, its Jacobian and ``J' q'`` from one pass.

        One ``computeAllTerms`` (what the simulator needs at every integration stage when forces
        act at the tip).
        """
        m, d, S = self._model, self._data, self._S
        qt, vt = (q, qd) if S is None else (S @ q, S @ qd)
        pin.computeAllTerms(m, d, qt, vt)
        fid = self._fid
        Jt = pin.getFrameJacobian(m, d, fid, _LWA)[:3]
        p = pin.updateFramePlacement(m, d, fid).translation.copy()
        acc = pin.getFrameClassicalAcceleration(m, d, fid, _LWA).linear.copy()
        if S is None:
            D, h, J = d.M.copy(), d.nle.copy(), Jt.copy()
        else:
            D, h, J = self._St @ d.M @ S, self._St @ d.nle, Jt @ S
        if self._has_friction:
            h += self.viscous * qd
        return D, h, p, J, acc

    def potential_energy(self, q: Vec) -> float:
        """Gravitational potential energy (J) of the device at ``q`` (0 without gravity)."""
        m, d, S = self._model, self._data, self._S
        q_ = self._q(q)
        return float(pin.computePotentialEnergy(m, d, q_ if S is None else S @ q_))
