"""Velocity from a driver's positions alone: a low-passed difference, an adaptive window, or a
Kalman filter.

``VelocityFilter``: the backward difference over the stamps' interval, then a first-order
low-pass. ``WindowVelocity``: first-order adaptive windowing (Janabi-Sharifi, Hayward and Chen
2000, "Discrete-time adaptive windowing for velocity estimation", IEEE TCST 8(6)), for encoder
counts coarse against the motion between samples: per joint, the slope of the least-squares
line through the longest run of recent samples (at most ``max_samples``) that all lie closer
than half a count to it. Slow motion gets a long window (little noise), fast motion a short one
(little lag). ``KalmanVelocity``: the steady-state Kalman filter of ``haptic_dob.core.
kalman_velocity`` per joint, its jerk density identified from a session (``haptic-identify
--velocity-noise``). Each takes (stamp ns, positions) and restarts from zero velocity after an
interval <= 0 or over ``max_gap_s``.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence
from typing import Protocol

from haptic_dob.core.kalman_velocity import KalmanState, steady_gain
from haptic_msgs_py.stamps import NS_PER_S

#: a step under this share of half a count is the driver's floating-point rounding (a joint
#: it computes from two others), not a finer encoder's count: ``finer_steps`` ignores it
ROUNDING_SHARE = 1e-6


def finer_steps(
    newest: Sequence[float], before: Sequence[float], half: Sequence[float], said: set[int]
) -> dict[int, float]:
    """The joints whose step from ``before`` to ``newest`` is under half their count (and over
    rounding), each once ever (``said`` keeps them), with that step."""
    new: dict[int, float] = {}
    for j, (a, b) in enumerate(zip(newest, before, strict=False)):
        step = abs(a - b)
        if ROUNDING_SHARE * half[j] < step < half[j] and j not in said:
            said.add(j)
            new[j] = step
    return new


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
    """First-order adaptive windowing, best fit (module docstring). Plain Python: on the
    command's path, cold between samples, it takes half the time numpy's calls did.

    Args:
        resolution: each joint's count (position units, > 0); a sample lies less than half of it
            off the motion's line.
        max_samples: the longest window, in intervals (>= 1; 1: the backward difference).
        max_gap_s: an interval <= 0 or longer restarts from zero velocity.
    """

    def __init__(self, resolution: Sequence[float], max_samples: int, max_gap_s: float) -> None:
        # strictly closer than half a count (a sample exactly half a count off, as far as a
        # rounded count can be, is out whatever the float rounding of its distance)
        self.half = tuple(0.5 * float(r) * (1.0 - 1e-9) for r in resolution)
        self.max_gap_s = max_gap_s
        self._t: deque[int] = deque(maxlen=max_samples + 1)  # stamps (ns), newest first
        self._q: deque[tuple[float, ...]] = deque(maxlen=max_samples + 1)
        self._finer: set[int] = set()  # the joints seen to step under half their count

    def update(self, stamp_ns: int, q: Sequence[float]) -> tuple[float, ...]:
        """The velocity (per s) at sample ``stamp_ns`` with positions ``q``."""
        if self._t and not 0.0 < (stamp_ns - self._t[0]) / NS_PER_S <= self.max_gap_s:
            self.reset()
        self._t.appendleft(stamp_ns)
        self._q.appendleft(tuple(q))
        if len(self._t) < 2:
            return (0.0,) * len(q)
        # seconds before this sample, from whole nanoseconds (a wall clock's stamps as float
        # seconds would keep their differences to 0.2 us only)
        tau = [(s - stamp_ns) / NS_PER_S for s in self._t]  # <= 0, newest first
        return tuple(_slope(tau, [p[j] for p in self._q], h) for j, h in enumerate(self.half))

    def finer_steps(self) -> dict[int, float]:
        """The joints whose newest step is under half their count, each once ever, with that
        step (called off the command's path)."""
        if len(self._q) < 2:
            return {}
        return finer_steps(self._q[0], self._q[1], self.half, self._finer)

    def reset(self) -> None:
        """Forget the history: the next sample starts again from zero velocity."""
        self._t.clear()
        self._q.clear()


class KalmanVelocity:
    """Each joint's steady-state Kalman filter (``haptic_dob.core.kalman_velocity``): plain
    Python on the command's path.

    Args:
        resolution: each joint's count (position units, > 0): the rounding's noise.
        jerk_psd: each joint's white-jerk density (units^2/s^5, > 0).
        period_s: the driver's nominal period, the gain's.
        max_gap_s: an interval <= 0 or longer restarts from zero velocity.
    """

    def __init__(
        self,
        resolution: Sequence[float],
        jerk_psd: Sequence[float],
        period_s: float,
        max_gap_s: float,
    ) -> None:
        self.gains = tuple(
            steady_gain(p, c, period_s) for p, c in zip(jerk_psd, resolution, strict=True)
        )
        self.half = tuple(0.5 * float(r) * (1.0 - 1e-9) for r in resolution)
        self.max_gap_s = max_gap_s
        self._joints: list[KalmanState] = []
        self._stamp = 0
        self._q: tuple[float, ...] = ()
        self._prev: tuple[float, ...] = ()
        self._finer: set[int] = set()

    def update(self, stamp_ns: int, q: Sequence[float]) -> tuple[float, ...]:
        """The velocity (per s) at sample ``stamp_ns`` with positions ``q``."""
        dt = (stamp_ns - self._stamp) / NS_PER_S
        self._stamp = stamp_ns
        self._prev, self._q = self._q, tuple(q)
        if not self._joints or not 0.0 < dt <= self.max_gap_s:
            self._joints = [KalmanState(g, y) for g, y in zip(self.gains, q, strict=True)]
            self._prev = ()
            return (0.0,) * len(q)
        out = []
        for f, y in zip(self._joints, q, strict=True):
            f.update(dt, y)
            out.append(f.qd)
        return tuple(out)

    def finer_steps(self) -> dict[int, float]:
        """The joints whose newest step is under half their count, each once ever, with that
        step (called off the command's path): a count set too coarse over-smooths."""
        return finer_steps(self._q, self._prev, self.half, self._finer)

    def reset(self) -> None:
        """Forget the state: the next sample starts again from zero velocity."""
        self._joints = []


def _slope(tau: list[float], y: list[float], half: float) -> float:
    """The slope of the least-squares line of the longest window [0, n] whose every sample is
    within ``half`` of it, growing n from 1 until one is not (running sums)."""
    if max(y) == min(y):
        return 0.0  # still: every window's line is flat through every sample
    slope = (y[0] - y[1]) / -tau[1]
    s1, st, sy = 2.0, tau[1], y[0] + y[1]
    stt, sty = st * st, st * y[1]
    for n in range(2, len(tau)):
        s1 += 1.0
        st += tau[n]
        stt += tau[n] * tau[n]
        sy += y[n]
        sty += tau[n] * y[n]
        b = (s1 * sty - st * sy) / (s1 * stt - st * st)
        a = (sy - b * st) / s1
        for i in range(n + 1):
            if abs(y[i] - a - b * tau[i]) > half:
                return slope
        slope = b
    return slope
