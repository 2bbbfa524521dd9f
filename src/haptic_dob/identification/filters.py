"""The filters and the least-squares step the identifications share (a slide's model, an arm's
joint friction): one record's samples in, filtered terms of the equation of motion out.

Positions are low-passed by a zero-phase Butterworth filter and differentiated by Savitzky-Golay;
the effort of sample k, applied over [k-1, k), is centred on the sample like the central
derivatives and filtered the same way; the Coulomb term is the filtered sign of a lightly
smoothed velocity. The same linear filters on every term make their lag and gain cancel; a term
nonlinear in the motion (an arm's rigid body) is computed on a lightly smoothed motion
(``light_motion``) and filtered after, like the effort (docs/design/identification.md, "The
filters"). Samples at rest are left out (stiction is in no model; an arm's whole fit leaves out
the stretches it is held still, ``held``), as are the filters' transients at both ends and
around a gap in the stamps (``contiguous``: states lost), and the rest is
decimated to about independent residuals so that standard errors mean something. Arrays are
along axis 0 (one column per joint for an arm).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy import signal

Arr = NDArray[np.float64]


#: friction is fitted where a joint moves faster than this many times its Coulomb term's turning
#: speed all through the filters' support: ``tanh(5) = 0.9999``, the term flat, so the late turn
#: of a filtered velocity at a reversal is out of the fit (``MotionFilters.clear_of_turns``)
FLAT_TURNS = 5.0
#: fewest samples (decimated) for a joint's friction fit clear of its turns; fewer: every sample
MIN_CLEAR = 40
#: rad/s (or m/s): slower is at rest for the friction fits (stiction is in no model)
MIN_SPEED = 0.02
#: s at rest, at least, for a stretch to be the device held (not a turn or a start from rest)
HELD_S = 0.5

#: the window (samples) of ``MotionFilters.light_motion``: as short as a quadratic fit's that
#: smooths the acceleration at all, so that the motion a nonlinear term sees is the true one
LIGHT_MOTION_WINDOW = 5


class IdentificationError(ValueError):
    """The record cannot give the model (too short, no motion, no step...): one line."""


@dataclass(frozen=True)
class MotionFilters:
    """The filters for a sample period ``dt`` (s) and a low-pass ``cutoff_hz``."""

    dt: float
    cutoff_hz: float
    sos: Any
    window: int  # Savitzky-Golay window (samples, odd)

    @classmethod
    def design(cls, dt: float, cutoff_hz: float) -> MotionFilters:
        """The filters, or ``IdentificationError`` for a cutoff the sample rate cannot carry."""
        fs = 1.0 / dt
        if not 0.0 < cutoff_hz < fs / 4:
            raise IdentificationError(f"cutoff must be in (0, {fs / 4:g}) Hz, got {cutoff_hz:g}")
        sos = signal.butter(4, cutoff_hz, fs=fs, output="sos")
        return cls(dt, cutoff_hz, sos, max(5, int(fs / cutoff_hz) | 1))

    def smooth(self, y: Arr) -> Arr:
        """The low-pass, then the Savitzky-Golay smoothing (a term of the equation)."""
        low = signal.sosfiltfilt(self.sos, y, axis=0)
        return np.asarray(signal.savgol_filter(low, self.window, 3, axis=0))

    def motion(self, position: Arr) -> tuple[Arr, Arr, Arr]:
        """Filtered position, its velocity and its acceleration."""
        x = signal.sosfiltfilt(self.sos, position, axis=0)
        w, dt = self.window, self.dt
        v = signal.savgol_filter(x, w, 3, deriv=1, delta=dt, axis=0)
        a = signal.savgol_filter(x, w, 3, deriv=2, delta=dt, axis=0)
        return np.asarray(x), np.asarray(v), np.asarray(a)

    def effort(self, effort: Arr) -> Arr:
        """The effort of [k-1, k) centred on sample k (mean of both sides), filtered."""
        mid = effort.copy()
        mid[:-1] = 0.5 * (effort[:-1] + effort[1:])
        return self.smooth(mid)

    def light_motion(self, position: Arr) -> tuple[Arr, Arr, Arr]:
        """A lightly smoothed position, velocity and acceleration (a quadratic Savitzky-Golay
        over ``LIGHT_MOTION_WINDOW`` samples): what a term nonlinear in the motion is computed
        on before ``smooth`` filters it like the effort (the noise its derivatives carry the
        low-pass takes out after)."""
        w, dt = LIGHT_MOTION_WINDOW, self.dt
        x = signal.savgol_filter(position, w, 2, axis=0)
        v = signal.savgol_filter(position, w, 2, deriv=1, delta=dt, axis=0)
        a = signal.savgol_filter(position, w, 2, deriv=2, delta=dt, axis=0)
        return np.asarray(x), np.asarray(v), np.asarray(a)

    def light_velocity(self, position: Arr) -> Arr:
        """A lightly smoothed velocity: its sign is the Coulomb term's, its size says moving."""
        return np.asarray(signal.savgol_filter(position, 11, 2, deriv=1, delta=self.dt, axis=0))

    def coulomb_term(self, light_velocity: Arr) -> Arr:
        """The filtered sign of the velocity."""
        return self.smooth(np.sign(light_velocity))

    def usable(self, light_velocity: Arr, min_speed: float) -> NDArray[np.bool_]:
        """Samples moving faster than ``min_speed`` all through the filter, away from the ends."""
        moving = np.abs(light_velocity) > min_speed
        keep = signal.sosfiltfilt(self.sos, moving.astype(float), axis=0) > 0.99
        edge = 2 * self.window
        keep[:edge] = False
        keep[len(keep) - edge :] = False
        return np.asarray(keep)

    def clear_of_turns(
        self, light_velocity: Arr, speed: float, min_speed: float, rows: NDArray[np.intp]
    ) -> NDArray[np.bool_]:
        """Which of ``rows`` (sample indices) move faster than ``FLAT_TURNS`` times the Coulomb
        term's turning ``speed`` (and ``min_speed``) all through the filter, where that term is
        flat (``usable``); all of them where fewer than ``MIN_CLEAR`` do."""
        clear = self.usable(light_velocity, max(min_speed, FLAT_TURNS * speed))[rows]
        return clear if int(clear.sum()) >= MIN_CLEAR else np.ones(len(rows), dtype=bool)

    def held(self, speed: Arr, min_speed: float, min_s: float) -> NDArray[np.bool_]:
        """Samples whose filters reach a stretch of at least ``min_s`` where ``speed`` stays
        under ``min_speed``: the device parked or held (an inkwell, a hand, a stop) by forces in
        no model, which a fit leaves out."""
        slow = np.concatenate([[0], (speed < min_speed).astype(np.int8), [0]])
        starts, ends = np.flatnonzero(np.diff(slow) == 1), np.flatnonzero(np.diff(slow) == -1)
        out = np.zeros(len(speed), dtype=bool)
        reach = 2 * self.window
        for a, b in zip(starts, ends, strict=True):
            if (b - a) * self.dt >= min_s:
                out[max(0, a - reach) : b + reach] = True
        return out

    def fit_rows(self, stamps_ns: NDArray[np.int64], speed: Arr) -> NDArray[np.bool_]:
        """Samples whose filters reach neither a lost state nor a stretch held still (``speed``:
        the fastest joint's, rad/s): the ones an arm's fit may use."""
        return self.contiguous(stamps_ns) & ~self.held(speed, MIN_SPEED, HELD_S)

    def contiguous(self, stamps_ns: NDArray[np.int64]) -> NDArray[np.bool_]:
        """Samples whose filters' support holds no gap in the stamps (a step of more than 1.5
        periods: states a driver or the network lost). The filters take the samples as one
        period apart, which is wrong across a gap: a fit leaves those samples out."""
        ok = np.ones(len(stamps_ns), dtype=bool)
        reach = 2 * self.window  # the Savitzky-Golay windows of the low-passed terms
        for g in np.flatnonzero(np.diff(stamps_ns) > 1.5e9 * self.dt):
            ok[max(0, g - reach) : g + 2 + reach] = False
        if ok.all():
            return ok
        return np.asarray(signal.sosfiltfilt(self.sos, ok.astype(float)) > 0.99)  # its tail

    @property
    def step(self) -> int:
        """Decimation to about independent residuals."""
        return max(1, int(1.0 / (self.dt * 2.0 * self.cutoff_hz)))


def fit(X: Arr, y: Arr, where: str) -> tuple[Arr, Arr, float]:
    """Least squares ``X theta = y``: theta, its standard errors, the residual's RMS."""
    theta, *_ = np.linalg.lstsq(X, y, rcond=None)
    resid = y - X @ theta
    sigma2 = float(resid @ resid) / max(1, len(y) - X.shape[1])
    try:
        std = np.sqrt(np.maximum(np.diag(sigma2 * np.linalg.inv(X.T @ X)), 0.0))
    except np.linalg.LinAlgError:
        raise IdentificationError(
            f"{where}: the motion does not separate the terms of the model (a richer "
            "excitation is needed)"
        ) from None
    return np.asarray(theta, np.float64), np.asarray(std, np.float64), math.sqrt(sigma2)


def physical(name: str, value: float, std: float, where: str) -> float:
    """A fitted friction term as a model may hold it: 0 where it is negative by less than two
    standard errors (consistent with none), else ``IdentificationError``."""
    if value >= 0.0:
        return value
    if value >= -2.0 * std:
        return 0.0
    raise IdentificationError(
        f"{where}: the fit gives a negative {name} ({value:.3g} +- {std:.2g}): the record does "
        "not separate friction from the rest (a richer excitation is needed)"
    )


def plus_minus(value: float | None, std: float | None, spec: str, none: str = "-") -> str:
    """``value +- std`` in ``spec``; ``none`` for no value."""
    if value is None:
        return none
    return f"{value:{spec}}" + (f" +- {std:{spec}}" if std is not None else "")
