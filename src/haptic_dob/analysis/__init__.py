"""Analysis of haptic sessions from arrays: transparency, vibration and energy."""

from haptic_dob.analysis.energy import EnergyResult, passivity_observer
from haptic_dob.analysis.transparency import (
    TransparencyResult,
    band_edge,
    h1_impedance,
    mass_damper_band_edge_hz,
    transparency,
)
from haptic_dob.analysis.vibration import (
    Growth,
    PerturbationResponse,
    envelope_growth,
    perturbation_response,
)

__all__ = [
    "EnergyResult",
    "Growth",
    "PerturbationResponse",
    "TransparencyResult",
    "band_edge",
    "envelope_growth",
    "h1_impedance",
    "mass_damper_band_edge_hz",
    "passivity_observer",
    "perturbation_response",
    "transparency",
]
