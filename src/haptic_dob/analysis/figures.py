"""The whole analysis of one steady stretch of a session from plain arrays: ``analyze_arrays``.

Transparency (``haptic_dob.analysis.transparency``) against a wall of known stiffness and damping,
the passivity observer's energy of hand force and velocity (``passivity_observer``), the share of
samples in contact and the vibration detector (``haptic_dob.analysis.oscillation``). The bag
analysis (``haptic_dob.bag.analyze``) calls it per segment, an in-process check on arrays alike.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from haptic_dob.analysis.energy import EnergyResult, passivity_observer
from haptic_dob.analysis.oscillation import Oscillation, OscillationSettings, oscillation
from haptic_dob.analysis.transparency import DEFAULT_FMAX_HZ, TransparencyResult, transparency


@dataclass
class Figures:
    """The analysis of one stretch of samples."""

    transparency: TransparencyResult | None
    energy: EnergyResult
    in_contact_pct: float | None
    oscillation: Oscillation | None
    problem: str | None  # why there is no transparency (too short, no motion, no stiffness)


def analyze_arrays(
    x: np.ndarray,
    force: np.ndarray,
    velocity: np.ndarray,
    fs_hz: float,
    stiffness_n_per_m: float | None,
    damping_n_s_per_m: float = 0.0,
    penetration: np.ndarray | None = None,
    fmax_hz: float = DEFAULT_FMAX_HZ,
    segment_s: float | None = None,
    oscillation_settings: OscillationSettings | None = None,
) -> Figures:
    """Transparency, energy, contact and vibration of motion x (m), hand force (N), v (m/s).

    ``penetration`` (m, > 0 in the wall) gives the contact share; the record should already
    leave out what is to be left out. ``segment_s`` is the transparency's Welch segment (None: the
    record's default); the vibration detector keeps its own.
    """
    dt = 1.0 / fs_hz
    energy = passivity_observer(force, velocity, dt)
    touching = None if penetration is None else penetration > 0.0
    contact = None if touching is None else float(np.mean(touching) * 100.0)
    osc = oscillation(x, fs_hz, touching, oscillation_settings)  # its own 2 s Welch segments
    tr, problem = None, None
    if stiffness_n_per_m is None:
        problem = "no wall stiffness recorded (pass --stiffness)"
    elif stiffness_n_per_m <= 0.0:
        problem = "the wall stiffness is 0 (no wall): transparency is undefined"
    else:
        try:
            tr = transparency(
                x, force, fs_hz, stiffness_n_per_m, damping_n_s_per_m, fmax_hz, segment_s
            )
        except ValueError as exc:  # too short for the spectral settings, or no motion
            problem = str(exc)
    return Figures(tr, energy, contact, osc, problem)
