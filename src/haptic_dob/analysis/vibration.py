"""Oscillation growth and sustained vibration from a time record.

``envelope_growth`` measures how fast an oscillation's envelope grows (> 0) or decays (< 0):
the signal's mean is removed, the analytic signal (``scipy.signal.hilbert``) gives the envelope,
and a least-squares line through ``ln(envelope)`` over the window gives the rate (1/s). Where the
envelope first passes ``stop_amplitude`` (the linear dynamics end there, e.g. contact is about to
be lost) the oscillation has grown for sure; the rate is then the mean growth up to that point,
``ln(stop / start) / t``, which a line fitted over a few cycles would estimate poorly. The
dominant frequency comes from the periodogram.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from haptic_dob.core.validation import positive


@dataclass(frozen=True)
class Growth:
    """Envelope growth of one oscillation record."""

    rate_per_s: float  # > 0 grows, < 0 decays
    frequency_hz: float  # dominant frequency in the window
    amplitude_start: float  # envelope at the start of the fit (signal units)
    amplitude_end: float  # envelope at the end of the fit
    fit_s: float  # length of the fitted part (s)


def envelope_growth(
    x: ArrayLike,
    fs_hz: float,
    baseline: float | None = None,
    stop_amplitude: float | None = None,
    edge_s: float = 0.05,
) -> Growth:
    """Growth rate (1/s) of the oscillation in ``x`` sampled at ``fs_hz``.

    Args:
        x: the record (for example the position after a perturbation).
        fs_hz: sample rate (Hz).
        baseline: the equilibrium to subtract (default: the record's mean).
        stop_amplitude: end the fit where the envelope first exceeds this (signal units).
        edge_s: time trimmed at each end against the Hilbert transform's edge effects (s).
    """
    from scipy import signal  # lazy: scipy.signal (~0.5 s) off a node's start-up

    fs = positive("fs_hz", fs_hz)
    xa = np.asarray(x, dtype=np.float64).reshape(-1)
    if xa.size < 16 or not np.all(np.isfinite(xa)):
        raise ValueError("x must hold at least 16 finite samples")
    d = xa - (float(np.mean(xa)) if baseline is None else float(baseline))
    env = np.abs(signal.hilbert(d))
    edge = round(edge_s * fs)
    lo, hi = edge, max(edge + 8, xa.size - edge)
    stopped = False
    if stop_amplitude is not None:
        over = np.nonzero(env[lo:hi] > stop_amplitude)[0]
        if over.size:
            hi = max(lo + 8, lo + int(over[0]) + 1)
            stopped = env[lo] < stop_amplitude
    seg = env[lo:hi]
    t = np.arange(seg.size) / fs
    floor = max(float(np.max(seg)) * 1e-9, 1e-300)
    if stopped:
        slope = math.log(float(seg[-1]) / max(float(seg[0]), floor)) / max(t[-1], 1.0 / fs)
    else:
        slope = float(np.polyfit(t, np.log(np.maximum(seg, floor)), 1)[0])
    f, p = signal.periodogram(d[lo:hi], fs=fs, detrend="linear")
    freq = float(f[int(np.argmax(p[1:])) + 1]) if p.size > 1 else math.nan
    return Growth(slope, freq, float(seg[0]), float(seg[-1]), seg.size / fs)


@dataclass(frozen=True)
class PerturbationResponse:
    """How a wall answers a force pulse while a hand pushes steadily into it."""

    growth_per_s: float  # envelope growth after the pulse (1/s); NaN if vibrating before it
    frequency_hz: float
    amplitude_m: float  # envelope at the end of the fit (or the swing before the pulse)
    vibrating_before_pulse: bool  # the contact itself already started a sustained oscillation

    @property
    def vibrates(self) -> bool:
        """True when the oscillation grows (or was sustained before the pulse)."""
        return bool(self.vibrating_before_pulse or self.growth_per_s > 0.0)


def perturbation_response(
    depth_m: ArrayLike,
    fs_hz: float,
    pulse_at_s: float,
    pulse_s: float,
    static_depth_m: float,
) -> PerturbationResponse:
    """Growth of the oscillation a pulse starts in a steadily pushed wall (the onset protocol).

    ``depth_m`` is the penetration into the wall over time (m, from the start of the session,
    > 0 inside); ``static_depth_m`` the equilibrium penetration (push / K). The growth is fitted
    from the end of the pulse about the equilibrium and stops where the oscillation reaches half
    the equilibrium depth (contact is about to be lost). A swing of that size already in the
    0.2 s before the pulse means the contact itself started a sustained oscillation: the wall
    vibrates and its growth is not measured (NaN).
    """
    from scipy import signal  # lazy: scipy.signal (~0.5 s) off a node's start-up

    fs = positive("fs_hz", fs_hz)
    d = np.asarray(depth_m, dtype=np.float64).reshape(-1)
    depth = positive("static_depth_m", static_depth_m)
    i0 = round(pulse_at_s * fs)
    pre = d[max(0, round((pulse_at_s - 0.2) * fs)) : i0]
    start = i0 + round(pulse_s * fs)
    if pre.size < 16 or d.size - start < 16:
        raise ValueError("the record must hold 0.2 s before the pulse and some time after it")
    pre_amp = float(np.max(np.abs(pre - depth)))
    if pre_amp > 0.5 * depth:
        f, p = signal.periodogram(pre - np.mean(pre), fs=fs)
        return PerturbationResponse(math.nan, float(f[int(np.argmax(p[1:])) + 1]), pre_amp, True)
    g = envelope_growth(d[start:], fs, baseline=depth, stop_amplitude=0.5 * depth)
    return PerturbationResponse(g.rate_per_s, g.frequency_hz, g.amplitude_end, False)
