"""The slide's loop in contact as a linear discrete-time system: stability without simulation.

Plant ``m x'' + b x' = u + F_h`` discretised exactly with a zero-order hold at period T; the hand
``F_h = F_push - k_h x`` (a push through a grip spring ``k_h``, as in the onset protocol; the
constant push drops out of the perturbation dynamics); the wall ``F_w = -K x`` on the encoder
sample; the observer exactly as ``DisturbanceObserver`` updates (pole-matched implicit update,
backward-difference velocity, the effort applied over the last period) with the plant's m and b,
so it estimates the hand force; CL with an ideal sensor reading ``F_h`` at the sample. The state
is ``[x, v, x_prev, v_prev_sample, z_prev, u_prev]``; the loop is stable when every eigenvalue of
the one-period map lies inside the unit circle.

It explains what the thesis could not: the discrete observer answers sample k with the effort
applied over [k-1, k) and a backward-difference velocity, so its estimate carries a piece of the
command's own change, and with force feedback ``Kf`` that piece feeds the command back. The DOB
loop is therefore *less* stable than CL with an ideal sensor (whose onset is the bound
``2 b / (T (1 + Kf))``), increasingly so for a faster observer.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.signal import cont2discrete

from haptic_dob.validation import nonnegative, positive

MODES = ("OL", "CL", "DOB")


def loop_map(
    stiffness: float,
    kf: float,
    mode: str,
    gain: float,
    m: float,
    b: float,
    T: float,
    hand_stiffness: float = 0.0,
) -> np.ndarray:
    """The one-period state map (6 x 6) of the loop in contact."""
    K = nonnegative("stiffness", stiffness)
    k_h = nonnegative("hand_stiffness", hand_stiffness)
    if mode not in MODES:
        raise ValueError(f"mode must be one of {', '.join(MODES)}, got {mode!r}")
    m, T, c = positive("m", m), positive("T", T), positive("gain", gain)
    A = np.array([[0.0, 1.0], [-k_h / m, -b / m]])
    B = np.array([[0.0], [1.0 / m]])
    Ad, Bd, *_ = cont2discrete((A, B, np.eye(2), np.zeros((2, 1))), T, "zoh")
    alpha = math.exp(-c * T / m)
    cd = m * math.expm1(c * T / m) / T  # the observer's pole-matched discrete gain
    e = np.eye(6)
    x, v, x_prev, qd_prev, z_prev, u_prev = e
    q = x  # the encoder sample (quantization left out)
    qd = (x - x_prev) / T
    z = alpha * z_prev + (1.0 - alpha) * (b * qd_prev - u_prev - cd * qd)
    d_hat = z + cd * qd
    f_wall = -K * q
    if mode == "OL":
        u = f_wall
    elif mode == "CL":  # an ideal sensor of the hand force at the sample
        u = f_wall + kf * (f_wall - k_h * q)
    else:
        u = f_wall + kf * (f_wall + d_hat)
    M = np.empty((6, 6))
    M[0] = Ad[0, 0] * x + Ad[0, 1] * v + Bd[0, 0] * u
    M[1] = Ad[1, 0] * x + Ad[1, 1] * v + Bd[1, 0] * u
    M[2], M[3], M[4], M[5] = q, qd, z, u
    return M


def spectral_radius(
    stiffness: float,
    kf: float,
    mode: str,
    gain: float,
    m: float,
    b: float,
    T: float,
    hand_stiffness: float = 0.0,
) -> float:
    """Largest eigenvalue magnitude of the loop map (> 1: unstable)."""
    M = loop_map(stiffness, kf, mode, gain, m, b, T, hand_stiffness)
    return float(np.max(np.abs(np.linalg.eigvals(M))))


def linear_onset(
    kf: float,
    mode: str,
    gain: float = 41.6,
    m: float = 0.416,
    b: float = 1.272,
    T: float = 1e-3,
    hand_stiffness: float = 0.0,
    k_max: float = 1e5,
) -> float | None:
    """Smallest stiffness (N/m) at which the linear loop is unstable; 0 if it is at any; None if
    stable up to ``k_max``. Found by bisection on the spectral radius (1 N/m resolution)."""

    def unstable(k: float) -> bool:
        return spectral_radius(k, kf, mode, gain, m, b, T, hand_stiffness) > 1.0

    lo, hi = 0.0, 1.0
    if unstable(0.0):
        return 0.0
    while not unstable(hi):
        lo, hi = hi, hi * 2.0
        if hi > k_max:
            return None
    while hi - lo > 1.0:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if unstable(mid) else (mid, hi)
    return hi
