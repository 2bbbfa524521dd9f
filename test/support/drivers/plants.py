"""The simulated plants under the test drivers, with the truth a test knows and the loop does not.

A plant is anything with the simulated device's cycle contract (``haptic_sim.device.sample.
SimulatedDevice``: ``sample()`` is sample k, ``apply(effort)`` holds an effort over [k, k+1) and
steps to k+1) plus ``truth()``, its hidden parameters. A driver owns one and never looks inside,
so another plant (an identified device model's, say) drops in by building it here.

- ``cartesian_slides``: a Force Dimension-like device as three of the suite's slides, one per
  base axis (mass, viscous and Coulomb friction, stiction, amplifier lag each), the hand on one
  of them: joints ``fd_x, fd_y, fd_z`` in metres.
- ``phantom``: the suite's PHANToM 1.5 (thesis appendix B) with joint friction, as a Touch: the
  driver computes the joint torques of a Cartesian force with the plant's own Jacobian.
- ``arm7``: ``config/urdf/arm7.urdf`` with gearbox friction and a table below the tool, as a
  Franka-like ros2_control arm.
"""

from __future__ import annotations

from dataclasses import asdict
from typing import Any

import numpy as np

from haptic_dob.core.environment import VirtualWall
from haptic_dob.core.models.phantom import PhantomModel
from haptic_dob.core.models.urdf import UrdfModel
from haptic_sim.arm.device import SimulatedArm
from haptic_sim.arm.params import ArmDeviceParams
from haptic_sim.device.sample import DeviceSample
from haptic_sim.hand import HandParams
from haptic_sim.slide.device import SimulatedSlide, SlideDeviceParams
from support.paths import ROOT

AXES = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))

#: the Force Dimension-like device's true physics per axis (mass kg, viscous N s/m, Coulomb N)
FD_AXES = ((0.22, 1.6, 0.12), (0.21, 1.4, 0.10), (0.20, 1.8, 0.14))
FD_MAX_FORCE_N = 12.0  # the Force Dimension SDK's cap
TOUCH_MAX_FORCE_N = 3.3  # the Touch's nominal maximum force (OpenHaptics clamps at it)
ARM_VISCOUS = (0.6, 0.6, 0.4, 0.4, 0.2, 0.1, 0.02)  # N m s/rad, the gearboxes (teleop_sim's)
ARM_COULOMB = (1.0, 1.0, 0.6, 0.6, 0.3, 0.15, 0.02)  # N m
ARM_HOME = (0.0, 0.5, 0.0, -1.5, 0.0, 1.0, 0.0)  # rad: the tool down, 0.40 m up


class CartesianSlides:
    """Three slides along x, y and z as one 3-joint plant (``SimulatedDevice``)."""

    dof = 3

    def __init__(self, slides: list[SimulatedSlide]) -> None:
        self.slides = slides
        self.period_ns = slides[0].period_ns
        self.max_effort = tuple(s.max_effort[0] for s in slides)
        self.model = None  # no joint-space model: the truth is the slides'

    @property
    def k(self) -> int:
        return self.slides[0].k

    def sample(self) -> DeviceSample:
        parts = [s.sample() for s in self.slides]
        q = tuple(p.q[0] for p in parts)
        qd = tuple(p.qd[0] for p in parts)
        hand = np.sum([p.hand_force for p in parts], axis=0)
        return DeviceSample(
            parts[0].k,
            parts[0].stamp_ns,
            q,
            qd,
            tuple(p.effort[0] for p in parts),
            q,
            qd,
            (0.0, 0.0, 0.0),
            (float(hand[0]), float(hand[1]), float(hand[2])),
        )

    def apply(self, effort: list[float] | tuple[float, ...]) -> None:
        for s, e in zip(self.slides, effort, strict=True):
            s.apply([e])

    def prepare(self) -> None:
        for s in self.slides:
            s.prepare()

    def truth(self) -> dict[str, Any]:
        return {"axes": [asdict(s.device) for s in self.slides]}


class Arm:
    """A ``SimulatedArm`` with its truth (``SimulatedDevice``)."""

    def __init__(self, arm: SimulatedArm, truth: dict[str, Any]) -> None:
        self.arm = arm
        self.dof = arm.dof
        self.period_ns = arm.period_ns
        self.max_effort = arm.max_effort
        self.model = arm.model
        self._truth = truth

    @property
    def k(self) -> int:
        return self.arm.k

    def sample(self) -> DeviceSample:
        return self.arm.sample()

    def apply(self, effort: list[float] | tuple[float, ...]) -> None:
        self.arm.apply(effort)

    def prepare(self) -> None:
        self.arm.prepare()

    def gravity(self) -> tuple[float, ...]:
        """The joint torques that hold the arm against gravity now (N m), as a Franka's own
        compensation computes them."""
        return tuple(self.model._gravity(self.arm.q).tolist())

    def truth(self) -> dict[str, Any]:
        return self._truth


def cartesian_slides(
    rate_hz: float, seed: int, hand: dict[str, Any], hand_axis: int
) -> CartesianSlides:
    """The Force Dimension-like plant: the hand (``HandParams`` fields) on axis ``hand_axis``."""
    slides = []
    for i, ((m, c, fc), axis) in enumerate(zip(FD_AXES, AXES, strict=True)):
        params = SlideDeviceParams(
            max_force_n=FD_MAX_FORCE_N, mass_kg=m, viscous_n_s_per_m=c, coulomb_n=fc
        )
        h = HandParams(**hand) if i == hand_axis else HandParams(behaviour="none")
        slides.append(
            SimulatedSlide(params, hand=h, rate_hz=rate_hz, substeps=2, seed=seed + i, axis=axis)
        )
    return CartesianSlides(slides)


def phantom(rate_hz: float, seed: int, hand: dict[str, Any], direction: tuple[float, ...]) -> Arm:
    """The Touch-like plant: the PHANToM 1.5 with joint friction, no gravity (counterweighted),
    the hand pushing along ``direction``."""
    viscous = 0.002  # N m s/rad
    model = PhantomModel("appendix_b", gravity=False, viscous=viscous)
    device = ArmDeviceParams(
        max_force_n=TOUCH_MAX_FORCE_N,
        encoder_resolution_rad=1.5e-4,
        hand_direction=tuple(direction),  # type: ignore[arg-type]  # three floats
    )
    arm = SimulatedArm(
        model, device, hand=HandParams(**hand), rate_hz=rate_hz, substeps=2, seed=seed
    )
    return Arm(arm, {"model": "phantom appendix_b", "viscous_n_m_s_per_rad": viscous})


def arm7(rate_hz: float, seed: int, table_z: float) -> Arm:
    """The Franka-like plant: arm7 with gearbox friction, a table at ``table_z`` below the tool."""
    model = UrdfModel(
        ROOT / "config" / "urdf" / "arm7.urdf", "tool", viscous=ARM_VISCOUS, coulomb=ARM_COULOMB
    )
    device = ArmDeviceParams(
        initial_position=ARM_HOME, encoder_resolution_rad=1e-6, velocity="exact"
    )
    table = VirtualWall(
        stiffness_n_per_m=3000.0,
        damping_n_s_per_m=10.0,
        position=(0.0, 0.0, table_z),
        normal=(0.0, 0.0, -1.0),
    )
    arm = SimulatedArm(
        model,
        device,
        hand=HandParams(behaviour="none"),
        rate_hz=rate_hz,
        substeps=2,
        seed=seed,
        contact=table,
    )
    truth = {"viscous_n_m_s_per_rad": ARM_VISCOUS, "coulomb_n_m": ARM_COULOMB, "table_z": table_z}
    return Arm(arm, truth)
