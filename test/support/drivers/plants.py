"""The simulated plants under the test drivers, with the truth a test knows and the loop does not.

A plant has the simulated device's cycle contract (``haptic_sim.device.sample.SimulatedDevice``:
``sample()`` is sample k, ``apply(effort)`` holds an effort over [k, k+1)) plus ``truth()``.

- ``point_mass``: ``config/point_mass_sim.yaml``'s Cartesian device (stiction, amplifier lag,
  encoder counts) as a Force Dimension: joints ``fd_x, fd_y, fd_z`` in metres.
- ``touch``: ``config/phantom_omni_sim.yaml``'s simulated Touch (a payload, joint friction and
  encoder counts ``phantom_omni.urdf`` lacks): joints ``waist, shoulder, elbow``.
- ``arm7``: ``config/urdf/arm7.urdf`` with gearbox friction and a table below the tool, as a
  Franka-like ros2_control arm.

A test changes a plant's truth only through those configs (and the hand, seed, rate, sub-steps)."""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path
from typing import Any

from haptic_dob.core.environment import VirtualWall
from haptic_dob.core.models.urdf import UrdfModel
from haptic_sim.arm.device import SimulatedArm
from haptic_sim.arm.params import ArmDeviceParams
from haptic_sim.device.batch import load_session
from haptic_sim.device.factory import SimulatedDeviceKind, build_device
from haptic_sim.device.sample import DeviceSample
from haptic_sim.hand import HandParams
from haptic_sim.point_mass.device import SimulatedPointMass
from support.paths import ROOT

#: the simulated devices' configs: their device_node section is the plant's truth
POINT_MASS_SIM = ROOT / "config" / "point_mass_sim.yaml"
TOUCH_SIM = ROOT / "config" / "phantom_omni_sim.yaml"
TOUCH_MAX_FORCE_N = 3.3  # the Touch's nominal maximum force (OpenHaptics clamps at it)
TOUCH_SUBSTEPS = 2  # RK4 steps per driver period at 500 Hz (1 ms): a Python driver's budget
ARM_VISCOUS = (0.6, 0.6, 0.4, 0.4, 0.2, 0.1, 0.02)  # N m s/rad, the gearboxes (teleop_sim's)
ARM_COULOMB = (1.0, 1.0, 0.6, 0.6, 0.3, 0.15, 0.02)  # N m
ARM_HOME = (0.0, 0.5, 0.0, -1.5, 0.0, 1.0, 0.0)  # rad: the tool down, 0.40 m up


class Plant:
    """A simulated device with its truth (``SimulatedDevice``)."""

    def __init__(self, device: SimulatedDeviceKind, truth: dict[str, Any]) -> None:
        self.device = device
        self.dof = device.dof
        self.period_ns = device.period_ns
        self.max_effort = device.max_effort
        self.model = device.model
        self._truth = truth

    @property
    def k(self) -> int:
        return self.device.k

    def sample(self) -> DeviceSample:
        return self.device.sample()

    def apply(self, effort: list[float] | tuple[float, ...]) -> None:
        self.device.apply(effort)

    def prepare(self) -> None:
        self.device.prepare()

    def gravity(self) -> tuple[float, ...]:
        """The joint torques that hold the arm against gravity now (N m), as a Franka's own
        compensation computes them."""
        assert isinstance(self.device, SimulatedArm)
        return tuple(self.model._gravity(self.device.q).tolist())

    def truth(self) -> dict[str, Any]:
        return self._truth


def simulated(config: Path, **values: Any) -> SimulatedDeviceKind:
    """The device ``config``'s device node simulates (its ``/**`` and ``device_node``
    sections), with ``values`` (flat parameter names) laid over them."""
    nodes = load_session(config)
    return build_device({**nodes["/**"], **nodes["device_node"], **values})


def hand_values(hand: dict[str, Any]) -> dict[str, Any]:
    """``HandParams`` fields as the device node's ``hand.*`` parameters."""
    return {f"hand.{k}": v for k, v in asdict(HandParams(**hand)).items()}


def point_mass(
    rate_hz: float, seed: int, hand: dict[str, Any], direction: tuple[float, ...]
) -> Plant:
    """The Force Dimension-like plant: the hand (``HandParams`` fields) pushing along
    ``direction``."""
    device = simulated(
        POINT_MASS_SIM,
        rate_hz=rate_hz,
        seed=seed,
        **{"cartesian.hand_direction": list(direction)},
        **hand_values(hand),
    )
    assert isinstance(device, SimulatedPointMass)
    return Plant(device, {"cartesian": asdict(device.device), "config": POINT_MASS_SIM.name})


def touch(
    rate_hz: float,
    seed: int,
    hand: dict[str, Any],
    direction: tuple[float, ...],
    encoder_resolution_rad: float | None = None,
) -> Plant:
    """The Touch-like plant: the hand pushing along ``direction``; its truth the URDF's rigid
    body plus the config's payload and joint friction (the Coulomb friction turning over the
    speeds ``coulomb_speed_rad_per_s``, the simulator's smoothing at this physics step), its
    encoders' counts the config's unless ``encoder_resolution_rad`` is given."""
    encoder = (
        {}
        if encoder_resolution_rad is None
        else {"arm.encoder_resolution_rad": encoder_resolution_rad}
    )
    device = simulated(
        TOUCH_SIM,
        rate_hz=rate_hz,
        seed=seed,
        substeps=TOUCH_SUBSTEPS,
        **{"arm.hand_direction": list(direction)},
        **encoder,
        **hand_values(hand),
    )
    assert isinstance(device, SimulatedArm) and isinstance(device.model, UrdfModel)
    m = device.model
    truth = {
        "config": TOUCH_SIM.name,
        "payload_kg": m.payload_kg,
        "viscous_n_m_s_per_rad": m.viscous.tolist(),
        "coulomb_n_m": m.coulomb.tolist(),
        "coulomb_speed_rad_per_s": device.coulomb_speeds,
        "encoder_resolution_rad": device.device.encoder_resolution_rad,
        "effort_limits_n_m": list(device.max_effort),
    }
    return Plant(device, truth)


def arm7(rate_hz: float, seed: int, table_z: float) -> Plant:
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
    return Plant(arm, truth)
