"""Device models: one interface (``DeviceModel``) for the slide, the PHANToM and URDF arms."""

from haptic_dob.models.base import DeviceModel
from haptic_dob.models.phantom import PhantomModel, PhantomParams, PhantomSettings
from haptic_dob.models.slide import SlideModel, SlideParams
from haptic_dob.models.urdf import UrdfModel, UrdfOptions, UrdfSettings

__all__ = [
    "DeviceModel",
    "PhantomModel",
    "PhantomParams",
    "PhantomSettings",
    "SlideModel",
    "SlideParams",
    "UrdfModel",
    "UrdfOptions",
    "UrdfSettings",
]
