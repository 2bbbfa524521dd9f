"""Build a simulated device from parameters: the device node and batch runs share it.

``model: slide`` builds the ``SimulatedSlide`` (its physics ``plant.``, its axis ``slide.axis``; the
model an observer assumes, ``slide.*``, is not the plant's truth); ``model: point_mass`` the
``SimulatedPointMass`` (its physics ``cartesian.``, its joint names ``point_mass.joint_names``;
the rest of ``point_mass.*`` is the model the others assume); ``model: phantom``
or ``urdf`` a ``SimulatedArm`` of the model ``build_model`` names (groups ``phantom.`` or the URDF
parameters, and ``arm.``), touching the wall ``contact.*`` when its stiffness is > 0 (a
teleoperation slave's remote environment, ``haptic_sim.arm.contact``). ``sensor.`` and ``hand.``
serve both.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from haptic_dob.core.environment import VirtualWall
from haptic_dob.core.models.factory import build_model
from haptic_dob.core.models.point_mass import PointMassParams
from haptic_dob.core.models.slide import SlideParams
from haptic_dob.runtime.params import ParamSpec, build, specs_of
from haptic_sim.arm.device import ArmDeviceParams, SimulatedArm
from haptic_sim.hand import HandParams
from haptic_sim.point_mass.device import PointMassDeviceParams, SimulatedPointMass
from haptic_sim.sensor import ForceSensorParams
from haptic_sim.slide.device import SimulatedSlide
from haptic_sim.slide.plant import SlideDeviceParams
from haptic_sim.slide.session import LoopSettings

#: an arm touches nothing unless ``contact.stiffness_n_per_m`` says so
NO_WALL = {"stiffness_n_per_m": 0.0}
NO_CONTACT = {f"contact.{name}": value for name, value in NO_WALL.items()}


def contact_specs() -> list[ParamSpec]:
    """``contact.*``: the wall an arm touches (one-sided; zero stiffness: none)."""
    specs = specs_of(
        VirtualWall,
        "contact.",
        read_only=True,
        defaults=NO_WALL,
        about="arm contact (K = 0: none)",
    )
    return [s for s in specs if s.name != "contact.two_sided"]


def simulation_specs() -> list[ParamSpec]:
    """Sub-steps, seed, length, plant, sensor and hand (read-only: they define the run)."""
    return [
        *(s for s in specs_of(LoopSettings, read_only=True) if s.name != "rate_hz"),
        *specs_of(SlideDeviceParams, "plant.", read_only=True),
        *specs_of(PointMassDeviceParams, "cartesian.", read_only=True),
        *specs_of(ArmDeviceParams, "arm.", read_only=True),
        *contact_specs(),
        *specs_of(ForceSensorParams, "sensor.", read_only=True),
        *specs_of(HandParams, "hand.", read_only=True),
    ]


#: what the device node simulates
SimulatedDeviceKind = SimulatedSlide | SimulatedPointMass | SimulatedArm


def build_device(values: Mapping[str, Any]) -> SimulatedDeviceKind:
    """The simulated device the parameters describe (``model``: slide, point_mass, phantom or
    urdf)."""
    kind = values.get("model", "slide")
    loop = build(LoopSettings, values)
    if kind == "slide":
        return SimulatedSlide(
            build(SlideDeviceParams, values, "plant."),
            build(ForceSensorParams, values, "sensor."),
            build(HandParams, values, "hand."),
            *loop.device_args(),
            axis=build(SlideParams, values, "slide.").axis,
        )
    if kind == "point_mass":
        return SimulatedPointMass(
            build(PointMassDeviceParams, values, "cartesian."),
            build(ForceSensorParams, values, "sensor."),
            build(HandParams, values, "hand."),
            *loop.device_args(),
            joint_names=build(PointMassParams, values, "point_mass.").joint_names,
        )
    if kind in ("phantom", "urdf"):
        return SimulatedArm(
            build_model(values),
            build(ArmDeviceParams, values, "arm."),
            build(ForceSensorParams, values, "sensor."),
            build(HandParams, values, "hand."),
            *loop.device_args(),
            contact=build(VirtualWall, {**NO_CONTACT, **values}, "contact."),
        )
    raise ValueError(
        f"device_node simulates model slide, point_mass, phantom or urdf, got {kind!r}"
    )
