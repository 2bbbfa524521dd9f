"""Transparency of a rendered impedance from motion and hand-force records (thesis 2.1.4, 7.2).

H1 estimator (Fite et al.): ``Z_hat(f) = S_xF(f) / S_xx(f)`` of motion x (position, m) and hand
force F (N), both by Welch averaging (``scipy.signal.csd`` / ``welch``): Hann window, 50 %
overlap, each segment's mean removed, ``segment_s`` long segments; by default (``segment_for``)
4 s if that still averages ``MIN_AVERAGES`` (16) segments, else 2 s (why:
docs/recording-and-analysis.md).

Transparency ``T(f) = Z_hat / Z_d``. The bandwidth is the first frequency, from the lowest non-zero
bin up to ``fmax``, where |T| leaves the +-3 dB band [0.708, 1.413], interpolated linearly in |T|
between the two bins around it; ``fmax`` with ``band_limited_by_fmax`` set if it never leaves.
The average normalized impedance error is the mean of ``|Z_d - Z_hat| / |Z_d|`` over the bins
inside the band, in percent. The magnitude-squared coherence of x and F comes with it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from haptic_dob.core.validation import nonnegative, positive

BAND_DB = 3.0
#: the Welch segments tried, longest first (s), and the averages the chosen one must give
SEGMENTS_S = (4.0, 2.0)
MIN_AVERAGES = 16
DEFAULT_FMAX_HZ = 10.0


def averages(duration_s: float, segment_s: float) -> int:
    """Welch segments of ``segment_s`` with 50 % overlap in ``duration_s`` (0 if none fits)."""
    if duration_s < segment_s:
        return 0
    return int((duration_s - segment_s) // (0.5 * segment_s)) + 1


def segment_for(duration_s: float) -> float:
    """The default Welch segment (s) for a record of ``duration_s``: the longest of
    ``SEGMENTS_S`` giving ``MIN_AVERAGES``, else the longest that fits, else the shortest."""
    for seg in SEGMENTS_S:
        if averages(duration_s, seg) >= MIN_AVERAGES:
            return seg
    return next((seg for seg in SEGMENTS_S if seg <= duration_s), SEGMENTS_S[-1])


@dataclass(frozen=True)
class TransparencyResult:
    """Frequency-domain transparency of one record (bins up to fmax, DC excluded)."""

    freqs_hz: np.ndarray
    impedance: np.ndarray  # complex Z_hat (N/m)
    desired: np.ndarray  # complex Z_d (N/m)
    transparency: np.ndarray  # complex T = Z_hat / Z_d
    coherence: np.ndarray
    bandwidth_hz: float
    band_limited_by_fmax: bool
    impedance_error_pct: float
    error_per_bin: np.ndarray  # |Z_d - Z_hat| / |Z_d| per bin (fraction)
    segment_s: float
    fmax_hz: float

    @property
    def band_below_first_bin(self) -> bool:
        """True when |T| is outside the band at the first bin: the band ends below it."""
        return (not self.band_limited_by_fmax) and self.bandwidth_hz <= float(self.freqs_hz[0])

    @property
    def magnitude_db(self) -> np.ndarray:
        """|T| in dB per bin."""
        return np.asarray(20.0 * np.log10(np.abs(self.transparency)))

    @property
    def mean_coherence_in_band(self) -> float:
        """Mean coherence over the bins inside the bandwidth (nan if none)."""
        inside = self.freqs_hz <= self.bandwidth_hz
        return float(np.mean(self.coherence[inside])) if inside.any() else math.nan


def h1_impedance(
    x: ArrayLike, force: ArrayLike, fs_hz: float, segment_s: float | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return (freqs_hz, Z_hat complex N/m, coherence) of force over motion by the H1 estimator
    (``segment_s`` None: ``segment_for`` the record's length).

    Raises ``ValueError`` when the arrays differ in length, are not finite, hold less than one
    segment, or the motion is constant.
    """
    from scipy import signal  # lazy: scipy.signal (~0.5 s) off a node's start-up

    fs = positive("fs_hz", fs_hz)
    xa = np.asarray(x, dtype=np.float64).reshape(-1)
    seg = positive("segment_s", segment_for(xa.size / fs) if segment_s is None else segment_s)
    fa = np.asarray(force, dtype=np.float64).reshape(-1)
    if xa.shape != fa.shape:
        raise ValueError(f"x and force must have the same length, got {xa.size} and {fa.size}")
    if not (np.all(np.isfinite(xa)) and np.all(np.isfinite(fa))):
        raise ValueError("x and force must be finite")
    nperseg = round(seg * fs)
    if nperseg < 8:
        raise ValueError(f"segment_s * fs_hz must give at least 8 samples, got {nperseg}")
    if xa.size < nperseg:
        raise ValueError(
            f"record too short for the spectral settings: {xa.size / fs:.3g} s < one "
            f"{seg:g} s segment"
        )
    if np.ptp(xa) == 0.0:
        raise ValueError("no motion: x is constant")
    kw = {"fs": fs, "window": "hann", "nperseg": nperseg, "noverlap": nperseg // 2}
    f, sxx = signal.welch(xa, **kw)
    _, sxf = signal.csd(xa, fa, **kw)
    _, coh = signal.coherence(xa, fa, **kw)
    with np.errstate(divide="ignore", invalid="ignore"):
        z = sxf / sxx
    return f, z, coh


def transparency(
    x: ArrayLike,
    force: ArrayLike,
    fs_hz: float,
    stiffness_n_per_m: float,
    damping_n_s_per_m: float = 0.0,
    fmax_hz: float = DEFAULT_FMAX_HZ,
    segment_s: float | None = None,
) -> TransparencyResult:
    """Transparency of the impedance ``K + j B w`` rendered from records of x (m) and F (N)
    (``segment_s`` None: ``segment_for`` the record's length)."""
    k = positive("stiffness_n_per_m", stiffness_n_per_m)
    b = nonnegative("damping_n_s_per_m", damping_n_s_per_m)
    fmax = positive("fmax_hz", fmax_hz)
    if segment_s is None:
        segment_s = segment_for(np.asarray(x).size / positive("fs_hz", fs_hz))
    f, z, coh = h1_impedance(x, force, fs_hz, segment_s)
    keep = (f > 0.0) & (f <= fmax)
    if keep.sum() < 2:
        raise ValueError(f"fewer than two frequency bins in (0, {fmax:g}] Hz; use longer segments")
    f, z, coh = f[keep], z[keep], coh[keep]
    zd = k + 1j * b * 2.0 * np.pi * f
    t = z / zd
    bw, limited = band_edge(f, np.abs(t), fmax)
    err = np.abs(zd - z) / np.abs(zd)
    inside = f <= bw
    avg = float(np.mean(err[inside]) * 100.0) if inside.any() else math.nan
    return TransparencyResult(f, z, zd, t, coh, bw, limited, avg, err, segment_s, fmax)


def band_edge(freqs_hz: np.ndarray, magnitude: np.ndarray, fmax_hz: float) -> tuple[float, bool]:
    """First exit of ``magnitude`` from the +-3 dB band, interpolated linearly in |T|.

    Returns (edge_hz, limited_by_fmax). If the first bin is already outside, the edge is that
    bin's frequency; a non-finite magnitude counts as outside.
    """
    lo, hi = 10 ** (-BAND_DB / 20.0), 10 ** (BAND_DB / 20.0)
    mag = np.asarray(magnitude, dtype=np.float64)
    outside = ~((mag >= lo) & (mag <= hi))
    if not outside.any():
        return float(fmax_hz), True
    i = int(np.argmax(outside))
    if i == 0 or not np.isfinite(mag[i]):
        return float(freqs_hz[i]), False
    bound = hi if mag[i] > hi else lo
    frac = (bound - mag[i - 1]) / (mag[i] - mag[i - 1])
    return float(freqs_hz[i - 1] + frac * (freqs_hz[i] - freqs_hz[i - 1])), False


def mass_damper_band_edge_hz(stiffness_n_per_m: float, mass_kg: float) -> float:
    """Band edge of an ideal mass-damper under OL: ``sqrt(0.293 K / m) / (2 pi)`` (theory 6)."""
    lo = 10 ** (-BAND_DB / 20.0)
    return math.sqrt((1.0 - lo) * stiffness_n_per_m / mass_kg) / (2.0 * math.pi)
