"""Transparency analysis from arrays (H1 impedance, bandwidth, impedance error)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from haptic_dob.analysis import band_edge, h1_impedance, mass_damper_band_edge_hz, transparency
from haptic_dob.analysis.transparency import averages, segment_for

FS = 1000.0


def mass_damper_record(K: float, m: float, b: float, seconds: float = 60.0, seed: int = 0):
    """Band-limited random motion and the force of an exact K + b s + m s^2 impedance.

    Both are built in the frequency domain as one periodic record (random phases, 0.05-10 Hz, as
    a hand moves), so the force is exact and the only error left is the estimator's own.
    """
    rng = np.random.default_rng(seed)
    n = int(seconds * FS)
    f = np.fft.rfftfreq(n, 1 / FS)
    X = np.where((f > 0.05) & (f < 10.0), np.exp(2j * np.pi * rng.random(f.size)), 0.0)
    w = 2 * np.pi * f
    x = np.fft.irfft(X, n)
    F = np.fft.irfft(X * (K + 1j * b * w - m * w**2), n)
    return x / np.std(x) * 1e-3, F / np.std(x) * 1e-3


def exact_edge(K: float, m: float, b: float) -> float:
    """Where |1 - m w^2 / K + j b w / K| first falls to 10^(-3/20)."""

    def g(f: float) -> float:
        w = 2 * np.pi * f
        return abs(1 - m * w * w / K + 1j * b * w / K) - 10 ** (-3 / 20)

    return brentq(g, 1e-3, 1.5 * mass_damper_band_edge_hz(K, m))


@pytest.mark.parametrize("K", [80.0, 800.0, 1600.0, 2400.0])
def test_mass_damper_bandwidth_matches_the_formula(K: float) -> None:
    x, f = mass_damper_record(K, 0.416, 1.272)
    tr = transparency(x, f, FS, K)
    # resolution: linear interpolation between 0.25 Hz bins of a curved |T| (worst at 80 N/m)
    assert tr.bandwidth_hz == pytest.approx(exact_edge(K, 0.416, 1.272), rel=0.02, abs=0.06)
    # the damping-free formula of the theory sheet
    assert tr.bandwidth_hz == pytest.approx(mass_damper_band_edge_hz(K, 0.416), rel=0.03)
    assert not tr.band_limited_by_fmax
    # window leakage from the large inertial force at 10 Hz costs coherence on soft walls
    assert tr.mean_coherence_in_band > 0.9


def test_impedance_error_is_the_mean_relative_error_inside_the_band() -> None:
    x, f = mass_damper_record(800.0, 0.416, 1.272)
    tr = transparency(x, f, FS, 800.0)
    w = 2 * np.pi * tr.freqs_hz
    exact = np.abs(-0.416 * w**2 + 1j * 1.272 * w) / 800.0
    inside = tr.freqs_hz <= tr.bandwidth_hz
    assert tr.impedance_error_pct == pytest.approx(np.mean(exact[inside]) * 100, rel=0.05)


def test_perfect_spring_is_transparent_to_fmax() -> None:
    x, f = mass_damper_record(800.0, 0.0, 0.0)
    tr = transparency(x, f, FS, 800.0, fmax_hz=10.0)
    assert tr.band_limited_by_fmax and tr.bandwidth_hz == 10.0
    assert tr.impedance_error_pct < 0.5


def test_a_band_that_ends_below_the_first_bin_is_flagged_not_measured() -> None:
    """A wall rendered 6 dB soft from the lowest frequency on: the band ends somewhere below the
    first bin (0.25 Hz with the default 4 s segments), which is a floor, not an edge; a record
    whose first bin is inside is not flagged."""
    x, f = mass_damper_record(800.0, 0.416, 1.272)
    soft = transparency(x, 0.5 * f, FS, 800.0)
    assert soft.segment_s == 4.0 and soft.freqs_hz[0] == pytest.approx(0.25)
    assert soft.band_below_first_bin and soft.bandwidth_hz == pytest.approx(0.25)
    assert not transparency(x, f, FS, 800.0).band_below_first_bin
    coarse = transparency(x, 0.5 * f, FS, 800.0, segment_s=2.0)
    assert coarse.band_below_first_bin and coarse.bandwidth_hz == pytest.approx(0.5)


def test_the_default_segment_is_as_long_as_sixteen_averages_allow() -> None:
    """4 s segments (0.25 Hz bins) where they average at least 16 (chapter 7's 38 s give 18),
    else 2 s: an 18 s record (8 averages of 4 s) and anything shorter, down to one segment."""
    assert averages(38.0, 4.0) == 18 and segment_for(38.0) == 4.0
    assert segment_for(34.0) == 4.0 and segment_for(33.9) == 2.0
    assert averages(18.0, 4.0) == 8 and segment_for(18.0) == 2.0
    assert segment_for(2.25) == 2.0 and averages(1.8, 2.0) == 0
    x, f = mass_damper_record(800.0, 0.416, 1.272, seconds=18.0)
    assert transparency(x, f, FS, 800.0).segment_s == 2.0


def test_band_edge_interpolates_linearly_in_magnitude() -> None:
    f = np.array([1.0, 2.0, 3.0])
    lo = 10 ** (-3 / 20)
    mag = np.array([1.0, lo + 0.1, lo - 0.3])
    edge, limited = band_edge(f, mag, 10.0)
    assert edge == pytest.approx(2.25) and not limited
    assert band_edge(f, np.array([0.5, 1.0, 1.0]), 10.0) == (1.0, False)


@pytest.mark.parametrize(
    ("args", "match"),
    [
        ((np.zeros(100), np.zeros(99)), "same length"),
        ((np.ones(5000), np.ones(5000)), "no motion"),
        ((np.arange(100.0), np.arange(100.0)), "too short"),
        ((np.array([np.nan] * 5000), np.zeros(5000)), "finite"),
    ],
)
def test_h1_rejects_bad_records(args, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        h1_impedance(*args, FS)


def test_transparency_rejects_bad_settings() -> None:
    x, f = mass_damper_record(800.0, 0.416, 1.272, seconds=10)
    with pytest.raises(ValueError, match="stiffness"):
        transparency(x, f, FS, 0.0)
    with pytest.raises(ValueError, match="fs_hz"):
        transparency(x, f, -1.0, 800.0)
    with pytest.raises(ValueError, match="fmax"):
        transparency(x, f, FS, 800.0, fmax_hz=0.0)
