"""Analysis of haptic sessions from arrays: transparency, vibration and energy."""

from haptic_dob.analysis.energy import EnergyResult, passivity_observer
from haptic_dob.analysis.transparency import (
    TransparencyResult,
    band_edge,
    h1_impedance,
    mass_damper_band_edge_hz,
    transparency,
)
from haptic_dob.analysis.vibration import Growth, envelope_growth

__all__ = [
    "EnergyResult",
    "Growth",
    "TransparencyResult",
    "band_edge",
    "envelope_growth",
    "h1_impedance",
    "mass_damper_band_edge_hz",
    "passivity_observer",
    "transparency",
]
