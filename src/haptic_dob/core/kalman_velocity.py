"""A joint's velocity from encoder counts by a steady-state Kalman filter (no ROS).

The joint's motion is a constant-acceleration model driven by white jerk of spectral density
``psd`` (position units squared per s^5), sampled every ``period_s``; its position is read to
the nearest count, a rounding error taken as white noise of variance ``count**2 / 12`` (Belanger
1992, "Estimation of angular velocity and acceleration from shaft-encoder measurements", ICRA).
The filter's gain is the steady state of the Riccati recursion at that period, so each sample
costs a few multiply-adds (``KalmanState.update``). ``innovations`` runs the same filter over a
whole record: its one-step prediction errors, whose likelihood ``haptic_dob.identification.
velocity_noise`` maximises to identify ``psd`` from a session's positions alone.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


def transition(dt: float) -> Array:
    """The constant-acceleration model's state transition over ``dt`` (s): (q, q', q'')."""
    return np.array([[1.0, dt, 0.5 * dt * dt], [0.0, 1.0, dt], [0.0, 0.0, 1.0]])


def process_noise(psd: float, dt: float) -> Array:
    """The covariance white jerk of density ``psd`` adds over ``dt`` (s), exact integral."""
    return psd * np.array(
        [
            [dt**5 / 20.0, dt**4 / 8.0, dt**3 / 6.0],
            [dt**4 / 8.0, dt**3 / 3.0, dt**2 / 2.0],
            [dt**3 / 6.0, dt**2 / 2.0, dt],
        ]
    )


@dataclass(frozen=True)
class SteadyGain:
    """The steady-state filter: ``gain`` (on q, q', q'') and the innovation's variance (units^2)
    at ``period_s`` for a joint of count ``count`` and jerk density ``psd``."""

    gain: tuple[float, float, float]
    innovation_var: float
    period_s: float


def steady_gain(psd: float, count: float, period_s: float) -> SteadyGain:
    """The Kalman gain the recursion settles to (``ValueError`` for a value <= 0 or not
    finite)."""
    for name, v in (("psd", psd), ("count", count), ("period_s", period_s)):
        if not (math.isfinite(v) and v > 0.0):
            raise ValueError(f"{name} must be a positive number, got {v!r}")
    from scipy import linalg  # lazy: only a Kalman velocity needs it

    F = transition(period_s)
    H = np.array([[1.0, 0.0, 0.0]])
    R = np.array([[count * count / 12.0]])
    P = linalg.solve_discrete_are(F.T, H.T, process_noise(psd, period_s), R)  # prior
    s = float(P[0, 0] + R[0, 0])
    k = P[:, 0] / s
    return SteadyGain((float(k[0]), float(k[1]), float(k[2])), s, period_s)


class KalmanState:
    """One joint's filter: the state (q, q', q'') and its steady gain.

    Each ``update`` predicts over the interval since the last sample (the stamps', so a late
    sample is predicted over its own interval) and corrects with the gain of the nominal period.
    """

    def __init__(self, gain: SteadyGain, q0: float) -> None:
        self.k0, self.k1, self.k2 = gain.gain
        self.q, self.qd, self.qdd = q0, 0.0, 0.0

    def update(self, dt: float, y: float) -> float:
        """The innovation of position ``y`` read ``dt`` (s) after the last; the state moves on."""
        q = self.q + dt * (self.qd + 0.5 * dt * self.qdd)
        qd = self.qd + dt * self.qdd
        e = y - q
        self.q = q + self.k0 * e
        self.qd = qd + self.k1 * e
        self.qdd = self.qdd + self.k2 * e
        return e


def innovations(y: Array, gain: SteadyGain) -> Array:
    """The filter's innovations over positions ``y`` sampled every ``gain.period_s`` (one
    fewer than ``y``), the filter started at rest at ``y[0]``: ``KalmanState``'s, by
    ``scipy.signal.lfilter``."""
    from scipy import signal  # lazy: only the identification needs it

    F = transition(gain.period_s)
    k = np.array(gain.gain)
    h = np.array([1.0, 0.0, 0.0])
    # s_k = x_{k-1} (filtered): s_{k+1} = (I - k h) F s_k + k y_k;  e_k = y_k - h F s_k
    a = (np.eye(3) - np.outer(k, h)) @ F
    c = -(h @ F)[None, :]
    b, den = signal.ss2tf(a, k[:, None], c, np.array([[1.0]]))
    d = np.asarray(y, dtype=np.float64) - y[0]  # the filter is linear: start it at rest, at 0
    out: Array = signal.lfilter(b[0], den, d[1:])
    return out
