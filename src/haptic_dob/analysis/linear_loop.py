"""The slide's loop in contact as a linear discrete-time system: stability without simulation.

Plant ``m x'' + b x' = F_a + F_h``, discretised exactly with a zero-order hold at period T;
``F_a`` is the command ``u``, or with an amplifier lag ``tau_a`` its lag ``tau_a F_a' = u - F_a``;
the hand ``F_h = F_push - k_h x`` (the constant push drops out); the wall ``F_w = -K x`` on the
encoder sample. DOB: the observer as ``DisturbanceObserver`` updates, with the plant's m and b;
CL: an ideal sensor reading ``F_h`` at the sample. The state is
``[x, v, (F_a,) x_prev, v_prev_sample, z_prev, u_prev]``; the loop is stable when every
eigenvalue of the one-period map (``loop_map``) lies inside the unit circle.

The DOB loop has a real mode near ``-Kf c T / (2 m)``, the command alternating its sign every
period; ``chatter_gain`` is the observer gain at which it leaves the unit circle (about
``2 m / (Kf T)``; a lag lowers it). Why: docs/design/stability.md.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.signal import cont2discrete

from haptic_dob.core.validation import nonnegative, positive

MODES = ("OL", "CL", "DOB")
#: how far above 1 a spectral radius must be to count as unstable (rounding of a unit eigenvalue)
MARGINAL = 1e-9


def _plant(m: float, b: float, k_h: float, T: float, lag: float) -> tuple[np.ndarray, np.ndarray]:
    """The plant's exact zero-order-hold map: ``[x, v]``, or ``[x, v, F_a]`` with a lag."""
    if lag > 0.0:
        A = np.array([[0.0, 1.0, 0.0], [-k_h / m, -b / m, 1.0 / m], [0.0, 0.0, -1.0 / lag]])
        B = np.array([[0.0], [0.0], [1.0 / lag]])
    else:
        A = np.array([[0.0, 1.0], [-k_h / m, -b / m]])
        B = np.array([[0.0], [1.0 / m]])
    n = A.shape[0]
    Ad, Bd, *_ = cont2discrete((A, B, np.eye(n), np.zeros((n, 1))), T, "zoh")
    return Ad, Bd[:, 0]


def loop_map(
    stiffness: float,
    kf: float,
    mode: str,
    gain: float,
    m: float,
    b: float,
    T: float,
    hand_stiffness: float = 0.0,
    amplifier_lag_s: float = 0.0,
) -> np.ndarray:
    """The one-period state map (6 x 6, or 7 x 7 with an amplifier lag) of the loop in contact."""
    K = nonnegative("stiffness", stiffness)
    k_h = nonnegative("hand_stiffness", hand_stiffness)
    lag = nonnegative("amplifier_lag_s", amplifier_lag_s)
    if mode not in MODES:
        raise ValueError(f"mode must be one of {', '.join(MODES)}, got {mode!r}")
    m, T, c = positive("m", m), positive("T", T), positive("gain", gain)
    Ad, Bd = _plant(m, b, k_h, T, lag)
    n_p = Ad.shape[0]
    alpha = math.exp(-c * T / m)
    cd = m * math.expm1(c * T / m) / T  # the observer's pole-matched discrete gain
    e = np.eye(n_p + 4)
    plant, (x_prev, qd_prev, z_prev, u_prev) = e[:n_p], e[n_p:]
    q = plant[0]  # the encoder sample of x (quantization left out)
    qd = (q - x_prev) / T
    z = alpha * z_prev + (1.0 - alpha) * (b * qd_prev - u_prev - cd * qd)
    d_hat = z + cd * qd
    f_wall = -K * q
    if mode == "OL":
        u = f_wall
    elif mode == "CL":  # an ideal sensor of the hand force at the sample
        u = f_wall + kf * (f_wall - k_h * q)
    else:
        u = f_wall + kf * (f_wall + d_hat)
    M = np.empty((n_p + 4, n_p + 4))
    M[:n_p] = Ad @ plant + np.outer(Bd, u)
    M[n_p], M[n_p + 1], M[n_p + 2], M[n_p + 3] = q, qd, z, u
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
    amplifier_lag_s: float = 0.0,
) -> float:
    """Largest eigenvalue magnitude of the loop map (> 1: unstable)."""
    M = loop_map(stiffness, kf, mode, gain, m, b, T, hand_stiffness, amplifier_lag_s)
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
    amplifier_lag_s: float = 0.0,
) -> float | None:
    """Smallest stiffness (N/m) at which the linear loop is unstable; 0 if it is at any; None if
    stable up to ``k_max``. Found by bisection on the spectral radius (1 N/m resolution); a
    radius within ``MARGINAL`` of 1 is marginal, not unstable (a free mass, K = 0 without a grip,
    has an eigenvalue of exactly 1, which rounding puts on either side)."""

    def unstable(k: float) -> bool:
        radius = spectral_radius(k, kf, mode, gain, m, b, T, hand_stiffness, amplifier_lag_s)
        return radius > 1.0 + MARGINAL

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


def sample_rate_mode(
    stiffness: float,
    kf: float,
    gain: float,
    m: float,
    b: float,
    T: float,
    hand_stiffness: float = 0.0,
    amplifier_lag_s: float = 0.0,
) -> float:
    """Magnitude of the DOB loop's negative real eigenvalue (the command alternating its sign
    every period; > 1: it chatters at the sample rate), 0 if there is none."""
    M = loop_map(stiffness, kf, "DOB", gain, m, b, T, hand_stiffness, amplifier_lag_s)
    ev = np.linalg.eigvals(M)
    real_negative = [abs(e.real) for e in ev if e.real < 0.0 and abs(e.imag) < 1e-9]
    return max(real_negative, default=0.0)


def chatter_gain(
    kf: float,
    m: float,
    b: float,
    T: float,
    stiffness: float = 800.0,
    hand_stiffness: float = 0.0,
    amplifier_lag_s: float = 0.0,
) -> float | None:
    """The observer gain c (N s/m) above which DOB at ``kf`` chatters at the sample rate (its
    sample-rate mode outside the unit circle), by bisection to 1e-4 relative; None if it does
    not below ``50 m / T`` (the observer's pole ``exp(-c T / m)`` then 2e-22: settled within a
    period). About ``2 m / (Kf T)`` without an amplifier lag."""
    positive("kf", kf)
    c_max = 50.0 * positive("m", m) / positive("T", T)

    def chatters(c: float) -> bool:
        mode = sample_rate_mode(stiffness, kf, c, m, b, T, hand_stiffness, amplifier_lag_s)
        return mode > 1.0

    lo, hi = 0.0, 2.0 * m / (kf * T)
    while not chatters(hi):
        if hi >= c_max:
            return None
        lo, hi = hi, min(hi * 2.0, c_max)
    while hi - lo > 1e-4 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if chatters(mid) else (mid, hi)
    return hi
