"""Test data for the bag analysis: analytic mass-spring-damper records and session parameters."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy.optimize import brentq

BAND_LOW = 10 ** (-3.0 / 20.0)  # |T| at the lower -3 dB edge


def msd_record(
    duration_s: float,
    fs_hz: float,
    mass_kg: float,
    damping_n_s_per_m: float,
    stiffness_n_per_m: float,
    seed: int = 0,
    offset_m: float = 2e-3,
    std_m: float = 1e-3,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(x, F, v) of a device whose hand force is exactly ``m x'' + b x' + K (x - 0)``.

    x is ``offset_m`` (inside a wall at 0) plus a multisine: every 0.05 Hz from 0.05 to 20 Hz with
    random phases and a gently falling amplitude, scaled to ``std_m``; F and v are its exact
    derivatives combined, so the impedance is ``K - m w^2 + j b w`` at every excited frequency.
    """
    rng = np.random.default_rng(seed)
    t = np.arange(round(duration_s * fs_hz)) / fs_hz
    f = np.arange(1, 401) * 0.05
    w = 2.0 * np.pi * f
    amp = 1.0 / (1.0 + (f / 5.0) ** 2)
    phase = rng.uniform(0.0, 2.0 * np.pi, f.size)
    arg = np.outer(w, t) + phase[:, None]
    s, c = np.sin(arg), np.cos(arg)
    x = amp @ s
    v = (amp * w) @ c
    a = -(amp * w * w) @ s
    scale = std_m / float(np.std(x))
    x, v, a = x * scale, v * scale, a * scale
    x = x + offset_m
    force = mass_kg * a + damping_n_s_per_m * v + stiffness_n_per_m * x
    return x, force, v


def msd_band_edge_hz(mass_kg: float, damping_n_s_per_m: float, stiffness_n_per_m: float) -> float:
    """First frequency where ``|K - m w^2 + j b w| / K`` leaves the +-3 dB band (Hz)."""

    def excess(f: float) -> float:
        w = 2.0 * math.pi * f
        mag = abs(complex(stiffness_n_per_m - mass_kg * w * w, damping_n_s_per_m * w))
        return mag / stiffness_n_per_m - BAND_LOW

    return brentq(excess, 1e-3, math.sqrt(stiffness_n_per_m / mass_kg) / (2.0 * math.pi))


def session_params(
    mode: str = "OL", kf: float = 0.0, stiffness: float = 800.0
) -> dict[str, dict[str, Any]]:
    """The relevant parameters of the loop's nodes, as the recorder's snapshot holds them."""
    return {
        "controller_node": {"mode": mode, "kf": kf, "max_force_n": 4.0},
        "environment_node": {
            "stiffness_n_per_m": stiffness,
            "damping_n_s_per_m": 0.0,
            "position": [0.0, 0.0, 0.0],
            "normal": [1.0, 0.0, 0.0],
        },
        "observer_node": {"gain": 41.6, "output_limit": 4.0},
    }
