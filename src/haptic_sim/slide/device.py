"""The simulated slide: plant, encoder, force sensor and hand in one stepping object.

The plant's physics is ``SlideDeviceParams`` (``haptic_sim.slide.plant``: stiction, Stribeck
friction and the amplifier's lag beyond the thesis's model): ``(m + m_h) x'' = F_a + F_grip -
c x' - F_f``, ``F_grip = k_h (x_r - x) + b_h (x_r' - x') + f_ff`` (the hand).

``substeps`` physics steps per control period (at least 10 kHz at 1 kHz control), each the exact
solution of the linear part (a 2x2 matrix exponential computed once) with the applied force, the
hand's reference and the friction held over the step: a semi-implicit Euler step would move the
mass ahead of the held force by ``T / (2 n)``. The command is held over the period and saturated
at ``max_force_n``. The encoder quantizes to ``encoder_resolution_m`` (after a white noise of
``encoder_noise_m``); velocity is the backward difference of the encoder positions, as a real
driver computes it."""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import expm

from haptic_dob.core.models.slide import SlideParams
from haptic_dob.core.validation import positive, unit_vector
from haptic_msgs_py.stamps import period_ns
from haptic_sim.device.sample import DeviceSample
from haptic_sim.hand import HandParams, HandReference, Reference
from haptic_sim.sensor import ForceSensor, ForceSensorParams, quantize
from haptic_sim.slide.plant import SlideDeviceParams


class SimulatedSlide:
    """Plant + encoder + force sensor + hand, stepping in the device cycle contract.

    Args:
        device: the plant's physics, actuator, encoder and start (``SlideDeviceParams``).
        sensor: force-sensor settings.
        hand: hand settings.
        rate_hz: control rate (Hz), > 0.
        substeps: physics steps per control period, >= 1.
        seed: seed of the hand's reference, the sensor noise and the encoder noise.
        axis: the slide's direction in the base frame (unit 3-vector).
        reference: the hand's reference along the axis, shared with other axes (None: one of its
            own from ``hand``, whose grip, mass and behaviour it takes either way).
    """

    dof = 1

    def __init__(
        self,
        device: SlideDeviceParams | None = None,
        sensor: ForceSensorParams | None = None,
        hand: HandParams | None = None,
        rate_hz: float = 1000.0,
        substeps: int = 10,
        seed: int = 0,
        axis: tuple[float, float, float] = (1.0, 0.0, 0.0),
        reference: Reference | None = None,
    ) -> None:
        self.device = device or SlideDeviceParams()
        self.sensor_params = sensor or ForceSensorParams()
        self.hand = hand or HandParams()
        self.rate_hz = positive("rate_hz", rate_hz)
        if int(substeps) != substeps or substeps < 1:
            raise ValueError(f"substeps must be an integer >= 1, got {substeps!r}")
        self.substeps = int(substeps)
        self.period_ns = period_ns(self.rate_hz)
        self.dt = self.period_ns * 1e-9
        self.dt_physics = self.dt / self.substeps
        d = self.device
        #: the plant's rigid-body part (true mass, viscous and Coulomb friction, axis)
        self.model = SlideParams(
            d.mass_kg, d.viscous_n_s_per_m, d.coulomb_n, tuple(unit_vector("axis", axis))
        ).model()
        self.max_effort = (d.max_force_n,)  # actuator saturation per joint
        self._axis = tuple(float(a) for a in self.model.axis)
        hand_rng, sensor_rng, encoder_rng = (
            np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(3)
        )
        self._reference: Reference = (
            HandReference(self.hand, self.dt_physics, hand_rng) if reference is None else reference
        )
        self._sensor = ForceSensor(self.sensor_params, self.dt_physics, sensor_rng)
        self._encoder_rng = encoder_rng
        self._discretise()
        # state
        self._k = 0
        self.x = d.initial_position_m
        self.v = 0.0
        self.accel = 0.0
        self.applied_force = 0.0  # N: the amplifier's output (lags the command)
        self.hand_force_true = 0.0
        self._q = self._encode(self.x)
        self._q_prev = self._q
        self._effort_applied = 0.0
        self._i_phys = 0
        self._sample = self._make_sample()

    @property
    def k(self) -> int:
        """Index of the current sample."""
        return self._k

    def sample(self) -> DeviceSample:
        """The current sample k."""
        return self._sample

    def prepare(self) -> None:
        """Do ahead the work the next ``apply`` would otherwise do first (the hand's next block)."""
        if self.hand.active:
            self._reference.prepare(self._i_phys + self.substeps - 1)

    def apply(self, effort: list[float] | tuple[float, ...]) -> None:
        """Hold ``effort`` (N, length 1; saturated at max_force_n) over [k, k+1) and step to k+1.

        Non-finite or wrong-length efforts raise ``ValueError`` and change nothing.
        """
        if len(effort) != 1:
            raise ValueError(f"effort must have length 1, got {len(effort)}")
        u = float(effort[0])
        if not math.isfinite(u):
            raise ValueError(f"effort must be finite, got {u}")
        lim = self.device.max_force_n
        u = lim if u > lim else (-lim if u < -lim else u)
        self._integrate(u)
        self._effort_applied = u
        self._k += 1
        self._q_prev = self._q
        self._q = self._encode(self.x)
        self._sample = self._make_sample()

    def _encode(self, x: float) -> float:
        """The encoder's reading of position ``x`` (m): its noise, then its counts."""
        d = self.device
        if d.encoder_noise_m > 0.0:
            x += d.encoder_noise_m * float(self._encoder_rng.standard_normal())
        return quantize(x, d.encoder_resolution_m)

    # ------------------------------------------------------------------------------------------
    def _integrate(self, u: float) -> None:
        h = self.hand
        b = self.device.viscous_n_s_per_m
        # moving: fc + rise * exp(-v^2 / vs^2) (SlideDeviceParams.friction_n, inlined)
        fc, fs, rise, inv_vs2 = self._friction
        exp = math.exp
        kh, bh, mh = h.stiffness_n_per_m, h.damping_n_s_per_m, h.mass_kg
        inv_m = self._inv_total_mass
        p00, p01, p10, p11, g0, g1 = self._step_matrices
        lag_end, lag_mean = self._lag
        active = h.active
        x, v, fa = self.x, self.v, self.applied_force
        a = 0.0
        grip = 0.0
        sensor = self._sensor
        for _ in range(self.substeps):
            ua = u + (fa - u) * lag_mean  # the applied force's mean over the step
            fa = u + (fa - u) * lag_end
            drive = ua
            if active:
                xr, vr, ff, j = self._reference.arrays(self._i_phys)
                grip = kh * (xr[j] - x) + bh * (vr[j] - v) + ff[j]
                drive = ua + kh * xr[j] + bh * vr[j] + ff[j]
            self._i_phys += 1
            f = ua + grip - b * v  # every force but the dry friction, at the start of the step
            if v != 0.0:
                mag = fc + rise * exp(-v * v * inv_vs2) if rise else fc
                friction = mag if v > 0.0 else -mag
            elif f > fs:
                friction = fs
            elif f < -fs:
                friction = -fs
            else:  # stuck: static friction balances the rest
                a = 0.0
                sensor.track(grip)
                continue
            a = (f - friction) * inv_m
            w = drive - friction
            x_new = p00 * x + p01 * v + g0 * w
            v_new = p10 * x + p11 * v + g1 * w
            if fs > 0.0 and ((v > 0.0 > v_new) or (v < 0.0 < v_new)):
                v_new = 0.0
            x, v = x_new, v_new
            sensor.track(grip - mh * a)
        self.x, self.v, self.accel, self.applied_force = x, v, a, fa
        self.hand_force_true = grip - mh * a

    def _discretise(self) -> None:
        """Matrix exponential of the linear part over one physics step (zero-order hold input),
        the friction's constants, and the amplifier lag's factors over one step (end, mean)."""
        h, d = self.hand, self.device
        M = d.mass_kg + (h.mass_kg if h.active else 0.0)  # no hand, no hand mass
        kh = h.stiffness_n_per_m if h.active else 0.0
        bh = h.damping_n_s_per_m if h.active else 0.0
        A = np.array([[0.0, 1.0], [-kh / M, -(d.viscous_n_s_per_m + bh) / M]])
        B = np.array([[0.0], [1.0 / M]])
        aug = np.zeros((3, 3))
        aug[:2, :2], aug[:2, 2:] = A, B
        E = expm(aug * self.dt_physics)
        self._step_matrices = tuple(
            float(E[i, j]) for i, j in ((0, 0), (0, 1), (1, 0), (1, 1), (0, 2), (1, 2))
        )
        self._inv_total_mass = 1.0 / M
        # friction: Coulomb, breakaway, the Stribeck rise and 1 / v_s^2 (as friction_n has them)
        fc, vs = d.coulomb_n, d.stribeck_velocity_m_per_s
        fs = fc * d.stiction_ratio
        self._friction = (fc, fs, fs - fc if vs > 0.0 else 0.0, 1.0 / (vs * vs) if vs else 0.0)
        tau, step = d.amplifier_lag_s, self.dt_physics
        if tau > 0.0:
            end = math.exp(-step / tau)
            self._lag = (end, (1.0 - end) * tau / step)
        else:
            self._lag = (0.0, 0.0)

    def _make_sample(self) -> DeviceSample:
        q = self._q
        qd = (q - self._q_prev) / self.dt
        ax = self._axis
        fm = self._sensor.read()
        fh = self.hand_force_true
        return DeviceSample(
            k=self._k,
            stamp_ns=self._k * self.period_ns,
            q=(q,),
            qd=(qd,),
            effort=(self._effort_applied,),
            ee_position=(ax[0] * q, ax[1] * q, ax[2] * q),
            ee_velocity=(ax[0] * qd, ax[1] * qd, ax[2] * qd),
            wrench_measured=(ax[0] * fm, ax[1] * fm, ax[2] * fm),
            hand_force=(ax[0] * fh, ax[1] * fh, ax[2] * fh),
        )
