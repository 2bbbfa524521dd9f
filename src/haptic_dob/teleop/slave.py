"""The slave arm's law: a joint impedance around a joint target that follows a Cartesian point.

Per cycle, with the joint state of sample k and the point ``x_d`` to track (m, base frame):

1. a damped-least-squares inverse-kinematics step moves the joint target ``q_d`` toward ``x_d``:
   ``dq = J# (x_d - p(q_d)) + (I - J# J) k_n (q_0 - q_d)``, ``J# = J^T (J J^T + lambda^2 I)^-1``
   at ``q_d``, ``q_0`` the start posture, ``dq`` limited to ``max_joint_speed_rad_s`` per period;
2. ``tau = K (q_d - q) - B q' + G(q)`` (the controller's model's gravity), saturated per joint at
   the model's effort limits (``haptic_dob.core.control.saturate``).

Gains: ``K = D(q_0) w^2``, ``B = 2 zeta w D(q_0)``, ``w = 2 pi bandwidth_hz`` (per-joint gains,
when given, are diagonal); ``q_d``, ``q_0`` start at the first sample's positions. With
``trajectory_path`` (an excitation file) it plays that by computed torque (``play``; why the
full matrices, the target in contact and this law: docs/design/teleoperation.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from haptic_dob.core.control import saturate
from haptic_dob.core.models.base import DeviceModel, Vec
from haptic_dob.core.validation import nonnegative, positive
from haptic_dob.identification.arm_excitation import FourierExcitation
from haptic_dob.runtime.params import param

#: how long the difference between the arm's first posture and a trajectory's start fades (s)
BLEND_S = 2.0


@dataclass(frozen=True)
class SlaveImpedance:
    """The slave's joint impedance and inverse kinematics (group ``slave.``)."""

    bandwidth_hz: float = field(
        default=8.0,
        metadata=param(
            description="each joint's loop bandwidth on its own inertia at the start pose",
            unit="Hz",
            bounds=(0.1, 200.0),
        ),
    )
    damping_ratio: float = field(
        default=1.0, metadata=param(description="each joint's damping ratio", bounds=(0.0, 10.0))
    )
    stiffness_n_m_per_rad: list[float] | tuple[float, ...] = field(
        default_factory=list,
        metadata=param(
            description="joint stiffness K, one per joint; [] = from bandwidth_hz",
            unit="N m/rad",
            bounds=(0.0, 1e6),
        ),
    )
    damping_n_m_s_per_rad: list[float] | tuple[float, ...] = field(
        default_factory=list,
        metadata=param(
            description="joint damping B, one per joint; [] = from damping_ratio",
            unit="N m s/rad",
            bounds=(0.0, 1e5),
        ),
    )
    ik_damping_m: float = field(
        default=0.01,
        metadata=param(
            description="damping lambda of the IK's least squares", unit="m", bounds=(1e-6, 1.0)
        ),
    )
    posture_gain: float = field(
        default=0.01,
        metadata=param(
            description="per-period pull of the redundant joints toward the start posture",
            bounds=(0.0, 1.0),
        ),
    )
    max_joint_speed_rad_s: float = field(
        default=2.0,
        metadata=param(
            description="largest speed of the joint target", unit="rad/s", bounds=(1e-3, 100.0)
        ),
    )
    gravity_compensation: bool = field(
        default=True, metadata=param(description="add the model's gravity effort")
    )
    trajectory_path: str = field(
        default="",
        metadata=param(
            description="excitation trajectory file to play; '' = track pose_desired",
            details="Joint targets by time, as haptic-excite writes them.",
        ),
    )

    def __post_init__(self) -> None:
        positive("bandwidth_hz", self.bandwidth_hz)
        nonnegative("damping_ratio", self.damping_ratio)
        for name in ("stiffness_n_m_per_rad", "damping_n_m_s_per_rad"):
            for i, v in enumerate(getattr(self, name)):
                nonnegative(f"{name}[{i}]", v)
        positive("ik_damping_m", self.ik_damping_m)
        if not 0.0 <= self.posture_gain <= 1.0:
            raise ValueError(f"posture_gain must be in [0, 1], got {self.posture_gain!r}")
        positive("max_joint_speed_rad_s", self.max_joint_speed_rad_s)


class SlaveController:
    """Joint impedance tracking a Cartesian point through differential IK (see the module).

    Args:
        model: the slave's model (its kinematics, inertia at the start pose, gravity, limits).
        settings: gains and IK settings.
        dt: the control period (s).
        trajectory: a trajectory to play (default: ``settings.trajectory_path``'s, if any).
    """

    def __init__(
        self,
        model: DeviceModel,
        settings: SlaveImpedance,
        dt: float,
        trajectory: FourierExcitation | None = None,
    ) -> None:
        self.model = model
        self.settings = settings
        self.dt = positive("dt", dt)
        n = model.dof
        for name in ("stiffness_n_m_per_rad", "damping_n_m_s_per_rad"):
            given = getattr(settings, name)
            if given and len(given) != n:
                raise ValueError(f"slave.{name} needs {n} values (one per joint), got {len(given)}")
        limits = getattr(model, "effort_limits", None)
        self.limits: list[float] | None = (
            [float(x) for x in limits]
            if limits is not None and len(limits) == n and all(x > 0.0 for x in limits)
            else None
        )
        self._eye3 = np.eye(3) * settings.ik_damping_m**2
        self.q_d: Vec | None = None  # the joint target
        self.q_0: Vec = np.zeros(n)  # the posture the redundant joints return to
        self.K = np.zeros((n, n))  # joint stiffness (N m/rad)
        self.B = np.zeros((n, n))  # joint damping (N m s/rad)
        self.trajectory = trajectory
        if trajectory is None and settings.trajectory_path:
            self.trajectory = FourierExcitation.load(settings.trajectory_path)
        if self.trajectory is not None and self.trajectory.joints != tuple(model.joint_names):
            raise ValueError(
                f"slave.trajectory_path: the trajectory moves {list(self.trajectory.joints)}, "
                f"the model's joints are {list(model.joint_names)}"
            )

    def start(self, q: Vec) -> None:
        """Take ``q`` as the joint target, the posture and the pose the gains are set at."""
        s = self.settings
        self.q_d = q.copy()
        self.q_0 = q.copy()
        inertia = self.model._mass_matrix(q)
        w = 2.0 * math.pi * s.bandwidth_hz
        given_k, given_b = s.stiffness_n_m_per_rad, s.damping_n_m_s_per_rad
        self.K = np.diag(given_k) if given_k else inertia * (w * w)
        self.B = np.diag(given_b) if given_b else inertia * (2.0 * s.damping_ratio * w)

    def command(self, q: Vec, qd: Vec, target: tuple[float, float, float]) -> list[float]:
        """Joint efforts (N m or N) for sample ``q``, ``q'`` and the point to track (m)."""
        if self.q_d is None:
            self.start(q)
        q_d = self.q_d
        assert q_d is not None
        m, s = self.model, self.settings
        J = m._jacobian(q_d)
        e = np.asarray(target) - m._forward_kinematics(q_d)
        A = J @ J.T + self._eye3
        Jsharp = J.T @ np.linalg.inv(A)  # (n, 3)
        dq = Jsharp @ e
        if s.posture_gain > 0.0:
            w = s.posture_gain * (self.q_0 - q_d)
            dq += w - Jsharp @ (J @ w)
        step = s.max_joint_speed_rad_s * self.dt
        biggest = float(np.max(np.abs(dq)))
        if biggest > step:
            dq *= step / biggest
        q_d = q_d + dq
        self.q_d = q_d
        return self.joint_command(q, qd, q_d)

    def play(self, q: Vec, qd: Vec, t_s: float) -> list[float]:
        """Joint efforts (N m or N) playing the trajectory at ``t_s`` (s since the first sample)."""
        traj = self.trajectory
        if traj is None:
            raise ValueError("no trajectory to play (slave.trajectory_path is '')")
        if self.q_d is None:
            self.start(q)
        (q_d,), (v_d,), (a_d,) = traj.motion(np.array([t_s]))
        if t_s < BLEND_S:
            gap = self.q_0 - np.asarray(traj.start)
            phase = math.pi * t_s / BLEND_S
            w = math.pi / BLEND_S
            q_d = q_d + (0.5 + 0.5 * math.cos(phase)) * gap
            v_d = v_d - 0.5 * w * math.sin(phase) * gap
            a_d = a_d - 0.5 * w * w * math.cos(phase) * gap
        s = self.settings
        w = 2.0 * math.pi * s.bandwidth_hz
        D, h = self.model._mass_matrix(q), self.model._bias_effort(q, qd)
        tau = D @ (a_d + w * w * (q_d - q) + 2.0 * s.damping_ratio * w * (v_d - qd)) + h
        out: list[float] = tau.tolist()
        return out if self.limits is None else saturate(out, self.limits)

    def joint_command(self, q: Vec, qd: Vec, q_d: Vec, qd_d: Vec | None = None) -> list[float]:
        """``K (q_d - q) + B (q_d' - q') + G(q)``, saturated (N m or N): the impedance around
        ``q_d`` (``q_d'`` = 0 when not given)."""
        if self.q_d is None:
            self.start(q)
        tau = self.K @ (q_d - q) - self.B @ (qd if qd_d is None else qd - qd_d)
        if self.settings.gravity_compensation:
            tau += self.model._gravity(q)
        out: list[float] = tau.tolist()
        return out if self.limits is None else saturate(out, self.limits)
