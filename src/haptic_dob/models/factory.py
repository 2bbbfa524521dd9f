"""Build the device model a node or a batch run names by parameters (``model`` + its group)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from haptic_dob.models.base import DeviceModel
from haptic_dob.models.slide import SlideParams
from haptic_msgs_py.params import ParamSpec, build, specs_of

MODEL_KINDS = ("slide",)


def model_specs() -> list[ParamSpec]:
    """The structural (read-only) parameters that choose and define the device model."""
    return [
        ParamSpec("model", "slide", "device model", choices=MODEL_KINDS, read_only=True),
        *specs_of(SlideParams, "slide.", read_only=True),
    ]


def build_model(values: Mapping[str, Any]) -> DeviceModel:
    """The model named by ``values['model']`` with its group's settings (``slide.*``)."""
    kind = values.get("model", "slide")
    if kind == "slide":
        return build(SlideParams, values, "slide.").model()
    raise ValueError(f"model must be one of {', '.join(MODEL_KINDS)}, got {kind!r}")
