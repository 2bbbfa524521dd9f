"""Sustained oscillation in contact with the wall (vibration), from the motion record.

1. The motion is band-passed to ``band_hz`` (4th-order Butterworth, zero phase); its amplitude
   is ``sqrt(2)`` times the RMS (m).
2. The frequency is the peak of its Welch spectrum (2 s Hann segments); the peak fraction is the
   share of the band's power within +-1 Hz of the peak and of its 2nd and 3rd harmonics.
3. The growth rate is the slope of ln(envelope) (``haptic_dob.analysis.envelope_growth``, 1/s).
4. A window vibrates when it is in contact at least ``min_contact`` of the time, the amplitude
   reaches ``threshold_m``, the peak fraction ``min_peak_fraction`` and the growth rate
   ``min_growth_per_s``.

A record longer than two ``window_s`` is judged window by window: it vibrates if any window does,
and reports the largest-amplitude vibrating window (else the largest) and how long its vibrating
windows last. A heuristic; why these steps and its calibration: docs/design/stability.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from haptic_dob.analysis.vibration import envelope_growth


@dataclass(frozen=True)
class OscillationSettings:
    """Band (Hz) and thresholds of the vibration detector."""

    band_hz: tuple[float, float] = (10.0, 200.0)
    threshold_m: float = 2e-5
    min_peak_fraction: float = 0.7
    min_growth_per_s: float = -0.05
    min_contact: float = 0.2
    window_s: float = 20.0

    def __post_init__(self) -> None:
        lo, hi = self.band_hz
        if not (0.0 < lo < hi and math.isfinite(hi)):
            raise ValueError(f"the vibration band needs 0 < LO < HI, got {lo:g}:{hi:g}")
        if not (self.threshold_m > 0.0 and math.isfinite(self.threshold_m)):
            raise ValueError(f"the vibration threshold must be > 0 m, got {self.threshold_m:g}")


@dataclass(frozen=True)
class Oscillation:
    """Oscillation figures of one segment."""

    vibrating: bool
    amplitude_m: float  # sqrt(2) * RMS of the band-passed motion
    frequency_hz: float  # spectral peak in the band
    growth_per_s: float  # slope of ln(envelope), > 0 grows
    peak_fraction: float  # band power at the peak and its harmonics / band power
    band_hz: tuple[float, float]  # the band actually used (capped below Nyquist)
    vibrating_s: float = 0.0  # total length of the windows that vibrate (s)
    windows: int = 1  # windows judged


def oscillation(
    x: np.ndarray,
    fs_hz: float,
    in_contact: np.ndarray | None,
    settings: OscillationSettings | None = None,
    segment_s: float = 2.0,
) -> Oscillation | None:
    """Band-limited oscillation of motion ``x`` (sampled at ``fs_hz``); None if it cannot be had.

    ``in_contact`` (bool per sample, None if unknown) gates the verdict; the figures come
    regardless.
    """
    s = settings or OscillationSettings()
    win = round(s.window_s * fs_hz)
    n = int(x.size)
    k = n // win if n >= 2 * win else 1
    bounds = [(i * win, (i + 1) * win) for i in range(k)] if k > 1 else [(0, n)]
    bounds[-1] = (bounds[-1][0], n)
    found = []
    for a, b in bounds:
        contact = None if in_contact is None else float(np.mean(in_contact[a:b]))
        r = _window(x[a:b], fs_hz, contact, s, segment_s)
        if r is not None:
            found.append((r, (b - a) / fs_hz))
    if not found:
        return None
    vib = [(r, d) for r, d in found if r.vibrating]
    pick = max(vib or found, key=lambda rd: rd[0].amplitude_m)[0]
    return replace(pick, vibrating_s=sum(d for _, d in vib), windows=len(found))


def _window(
    x: np.ndarray,
    fs_hz: float,
    contact_fraction: float | None,
    s: OscillationSettings,
    segment_s: float,
) -> Oscillation | None:
    """The figures of one window (see the module docstring)."""
    from scipy import signal  # lazy: scipy.signal (~0.5 s) off a node's start-up

    lo, hi = s.band_hz
    hi = min(hi, 0.45 * fs_hz)
    nper = round(segment_s * fs_hz)
    if lo >= hi or x.size < max(nper, 64):
        return None
    sos = signal.butter(4, [lo, hi], btype="bandpass", fs=fs_hz, output="sos")
    y = signal.sosfiltfilt(sos, x - float(np.mean(x)))
    amp = math.sqrt(2.0) * float(np.std(y))
    f, p = signal.welch(y, fs=fs_hz, window="hann", nperseg=nper, noverlap=nper // 2)
    band = (f >= lo) & (f <= hi)
    total = float(p[band].sum())
    if total <= 0.0:
        return Oscillation(False, 0.0, math.nan, math.nan, 0.0, (lo, hi))
    i = int(np.argmax(np.where(band, p, -1.0)))
    f0 = float(f[i])
    near = np.zeros(f.size, bool)
    for h in (1, 2, 3):
        near |= np.abs(f - h * f0) <= 1.0
    frac = float(p[near & band].sum()) / total
    growth = envelope_growth(y, fs_hz, baseline=0.0).rate_per_s
    vibrating = (
        contact_fraction is not None
        and contact_fraction >= s.min_contact
        and amp >= s.threshold_m
        and frac >= s.min_peak_fraction
        and growth >= s.min_growth_per_s
    )
    return Oscillation(bool(vibrating), amp, f0, float(growth), frac, (lo, hi))
