"""Device models: one interface (``DeviceModel``) for the slide, the point mass, the PHANToM and
URDF arms."""

from haptic_dob.core.models.base import DeviceModel
from haptic_dob.core.models.phantom import PhantomModel, PhantomParams, PhantomSettings
from haptic_dob.core.models.point_mass import PointMassModel, PointMassParams
from haptic_dob.core.models.slide import SlideModel, SlideParams
from haptic_dob.core.models.urdf import UrdfModel, UrdfOptions, UrdfSettings

__all__ = [
    "DeviceModel",
    "PhantomModel",
    "PhantomParams",
    "PhantomSettings",
    "PointMassModel",
    "PointMassParams",
    "SlideModel",
    "SlideParams",
    "UrdfModel",
    "UrdfOptions",
    "UrdfSettings",
]
