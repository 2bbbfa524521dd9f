"""Energy exchanged between device and hand: a passivity observer (Hannaford & Ryu 2002).

``E(n) = T * sum_{k<=n} F_h(k) v(k)`` is the energy the hand has put into the device through the
handle port (``F_h`` the hand's force on the device, ``v`` the handle velocity along it). A
passive device keeps ``E(n) >= -E(0)``; where ``E`` falls below zero the device has delivered net
energy to the hand. The largest such excursion ``max(0, -min E)`` measures how active the
rendering was; ``delivered`` is the running energy the device gave the hand, ``-E``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from haptic_dob.core.validation import positive


@dataclass(frozen=True)
class EnergyResult:
    """Passivity-observer summary of one record (joules)."""

    energy_in_j: np.ndarray  # E(n), energy into the device from the hand
    final_j: float  # E at the end
    max_active_j: float  # largest net energy delivered to the hand, max(0, -min E)
    t_max_active_s: float  # time of that excursion


def passivity_observer(force_n: ArrayLike, velocity_m_s: ArrayLike, dt: float) -> EnergyResult:
    """Passivity observer of the hand port from force (N) and velocity (m/s) at period dt (s)."""
    T = positive("dt", dt)
    f = np.asarray(force_n, dtype=np.float64).reshape(-1)
    v = np.asarray(velocity_m_s, dtype=np.float64).reshape(-1)
    if f.shape != v.shape:
        raise ValueError(f"force and velocity must have the same length, got {f.size} and {v.size}")
    if f.size == 0:
        raise ValueError("force and velocity must not be empty")
    if not (np.all(np.isfinite(f)) and np.all(np.isfinite(v))):
        raise ValueError("force and velocity must be finite")
    e = np.cumsum(f * v) * T
    i = int(np.argmin(e))
    active = max(0.0, -float(e[i]))
    return EnergyResult(e, float(e[-1]), active, i * T if active > 0.0 else 0.0)
