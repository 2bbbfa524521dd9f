"""Analysis of haptic sessions from arrays: transparency, vibration, oscillation and energy."""

from haptic_dob.analysis.energy import EnergyResult, passivity_observer
from haptic_dob.analysis.figures import Figures, analyze_arrays
from haptic_dob.analysis.oscillation import Oscillation, OscillationSettings, oscillation
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
    "Figures",
    "Growth",
    "Oscillation",
    "OscillationSettings",
    "PerturbationResponse",
    "TransparencyResult",
    "analyze_arrays",
    "band_edge",
    "envelope_growth",
    "h1_impedance",
    "mass_damper_band_edge_hz",
    "oscillation",
    "passivity_observer",
    "perturbation_response",
    "transparency",
]
