"""Velocity from a driver's positions alone: a low-passed difference, or an adaptive window.

``VelocityFilter``: the backward difference over the stamps' interval, then a first-order
low-pass. ``WindowVelocity``: first-order adaptive windowing (Janabi-Sharifi, Hayward and Chen
2000, "Discrete-time adaptive windowing for velocity estimation", IEEE TCST 8(6)), for encoder
counts coarse against the motion between samples: per joint, the slope of the least-squares
line through the longest run of recent samples (at most ``max_samples``) that all lie closer
than half a count to it. Slow motion gets a long window (little noise), fast motion a short one
(little lag). Both take (stamp ns, positions) and restart from zero velocity after an interval
<= 0 or over ``max_gap_s``.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence
from typing import Protocol

import numpy as np

from haptic_msgs_py.stamps import NS_PER_S


class Velocity(Protocol):
    """What the state reader asks of a velocity estimator."""

    def update(self, stamp_ns: int, q: Sequence[float]) -> tuple[float, ...]: ...

    def reset(self) -> None: ...


class VelocityFilter:
    """Backward difference of positions over the stamps' interval, then a first-order low-pass
    (``alpha = 1 - exp(-2 pi fc dt)``; ``fc = 0``: unfiltered). The first sample's velocity is
    zero; an interval <= 0 or over ``max_gap_s`` restarts the filter from that sample."""

    def __init__(self, cutoff_hz: float, max_gap_s: float) -> None:
        self.cutoff_hz = cutoff_hz
        self.max_gap_s = max_gap_s
        self._q: tuple[float, ...] | None = None
        self._stamp = 0
        self._v: list[float] = []

    def update(self, stamp_ns: int, q: Sequence[float]) -> tuple[float, ...]:
        """The velocity (per s) at sample ``stamp_ns`` with positions ``q``."""
        prev, self._q = self._q, tuple(q)
        dt = (stamp_ns - self._stamp) / NS_PER_S
        self._stamp = stamp_ns
        if prev is None or not 0.0 < dt <= self.max_gap_s:
            self._v = [0.0] * len(q)
            return tuple(self._v)
        raw = [(a - b) / dt for a, b in zip(q, prev, strict=True)]
        if self.cutoff_hz <= 0.0:
            self._v = raw
        else:
            alpha = 1.0 - math.exp(-2.0 * math.pi * self.cutoff_hz * dt)
            self._v = [v + alpha * (r - v) for v, r in zip(self._v, raw, strict=True)]
        return tuple(self._v)

    def reset(self) -> None:
        """Forget the history: the next sample starts again from zero velocity."""
        self._q = None


class WindowVelocity:
    """First-order adaptive windowing, best fit (module docstring).

    Args:
        resolution: each joint's count (position units, > 0); a sample lies less than half of it
            off the motion's line.
        max_samples: the longest window, in intervals (>= 1; 1: the backward difference).
        max_gap_s: an interval <= 0 or longer restarts from zero velocity.
    """

    def __init__(self, resolution: Sequence[float], max_samples: int, max_gap_s: float) -> None:
        # strictly closer than half a count (a sample exactly half a count off, as far as a
        # rounded count can be, is out whatever the float rounding of its distance)
        self.half = 0.5 * np.asarray(resolution, dtype=np.float64) * (1.0 - 1e-9)
        self.max_gap_s = max_gap_s
        self._t: deque[float] = deque(maxlen=max_samples + 1)  # newest first (s)
        self._y: deque[np.ndarray] = deque(maxlen=max_samples + 1)

    def update(self, stamp_ns: int, q: Sequence[float]) -> tuple[float, ...]:
        """The velocity (per s) at sample ``stamp_ns`` with positions ``q``."""
        t = stamp_ns / NS_PER_S
        if self._t and not 0.0 < t - self._t[0] <= self.max_gap_s:
            self.reset()
        self._t.appendleft(t)
        self._y.appendleft(np.asarray(q, dtype=np.float64))
        if len(self._t) < 2:
            return (0.0,) * len(q)
        tau = np.fromiter(self._t, np.float64, len(self._t)) - t  # <= 0, newest first
        y = np.stack(self._y)  # (samples, joints)
        # least-squares line of the windows [0, n] for every n at once (cumulative sums)
        s1 = np.arange(1.0, tau.size + 1.0)[:, None]
        st, stt = np.cumsum(tau)[:, None], np.cumsum(tau * tau)[:, None]
        sy, sty = np.cumsum(y, axis=0), np.cumsum(tau[:, None] * y, axis=0)
        det = s1 * stt - st * st
        with np.errstate(divide="ignore", invalid="ignore"):
            slope = (s1 * sty - st * sy) / det
        slope, s1, st, sy = slope[1:], s1[1:], st[1:], sy[1:]  # windows of >= 2 samples
        icpt = (sy - slope * st) / s1
        # each window's largest distance of its samples from its line
        off = np.abs(y[None, :, :] - icpt[:, None, :] - slope[:, None, :] * tau[None, :, None])
        inside = np.arange(tau.size)[None, :] <= np.arange(1, tau.size)[:, None]
        worst = np.where(inside[:, :, None], off, 0.0).max(axis=1)  # (windows, joints)
        fits = np.cumprod(worst <= self.half, axis=0)
        n = np.maximum(fits.sum(axis=0), 1)  # the two newest samples always fit
        return tuple(float(v) for v in slope[n - 1, np.arange(y.shape[1])])

    def reset(self) -> None:
        """Forget the history: the next sample starts again from zero velocity."""
        self._t.clear()
        self._y.clear()
