"""The one module that talks to pinocchio (its camelCase API stays here).

``PinocchioModel`` is a ``DeviceModel`` whose terms come from one pinocchio ``Model``/``Data`` pair
built up front; the loop calls pinocchio's free functions (``crba``, ``rnea``,
``computeGeneralizedGravity``, ``computeFrameJacobian``...) on it. A constant linear map ``S``
(``q_t = S q``, ``q'_t = S q'``) lets a closed-loop mechanism whose loop closure is linear in the
angles (the PHANToM's parallelogram) be computed on its open tree::

    D = S^T M_t(S q) S,   C q' + G = S^T rnea(S q, S q', 0),   J = J_t(S q) S

A model whose configuration is not its joint angles (continuous joints: ``(cos, sin)``) takes our
angles through ``pinocchio.integrate`` from its neutral configuration. ``tree_model`` builds a tree
of revolute joints with point-like bodies (``_pinocchio_tree``); URDF arms come from
``_pinocchio_urdf``. SI units throughout; gravity is 9.81 m/s^2 along -z.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from haptic_dob.core.models.base import DeviceModel, Mat, Vec
from haptic_dob.core.validation import vector

#: standard gravity (m/s^2), pointing along -z of the base frame
GRAVITY_M_S2 = 9.81
_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


# --- the device model on a pinocchio model -----------------------------------------------------
class PinocchioModel(DeviceModel):
    """A ``DeviceModel`` computed by pinocchio on ``model`` (one ``Data``, built here).

    Args:
        model: the pinocchio model (this object owns it from now on).
        frame_id: id of the end-effector frame (its origin is the end-effector point).
        joint_names: names of the joint-space coordinates, in order.
        S: constant map from our coordinates to pinocchio's (``q_t = S q``), None = identity.
        gravity: False leaves gravity out (G = 0), e.g. for an observer's model (thesis 5.2.1).
        viscous, coulomb: joint friction b (N m s/rad or N s/m) and Fc (N m or N), scalar or
            per joint, >= 0: ``b q' + Fc sgn(q')``.
        coulomb_speed: v_c (rad/s or m/s), scalar or per joint, >= 0: where > 0 the Coulomb
            term is ``Fc tanh(q' / v_c)`` (a friction that turns over a speed, as identified).
        armature: rotor inertia reflected to each joint (kg m^2 or kg), scalar or per joint,
            >= 0: added to D's diagonal (pinocchio's ``armature``; ``S`` then a permutation).
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
        coulomb: float | Sequence[float] = 0.0,
        coulomb_speed: float | Sequence[float] = 0.0,
        armature: float | Sequence[float] = 0.0,
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
        # continuous joints: pinocchio's configuration is (cos, sin), ours the angle
        self._angles_to_config = model.nq != model.nv
        self._neutral = pin.neutral(model)
        # pinocchio's mimic joints: computeAllTerms and computePotentialEnergy refuse them
        self._mimic = any(
            model.joints[i].shortname() == "JointModelMimic" for i in range(1, model.njoints)
        )
        self.viscous = self._per_joint("viscous", viscous)
        self.coulomb = self._per_joint("coulomb", coulomb)
        self.coulomb_speed = self._per_joint("coulomb_speed", coulomb_speed)
        self._has_coulomb = bool(np.any(self.coulomb > 0.0))
        self._has_friction = bool(np.any(self.viscous > 0.0) or self._has_coulomb)
        # Fc tanh(q' / v_c) where v_c > 0 (1 / v_c here, 0 elsewhere), Fc sgn(q') elsewhere
        self._smooth = self.coulomb_speed > 0.0
        speed = np.where(self._smooth, self.coulomb_speed, 1.0)
        self._inv_speed = np.where(self._smooth, 1.0 / speed, 0.0)
        self._any_smooth = bool(np.any(self._smooth & (self.coulomb > 0.0)))
        self.armature = self._per_joint("armature", armature)
        if S is None:
            model.armature[:] = self.armature
        elif np.any(self.armature > 0.0):
            if not np.array_equal(S @ S.T, np.eye(model.nv)):
                raise ValueError("armature needs one pinocchio joint per coordinate")
            model.armature[:] = S @ self.armature

    def _per_joint(self, name: str, value: float | Sequence[float]) -> Vec:
        """A scalar for every joint, or one value per joint; finite and >= 0."""
        v = np.asarray(value, dtype=np.float64)
        v = np.full(self.dof, float(v)) if v.ndim == 0 else vector(name, v, self.dof)
        if np.any(v < 0.0) or not np.all(np.isfinite(v)):
            raise ValueError(f"{name} must be finite and >= 0, got {v.tolist()}")
        return v

    # --- our coordinates to pinocchio's ------------------------------------------------------
    def _conf(self, q: Vec) -> Vec:
        """Pinocchio's configuration for our joint coordinates ``q`` (angles, offsets)."""
        qt = q if self._S is None else self._S @ q
        if self._angles_to_config:
            conf: Vec = pin.integrate(self._model, self._neutral, qt)
            return conf
        return qt

    def _vel(self, qd: Vec) -> Vec:
        """Pinocchio's velocity for ours."""
        return qd if self._S is None else self._S @ qd

    def _ours(self, M: Mat) -> Mat:
        """A (nv, nv) matrix of pinocchio's in our coordinates (``S^T M S``), copied."""
        return M.copy() if self._S is None else self._St @ M @ self._S

    def _effort(self, tau: Vec) -> Vec:
        """A generalized force of pinocchio's in our coordinates (``S^T tau``), copied."""
        return tau.copy() if self._S is None else self._St @ tau

    def _columns(self, J: Mat) -> Mat:
        """A Jacobian over pinocchio's velocity in our coordinates (``J S``), copied."""
        return J.copy() if self._S is None else J @ self._S

    # --- one pass for the observer and the simulator -------------------------------------------
    def mass_and_bias(self, q: Vec, qd: Vec) -> tuple[Mat, Vec]:
        """D(q) and C(q, q') q' + G(q) + friction(q') from one pinocchio pass (validated)."""
        return self._mass_and_bias(self._q(q), self._qd(qd))

    def _mass_and_bias(self, q: Vec, qd: Vec) -> tuple[Mat, Vec]:
        m, d = self._model, self._data
        qt = self._conf(q)
        D = self._ours(pin.crba(m, d, qt))
        h = self._effort(pin.rnea(m, d, qt, self._vel(qd), self._zero_t))
        if self._has_friction:
            h += self._friction(qd)
        return D, h

    def _mass_and_momentum_bias(self, q: Vec, qd: Vec) -> tuple[Mat, Vec]:
        """D(q) and ``G + friction - C^T q'`` from pinocchio's Coriolis matrix (mimic joints,
        which it refuses: ``DeviceModel``'s differences)."""
        if self._mimic:
            return super()._mass_and_momentum_bias(q, qd)
        m, d = self._model, self._data
        qt, vt = self._conf(q), self._vel(qd)
        C = pin.computeCoriolisMatrix(m, d, qt, vt)
        beta = self._effort(pin.computeGeneralizedGravity(m, d, qt) - C.T @ vt)
        D = self._ours(pin.crba(m, d, qt))
        if self._has_friction:
            beta += self._friction(qd)
        return D, beta

    def inverse_dynamics(self, q: Vec, qd: Vec, qdd: Vec) -> Vec:
        """The effort ``D q'' + C q' + G + friction`` that moves the arm so (RNEA, validated)."""
        q_, qd_, qdd_ = self._q(q), self._qd(qd), self._qd(qdd)
        m, d = self._model, self._data
        tau = self._effort(pin.rnea(m, d, self._conf(q_), self._vel(qd_), self._vel(qdd_)))
        if self._has_friction:
            tau += self._friction(qd_)
        return tau

    # --- DeviceModel ---------------------------------------------------------------------------
    def _mass_matrix(self, q: Vec) -> Mat:
        return self._ours(pin.crba(self._model, self._data, self._conf(q)))

    def _rnea(self, q: Vec, qd: Vec) -> Vec:
        m, d = self._model, self._data
        return self._effort(pin.rnea(m, d, self._conf(q), self._vel(qd), self._zero_t))

    def _coriolis_vector(self, q: Vec, qd: Vec) -> Vec:
        return self._rnea(q, qd) - self._gravity(q)

    def _gravity(self, q: Vec) -> Vec:
        return self._effort(pin.computeGeneralizedGravity(self._model, self._data, self._conf(q)))

    def _friction(self, qd: Vec) -> Vec:
        f: Vec = self.viscous * qd
        if self._any_smooth:
            f += self.coulomb * np.where(self._smooth, np.tanh(qd * self._inv_speed), np.sign(qd))
        elif self._has_coulomb:
            f += self.coulomb * np.sign(qd)
        return f

    def _bias_effort(self, q: Vec, qd: Vec) -> Vec:
        h = self._rnea(q, qd)
        if self._has_friction:
            h += self._friction(qd)
        return h

    def _jacobian(self, q: Vec) -> Mat:
        m, d = self._model, self._data
        J: Mat = pin.computeFrameJacobian(m, d, self._conf(q), self._fid, _LWA)[:3]
        return self._columns(J)

    def _forward_kinematics(self, q: Vec) -> Vec:
        m, d = self._model, self._data
        pin.forwardKinematics(m, d, self._conf(q))
        x: Vec = pin.updateFramePlacement(m, d, self._fid).translation.copy()
        return x

    def _tip_state(self, q: Vec, qd: Vec) -> tuple[Vec, Mat, Vec]:
        """End-effector point p (m), linear Jacobian J (3, dof) and ``J' q'`` (m/s^2).

        ``J' q'`` is the point's acceleration at zero joint acceleration (the classical
        acceleration, centripetal terms included): what a point mass at the tip adds to the bias.
        """
        m, d = self._model, self._data
        qt = self._conf(q)
        pin.forwardKinematics(m, d, qt, self._vel(qd), self._zero_t)
        p = pin.updateFramePlacement(m, d, self._fid).translation.copy()
        acc = pin.getFrameClassicalAcceleration(m, d, self._fid, _LWA).linear.copy()
        pin.computeJointJacobians(m, d, qt)
        return p, self._columns(pin.getFrameJacobian(m, d, self._fid, _LWA)[:3]), acc

    def _dynamics_and_tip(self, q: Vec, qd: Vec) -> tuple[Mat, Vec, Vec, Mat, Vec]:
        """D, bias effort, end-effector point, its Jacobian and ``J' q'`` from one pass.

        One ``computeAllTerms`` (what the simulator needs at every integration stage when forces
        act at the tip); with mimic joints, which it refuses, the two passes it stands for.
        """
        if self._mimic:
            D, h = self._mass_and_bias(q, qd)
            return (D, h, *self._tip_state(q, qd))
        m, d, fid = self._model, self._data, self._fid
        pin.computeAllTerms(m, d, self._conf(q), self._vel(qd))
        J = self._columns(pin.getFrameJacobian(m, d, fid, _LWA)[:3])
        p = pin.updateFramePlacement(m, d, fid).translation.copy()
        acc = pin.getFrameClassicalAcceleration(m, d, fid, _LWA).linear.copy()
        D, h = self._ours(d.M), self._effort(d.nle)
        if self._has_friction:
            h += self._friction(qd)
        return D, h, p, J, acc

    # --- forward dynamics for the simulator (ABA: no mass matrix, no linear solve) ------------
    @property
    def _has_forward_dynamics(self) -> bool:
        """Whether ``_tip_motion`` and ``_forward_dynamics`` apply: our coordinates are
        pinocchio's velocity coordinates (no selection, no mimic joint)."""
        return self._S is None and not self._mimic

    def _tip_motion(self, q: Vec, qd: Vec) -> tuple[Vec, Vec]:
        """End-effector point p (m) and its velocity ``J q'`` (m/s), from one kinematics pass."""
        m, d, fid = self._model, self._data, self._fid
        pin.forwardKinematics(m, d, self._conf(q), qd)
        p = pin.updateFramePlacement(m, d, fid).translation.copy()
        return p, pin.getFrameVelocity(m, d, fid, _LWA).linear.copy()

    def _forward_dynamics(self, q: Vec, qd: Vec, tau: Vec, f_tip: Vec | None) -> Vec:
        """Rigid-body joint acceleration (rad/s^2) under effort ``tau`` and a force ``f_tip`` (N,
        world frame) at the end effector, friction left to the caller: ``D^-1 (tau - C q' - G +
        J^T f)`` by pinocchio's ABA, no mass matrix and no solve (the simulated arm's integrator
        calls it 8 times a sample)."""
        m, d = self._model, self._data
        qt = self._conf(q)
        if f_tip is not None and (f_tip[0] != 0.0 or f_tip[1] != 0.0 or f_tip[2] != 0.0):
            J = pin.computeFrameJacobian(m, d, qt, self._fid, _LWA)[:3]
            tau = tau + J.T @ f_tip
        a: Vec = pin.aba(m, d, qt, qd, tau).copy()
        return a

    def potential_energy(self, q: Vec) -> float:
        """Gravitational potential energy (J) of the device at ``q`` (0 without gravity)."""
        m, d = self._model, self._data
        conf = self._conf(self._q(q))
        if self._mimic:  # m g z of the centre of mass (gravity along -z)
            com_z = float(pin.centerOfMass(m, d, conf)[2])
            return float(pin.computeTotalMass(m)) * -float(m.gravity.linear[2]) * com_z
        return float(pin.computePotentialEnergy(m, d, conf))
