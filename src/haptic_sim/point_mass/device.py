"""A simulated Cartesian device (a Force Dimension Omega or Falcon as its driver sees it).

Three uncoupled axes along the base frame's x, y and z, each the simulated slide's plant
(``haptic_sim.slide.device``) with its own truth: mass, viscous and Coulomb friction, stiction
with a Stribeck fall-off that the point-mass model misses, the amplifier's lag, the actuator's
saturation, encoder counts after a white noise, and a force sensor at the handle. One hand holds
the handle in 3-D (``haptic_sim.hand_space``): its reference is the sum of a push along
``hand_direction`` and motions across it, each axis's plant taking its component (the grip's
spring, damper and mass act on every axis alike). ``hand.behaviour: none``: the stylus is not held.

The sample's joints are the end effector's x, y, z (m, the model's ``joint_names``: ``fd_x, fd_y,
fd_z`` by default), velocity the encoders' backward difference, effort the command applied over
[k-1, k) after saturation, as ``forcedimension_ros2`` reports them; the end-effector point is the
joints.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from haptic_dob.core.models.point_mass import FD_JOINTS, PointMassModel
from haptic_dob.core.validation import finite_scalar, nonnegative, positive, unit_vector, vector
from haptic_dob.runtime.params import param
from haptic_msgs_py.stamps import period_ns
from haptic_sim.device.sample import DeviceSample
from haptic_sim.hand import HandParams
from haptic_sim.hand_space import CartesianReference, hand_references
from haptic_sim.sensor import ForceSensorParams
from haptic_sim.slide.device import SimulatedSlide
from haptic_sim.slide.plant import SlideDeviceParams

#: the Force Dimension SDK's force cap with gravity compensation on (N per axis)
FD_MAX_FORCE_N = 12.0
AXES = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
Vec3 = tuple[float, float, float]


@dataclass(frozen=True)
class PointMassDeviceParams:
    """The simulated Cartesian device (the device's ``cartesian.*``): its truth per axis, its
    actuators, encoders, start and the hand's geometry.

    The defaults are a device of a Force Dimension Omega's class, not its datasheet: masses of a
    few hundred grams, light friction, stiction 1.5 times the Coulomb level falling off over
    5 mm/s, a 0.1 ms current loop, 2 um encoder counts (the class's resolution is better than
    0.01 mm) after 0.5 um of noise.
    """

    mass_kg: Vec3 = field(
        default=(0.25, 0.22, 0.28),
        metadata=param(
            description="the plant's true moving mass per axis (x, y, z)",
            unit="kg",
            bounds=(1e-3, 100.0),
        ),
    )
    viscous_n_s_per_m: Vec3 = field(
        default=(1.0, 0.8, 1.2),
        metadata=param(
            description="the plant's true viscous friction per axis",
            unit="N s/m",
            bounds=(0.0, 1e3),
        ),
    )
    coulomb_n: Vec3 = field(
        default=(0.06, 0.05, 0.08),
        metadata=param(
            description="the plant's true Coulomb (sliding) friction per axis",
            unit="N",
            bounds=(0.0, 100.0),
        ),
    )
    stiction_ratio: float = field(
        default=1.5,
        metadata=param(
            description="static friction (breakaway) over the Coulomb level", bounds=(1.0, 10.0)
        ),
    )
    stribeck_velocity_m_per_s: float = field(
        default=0.005,
        metadata=param(
            description="speed over which friction falls from static to Coulomb",
            unit="m/s",
            bounds=(0.0, 1.0),
        ),
    )
    amplifier_lag_s: float = field(
        default=1e-4,
        metadata=param(
            description="time constant of the amplifiers' current loops",
            unit="s",
            bounds=(0.0, 0.1),
        ),
    )
    max_force_n: float = field(
        default=FD_MAX_FORCE_N,
        metadata=param(
            description="actuator saturation per axis (the SDK's cap)", unit="N", bounds=(1e-3, 1e3)
        ),
    )
    encoder_resolution_m: float = field(
        default=2e-6,
        metadata=param(description="encoder resolution per axis", unit="m", bounds=(1e-12, 1e-2)),
    )
    encoder_noise_m: float = field(
        default=5e-7,
        metadata=param(
            description="white noise on the position before the encoder counts (std)",
            unit="m",
            bounds=(0.0, 1e-2),
        ),
    )
    initial_position: Vec3 = field(
        default=(0.0, 0.0, 0.0),
        metadata=param(description="end-effector point at start (x, y, z)", unit="m"),
    )
    hand_direction: Vec3 = field(
        default=(0.0, 0.0, -1.0),
        metadata=param(description="direction of the hand's push (unit 3-vector, base frame)"),
    )
    hand_lateral_amplitude_m: float = field(
        default=0.0,
        metadata=param(
            description="std of the semi-random hand motion across the push",
            unit="m",
            bounds=(0.0, 1.0),
        ),
    )

    def __post_init__(self) -> None:
        for i in range(3):
            positive(f"mass_kg[{i}]", self.mass_kg[i])
            nonnegative(f"viscous_n_s_per_m[{i}]", self.viscous_n_s_per_m[i])
            nonnegative(f"coulomb_n[{i}]", self.coulomb_n[i])
        vector("initial_position", self.initial_position, 3)
        unit_vector("hand_direction", self.hand_direction)
        nonnegative("hand_lateral_amplitude_m", self.hand_lateral_amplitude_m)
        finite_scalar("stiction_ratio", self.stiction_ratio)
        self.axis(0)  # the rest is the slide's to check

    def axis(self, i: int) -> SlideDeviceParams:
        """Axis ``i``'s plant (0, 1, 2: x, y, z) as the simulated slide takes it."""
        return SlideDeviceParams(
            max_force_n=self.max_force_n,
            encoder_resolution_m=self.encoder_resolution_m,
            initial_position_m=float(self.initial_position[i]),
            mass_kg=float(self.mass_kg[i]),
            viscous_n_s_per_m=float(self.viscous_n_s_per_m[i]),
            coulomb_n=float(self.coulomb_n[i]),
            stiction_ratio=self.stiction_ratio,
            stribeck_velocity_m_per_s=self.stribeck_velocity_m_per_s,
            amplifier_lag_s=self.amplifier_lag_s,
            encoder_noise_m=self.encoder_noise_m,
        )

    def truth(self, joint_names: tuple[str, ...] = FD_JOINTS) -> PointMassModel:
        """The plant's rigid part as a point-mass model (what identification should find)."""
        return PointMassModel(self.mass_kg, self.viscous_n_s_per_m, self.coulomb_n, joint_names)


class SimulatedPointMass:
    """Three simulated axes and a 3-D hand, stepping in the device cycle contract.

    Args:
        device: the plant's truth, actuators, encoders, start and hand geometry.
        sensor: force-sensor settings (each axis).
        hand: hand settings (``behaviour: none``: not held).
        rate_hz: control rate (Hz), > 0.
        substeps: physics steps per control period, >= 1.
        seed: seed of the hand's reference and of each axis's sensor and encoder noise.
        joint_names: the axes' joint names.
    """

    dof = 3

    def __init__(
        self,
        device: PointMassDeviceParams | None = None,
        sensor: ForceSensorParams | None = None,
        hand: HandParams | None = None,
        rate_hz: float = 1000.0,
        substeps: int = 10,
        seed: int = 0,
        joint_names: tuple[str, ...] = FD_JOINTS,
    ) -> None:
        self.device = device or PointMassDeviceParams()
        self.hand = hand or HandParams(behaviour="none")
        #: the plant's rigid part (its true masses and friction; stiction and lag apart)
        self.model = self.device.truth(tuple(joint_names))
        self.period_ns = period_ns(positive("rate_hz", rate_hz))
        self.dt = self.period_ns * 1e-9
        self.max_effort = (self.device.max_force_n,) * 3
        if int(substeps) != substeps or substeps < 1:
            raise ValueError(f"substeps must be an integer >= 1, got {substeps!r}")
        seeds = np.random.SeedSequence(seed).spawn(6)
        rngs = [np.random.default_rng(s) for s in seeds[:3]]
        step = self.dt / int(substeps)  # the slides' physics step
        direction = unit_vector("hand_direction", self.device.hand_direction)
        refs = hand_references(
            self.hand, direction, self.device.hand_lateral_amplitude_m, step, rngs
        )
        space = CartesianReference(refs, np.asarray(self.device.initial_position)) if refs else None
        self._axes = [
            SimulatedSlide(
                self.device.axis(i),
                sensor,
                self.hand,
                rate_hz,
                substeps,
                int(seeds[3 + i].generate_state(1)[0]),
                axis=AXES[i],
                reference=None if space is None else space.axis(i),
            )
            for i in range(3)
        ]
        self._sample = self._make_sample()

    @property
    def k(self) -> int:
        """Index of the current sample."""
        return self._axes[0].k

    def sample(self) -> DeviceSample:
        """The current sample k."""
        return self._sample

    def prepare(self) -> None:
        """Do ahead the work the next ``apply`` would otherwise do first (the hand's next block)."""
        self._axes[0].prepare()

    def apply(self, effort: list[float] | tuple[float, ...]) -> None:
        """Hold ``effort`` (N per axis; saturated at max_force_n) over [k, k+1), step to k+1.

        Non-finite or wrong-length efforts raise ``ValueError`` and change nothing.
        """
        if len(effort) != 3:
            raise ValueError(f"effort must have length 3, got {len(effort)}")
        u = [float(e) for e in effort]
        if not all(np.isfinite(u)):
            raise ValueError(f"effort must be finite, got {u}")
        for axis, e in zip(self._axes, u, strict=True):
            axis.apply((e,))
        self._sample = self._make_sample()

    @property
    def position(self) -> Vec3:
        """The end effector's true position (m)."""
        x, y, z = (a.x for a in self._axes)
        return (x, y, z)

    @property
    def hand_force_true(self) -> Vec3:
        """The hand's true force on the handle (N)."""
        x, y, z = (a.hand_force_true for a in self._axes)
        return (x, y, z)

    def _make_sample(self) -> DeviceSample:
        sx, sy, sz = (a.sample() for a in self._axes)
        q = (sx.q[0], sy.q[0], sz.q[0])
        qd = (sx.qd[0], sy.qd[0], sz.qd[0])
        return DeviceSample(
            k=sx.k,
            stamp_ns=sx.stamp_ns,
            q=q,
            qd=qd,
            effort=(sx.effort[0], sy.effort[0], sz.effort[0]),
            ee_position=q,
            ee_velocity=qd,
            wrench_measured=(
                sx.wrench_measured[0],
                sy.wrench_measured[1],
                sz.wrench_measured[2],
            ),
            hand_force=(sx.hand_force[0], sy.hand_force[1], sz.hand_force[2]),
        )
