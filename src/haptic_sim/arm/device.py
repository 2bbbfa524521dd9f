"""A simulated multi-DOF arm (the PHANToM 1.5, any URDF arm): plant, encoders, sensor and hand.

Plant: any ``DeviceModel``, its acceleration at each stage ``haptic_sim.arm.acceleration``'s
(the hand's force, an optional known external force and the contact's on the tip;
``contact_force_true`` at the sample). ``substeps`` RK4 steps per control period (10 at 1 kHz),
the effort held over the period, the hand's reference and the external force over each
sub-step. Coulomb friction is smoothed to ``Fc tanh(q' / eps)``
(``arm_dynamics.coulomb_smoothing``; docs/design/friction.md). Each
joint's effort is saturated at ``joint_effort_limits``, else the model's limits, else the effort
that gives ``max_force_n`` at the tip at the start pose (``haptic_sim.arm.params``).
Encoders (``haptic_sim.arm.encoders``): counts of the joints or of ``encoder_matrix``'s rows;
velocity their backward difference. Hand (``haptic_sim.hand_space``): a mass ``m_h`` moving
with the handle (``D + m_h J^T J``) held by a grip spring and damper to its reference
(``behaviour: none``: none). Force sensor: three axes reading the handle's external force.
"""

from __future__ import annotations

import math

import numpy as np

from haptic_dob.core.environment import VirtualWall
from haptic_dob.core.models.base import DeviceModel, Vec
from haptic_dob.core.validation import positive, unit_vector, vector
from haptic_msgs_py.stamps import period_ns
from haptic_sim.arm.acceleration import ArmAcceleration
from haptic_sim.arm.contact import contact_of
from haptic_sim.arm.dynamics import coulomb_smoothing, mass_and_bias
from haptic_sim.arm.encoders import Encoders
from haptic_sim.arm.params import ArmDeviceParams, effort_limits
from haptic_sim.device.sample import DeviceSample
from haptic_sim.hand import HandParams, HandReference
from haptic_sim.hand_space import hand_references
from haptic_sim.sensor import ForceSensor, ForceSensorParams

_ZERO3 = np.zeros(3)


class SimulatedArm:
    """Plant + encoders + force sensor + 3-D hand for any ``DeviceModel`` (cycle contract).

    Args:
        model: the arm's true physics (gravity included unless the model leaves it out).
        device: actuators, encoders, start, hand direction, external force.
        sensor: force-sensor settings (each of the three axes).
        hand: hand settings (``hand.py``); default ``behaviour='none'``.
        rate_hz: control rate (Hz), > 0.
        substeps: RK4 steps per control period, >= 1.
        seed: seed of the hand's reference and the sensor noise.
        contact: a wall the end effector touches (None, or zero stiffness: none).
    """

    def __init__(
        self,
        model: DeviceModel,
        device: ArmDeviceParams | None = None,
        sensor: ForceSensorParams | None = None,
        hand: HandParams | None = None,
        rate_hz: float = 1000.0,
        substeps: int = 10,
        seed: int = 0,
        contact: VirtualWall | None = None,
    ) -> None:
        if not isinstance(model, DeviceModel):
            raise ValueError(f"model must be a DeviceModel, got {type(model).__name__}")
        self.model = model
        self.dof = model.dof
        self.device = device or ArmDeviceParams()
        self.sensor_params = sensor or ForceSensorParams()
        self.hand = hand or HandParams(behaviour="none")
        self.rate_hz = positive("rate_hz", rate_hz)
        if int(substeps) != substeps or substeps < 1:
            raise ValueError(f"substeps must be an integer >= 1, got {substeps!r}")
        self.substeps = int(substeps)
        self.period_ns = period_ns(self.rate_hz)
        self.dt = self.period_ns * 1e-9
        self.dt_physics = self.dt / self.substeps
        n = self.dof
        dev = self.device
        if dev.initial_position:
            q0 = vector("initial_position", list(dev.initial_position), n)
        else:
            q0 = np.array(getattr(model, "home", np.zeros(n)), dtype=np.float64)
        self._dyn = mass_and_bias(model)
        self._coulomb, self._coulomb_eps = coulomb_smoothing(model, self._dyn, q0, self.dt_physics)
        self.effort_limits = effort_limits(dev, model, q0)
        #: actuator saturation per joint (N m or N), the ``SimulatedDevice`` protocol's name
        self.max_effort = tuple(self.effort_limits.tolist())
        self._lim = self.effort_limits
        self._neg_lim = -self.effort_limits
        # hand and external force
        self._u = unit_vector("hand_direction", dev.hand_direction)
        self._f_ext = vector("external_force_n", dev.external_force_n, 3)
        self._ext_on_step = (
            math.ceil(dev.external_force_at_s / self.dt_physics - 1e-9)
            if np.any(self._f_ext != 0.0)
            else None
        )
        seeds = np.random.SeedSequence(seed).spawn(6)
        rngs = [np.random.default_rng(s) for s in seeds]
        h = self.hand
        self._ref: list[tuple[HandReference, Vec]] = hand_references(
            h, self._u, dev.hand_lateral_amplitude_m, self.dt_physics, rngs
        )
        self._sensors = [ForceSensor(self.sensor_params, self.dt_physics, r) for r in rngs[3:]]
        self.contact = contact_of(contact)
        self._needs_tip = h.active or self._ext_on_step is not None or self.contact is not None
        self._kh, self._bh = h.stiffness_n_per_m, h.damping_n_s_per_m
        self._mh = h.mass_kg if h.active else 0.0
        self._accel = ArmAcceleration(
            model,
            self._dyn,
            (self._coulomb, self._coulomb_eps),
            None if self.contact is None else self.contact.force,
            self._needs_tip,
            (self._kh, self._bh, self._mh),
        )
        self._exact_velocity = dev.velocity == "exact"
        # state
        self._k = 0
        self._i_phys = 0
        self.q = q0.copy()
        self.v = np.zeros(n)
        self.accel = np.zeros(n)
        self.p0 = model._forward_kinematics(self.q)
        self.hand_force_true = np.zeros(3)  # the hand's force on the handle (N)
        self.tip_force_true = np.zeros(3)  # hand + external force + contact on the tip (N)
        self.contact_force_true = np.zeros(3)  # the contact's force at the sample's state (N)
        self._effort_applied = np.zeros(n)
        self._encode = Encoders(dev.encoder_resolution_rad, dev.encoder_matrix, n).read
        self._q_enc = self._encode(self.q)
        self._q_enc_prev = self._q_enc
        self._sample = self._make_sample()

    # --- protocol --------------------------------------------------------------------------
    @property
    def k(self) -> int:
        """Index of the current sample."""
        return self._k

    def sample(self) -> DeviceSample:
        """The current sample k."""
        return self._sample

    def prepare(self) -> None:
        """Do ahead the work the next ``apply`` would otherwise do first (the hand's next block)."""
        for ref, _ in self._ref:
            ref.prepare(self._i_phys + self.substeps - 1)

    def apply(self, effort: list[float] | tuple[float, ...]) -> None:
        """Hold ``effort`` (saturated per joint) over [k, k+1) and step to k+1.

        Wrong-length or non-finite efforts raise ``ValueError`` and change nothing.
        """
        if len(effort) != self.dof:
            raise ValueError(f"effort must have length {self.dof}, got {len(effort)}")
        u = np.array(effort, dtype=np.float64)
        if u.ndim != 1 or not math.isfinite(u @ u):
            raise ValueError(f"effort must be finite, got {list(effort)!r}")
        u = np.minimum(np.maximum(u, self._neg_lim), self._lim)
        self._integrate(u)
        if self.contact is not None:  # the contact at the sample's true state, for evaluation
            c = self.contact.force_at(self.model, self.q, self.v)
            on = self._ext_on_step is not None and self._i_phys > self._ext_on_step
            self.tip_force_true = self.hand_force_true + c + (self._f_ext if on else _ZERO3)
            self.contact_force_true = c
        self._effort_applied = u
        self._k += 1
        self._q_enc_prev = self._q_enc
        self._q_enc = self._encode(self.q)
        self._sample = self._make_sample()

    # --- physics ---------------------------------------------------------------------------
    def _reference(self) -> tuple[Vec, Vec, Vec] | None:
        """Hand reference at the current physics step: position, velocity, feed-forward force."""
        if not self._ref:
            return None
        x_r, v_r, f_ff = self.p0.copy(), np.zeros(3), np.zeros(3)
        for ref, e in self._ref:
            x, xd, ff, j = ref.arrays(self._i_phys)
            x_r += x[j] * e
            v_r += xd[j] * e
            if ff[j] != 0.0:
                f_ff += ff[j] * e
        # the damper's reference velocity, the spring's anchor and the pulse, combined once
        return self._kh * x_r + self._bh * v_r + f_ff, x_r, v_r

    def _integrate(self, tau: Vec) -> None:
        hstep = self.dt_physics
        half = 0.5 * hstep
        q, v = self.q, self.v
        a1 = self.accel
        for _ in range(self.substeps):
            ref = self._reference()
            f_ext = (
                self._f_ext
                if self._ext_on_step is not None and self._i_phys >= self._ext_on_step
                else _ZERO3
            )
            a1 = self._accel(q, v, tau, f_ext, ref)
            if self._needs_tip:
                grip, J, jdv, external = self._accel.last
                hand = grip - self._mh * (J @ a1 + jdv) if ref is not None else grip
                total = hand + external
                for s, f in zip(self._sensors, total.tolist(), strict=True):
                    s.track(f)
                self.hand_force_true, self.tip_force_true = hand, total
            v2 = v + half * a1
            a2 = self._accel(q + half * v, v2, tau, f_ext, ref)
            v3 = v + half * a2
            a3 = self._accel(q + half * v2, v3, tau, f_ext, ref)
            v4 = v + hstep * a3
            a4 = self._accel(q + hstep * v3, v4, tau, f_ext, ref)
            q = q + (hstep / 6.0) * (v + 2.0 * (v2 + v3) + v4)
            v = v + (hstep / 6.0) * (a1 + 2.0 * (a2 + a3) + a4)
            self._i_phys += 1
        self.q, self.v, self.accel = q, v, a1

    # --- sensing ---------------------------------------------------------------------------
    def _make_sample(self) -> DeviceSample:
        q = self._q_enc
        qd = self.v.copy() if self._exact_velocity else (q - self._q_enc_prev) / self.dt
        m = self.model
        p = m._forward_kinematics(q)
        pv = m._jacobian(q) @ qd
        fm = tuple(s.read() for s in self._sensors)
        fh = self.tip_force_true
        return DeviceSample(
            k=self._k,
            stamp_ns=self._k * self.period_ns,
            q=tuple(q.tolist()),
            qd=tuple(qd.tolist()),
            effort=tuple(self._effort_applied.tolist()),
            ee_position=(float(p[0]), float(p[1]), float(p[2])),
            ee_velocity=(float(pv[0]), float(pv[1]), float(pv[2])),
            wrench_measured=(fm[0], fm[1], fm[2]),
            hand_force=(float(fh[0]), float(fh[1]), float(fh[2])),
        )

    # --- evaluation ------------------------------------------------------------------------
    @property
    def time_s(self) -> float:
        """Simulated time of the current sample (s)."""
        return self._k * self.dt

    @property
    def coulomb_speeds(self) -> list[float]:
        """The speed (rad/s or m/s) over which the plant turns each joint's Coulomb friction,
        ``Fc tanh(q' / eps)``: the simulator's smoothing at its physics step ([] without Coulomb
        friction). Part of the plant's truth: an identification finds it as ``v_c``."""
        return [] if self._coulomb is None else self._coulomb_eps.tolist()

    def kinetic_energy(self) -> float:
        """``q'^T D q' / 2`` (J) of the arm's true state (the hand's mass not included)."""
        D, _ = self._dyn(self.q, self.v)
        return 0.5 * float(self.v @ D @ self.v)


__all__ = ["ArmDeviceParams", "SimulatedArm"]
