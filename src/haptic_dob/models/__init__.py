"""Device models: one interface (``DeviceModel``) for the slide, the PHANToM and URDF arms."""

from haptic_dob.models.base import DeviceModel
from haptic_dob.models.slide import SlideModel, SlideParams

__all__ = ["DeviceModel", "SlideModel", "SlideParams"]
