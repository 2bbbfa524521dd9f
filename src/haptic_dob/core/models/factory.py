"""Build the device model a node or a batch run names by parameters (``model`` + its group).

- ``slide``: ``slide.*`` (``SlideParams``).
- ``point_mass``: ``point_mass.*`` (``PointMassParams``): a Cartesian point mass per axis (Force
  Dimension devices).
- ``phantom``: ``phantom.params`` (``appendix_b`` | ``cavusoglu``), ``phantom.gravity``,
  ``phantom.viscous_n_m_s_per_rad`` (``PhantomSettings``).
- ``urdf``: ``robot_description`` (URDF text, the ROS convention) or ``urdf_path``, ``tip_frame``,
  ``joint_names``, plus ``urdf.gravity``, ``urdf.viscous_n_m_s_per_rad``, ``urdf.coulomb_n_m``,
  ``urdf.coulomb_speed_rad_per_s`` and ``urdf.armature_kg_m2``.

All of them are structural, so read-only.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from haptic_dob.core.models.base import DeviceModel
from haptic_dob.core.models.phantom import PhantomSettings
from haptic_dob.core.models.point_mass import PointMassParams
from haptic_dob.core.models.slide import SlideParams
from haptic_dob.core.models.urdf import UrdfOptions, UrdfSettings
from haptic_dob.runtime.params import ParamSpec, build, param, specs_of

MODEL_KINDS = ("slide", "point_mass", "phantom", "urdf")


@dataclass(frozen=True)
class ModelChoice:
    """Which device model (``model``); its group holds its settings."""

    model: str = field(
        default="slide",
        metadata=param(description="device model", choices=MODEL_KINDS, read_only=True),
    )


def model_specs() -> list[ParamSpec]:
    """The structural (read-only) parameters that choose and define the device model."""
    return [
        *specs_of(ModelChoice),
        *specs_of(SlideParams, "slide.", read_only=True),
        *specs_of(PointMassParams, "point_mass.", read_only=True),
        *specs_of(PhantomSettings, "phantom.", read_only=True),
        *specs_of(UrdfSettings, "", read_only=True),
        *specs_of(UrdfOptions, "urdf.", read_only=True),
    ]


def build_model(values: Mapping[str, Any]) -> DeviceModel:
    """The model named by ``values['model']`` with its group's settings.

    Raises ``ValueError`` with one clear message when the settings are missing or invalid.
    """
    kind = values.get("model", "slide")
    if kind == "slide":
        return build(SlideParams, values, "slide.").model()
    if kind == "point_mass":
        return build(PointMassParams, values, "point_mass.").model()
    if kind == "phantom":
        return build(PhantomSettings, values, "phantom.").model()
    if kind == "urdf":
        return build(UrdfSettings, values).model(build(UrdfOptions, values, "urdf."))
    raise ValueError(f"model must be one of {', '.join(MODEL_KINDS)}, got {kind!r}")
