"""The identification input per axis: a bounded chirp or multisine, and the holding spring."""

from __future__ import annotations

import math

import numpy as np
import pytest

from haptic_dob.core.cycle import wall_force
from haptic_dob.core.environment import VirtualWall
from haptic_dob.core.excitation import Excitation
from haptic_dob.runtime.params import build, specs_of

ORIGIN = (0.0, 0.0, 0.0)
NORMAL = (0.0, 0.0, 1.0)


def samples(e: Excitation, seconds: float, rate_hz: float = 1000.0) -> np.ndarray:
    t = np.arange(round(seconds * rate_hz)) / rate_hz
    return np.array([e.force(x, NORMAL, ORIGIN) for x in t])


@pytest.mark.parametrize("kind", ["chirp", "multisine"])
def test_each_axis_gets_its_own_bounded_signal(kind: str) -> None:
    """Within +-amplitude on every axis, reaching it; the three axes all but uncorrelated."""
    e = Excitation(kind, 1.5, at_s=0.0, low_hz=1.0, high_hz=8.0, period_s=10.0, along="axes")
    f = samples(e, 20.0)
    assert np.abs(f).max() <= 1.5
    assert np.abs(f).max(axis=0) == pytest.approx([1.5] * 3, rel=0.02)
    corr = np.corrcoef(f.T)
    assert np.abs(corr[np.triu_indices(3, 1)]).max() < 0.05, corr
    # each axis is the first a third of a period later
    shift = round(10.0 / 3.0 * 1000)
    t = np.arange(2000) / 1000.0 + 1.0
    later = np.array([e.force(x + 10.0 / 3.0, NORMAL, ORIGIN)[0] for x in t])
    np.testing.assert_allclose(f[1000:3000, 1], later, atol=1e-9)
    assert shift > 0


def test_the_multisine_holds_the_band_and_nothing_else() -> None:
    """Power at the multiples of 1/period inside [low, high], none outside."""
    e = Excitation("multisine", 1.0, at_s=0.0, low_hz=2.0, high_hz=5.0, period_s=2.0, along="axes")
    x = samples(e, 2.0)[:, 0]  # one period
    spectrum = np.abs(np.fft.rfft(x)) / len(x)
    freqs = np.fft.rfftfreq(len(x), 1e-3)
    inside = (freqs >= 2.0) & (freqs <= 5.0)
    assert np.all(spectrum[inside] > 0.05)
    assert spectrum[~inside].max() < 1e-9
    assert np.count_nonzero(inside) == 7  # 2.0, 2.5, ... 5.0 Hz


def test_the_chirp_sweeps_from_low_to_high_over_its_period() -> None:
    """Half a period between zero crossings: the frequency of a logarithmic sweep,
    ``low (high / low)^(t / period)``, midway between them."""
    e = Excitation("chirp", 1.0, at_s=1.0, low_hz=1.0, high_hz=16.0, period_s=4.0, along="axes")
    x = samples(e, 5.0)[:, 0]
    assert not x[:1000].any()  # nothing before at_s
    crossings = np.flatnonzero(np.diff(np.signbit(x[1000:]))) * 1e-3  # s after the start
    measured = 0.5 / np.diff(crossings)
    want = 16.0 ** (0.5 * (crossings[1:] + crossings[:-1]) / 4.0)
    np.testing.assert_allclose(measured, want, rtol=0.05)
    assert want[0] < 1.6 and want[-1] > 14.0


def test_along_the_normal_the_chirp_is_one_signal_and_step_and_sine_are_unchanged() -> None:
    wall = VirtualWall(stiffness_n_per_m=0.0, normal=(0.0, 1.0, 0.0))
    e = Excitation("chirp", 2.0, at_s=0.0, low_hz=1.0, high_hz=8.0)
    for t in (0.1, 0.37, 2.2):
        f = wall_force(wall, ORIGIN, ORIGIN, e, round(t * 1e9))
        assert f == pytest.approx((0.0, e.force_n(t), 0.0))
    step = Excitation("step", 2.4, at_s=1.0)
    assert wall_force(wall, ORIGIN, ORIGIN, step, 1_000_000_000) == (0.0, 2.4, 0.0)
    sine = Excitation("sine", 0.6, at_s=0.0, frequency_hz=2.0)
    assert sine.force((0.125), (1.0, 0.0, 0.0), ORIGIN)[0] == pytest.approx(0.6)


def test_the_holding_spring_pulls_toward_its_point_on_every_axis() -> None:
    e = Excitation(hold_n_per_m=150.0, hold_at=(0.01, 0.0, -0.02))
    assert e.active and e.force_n(5.0) == 0.0
    f = e.force(3.0, NORMAL, (0.03, -0.01, -0.02))
    assert f == pytest.approx((-3.0, 1.5, 0.0))
    wall = VirtualWall(stiffness_n_per_m=0.0)
    assert wall_force(wall, (0.03, -0.01, -0.02), ORIGIN, e, 0) == pytest.approx(f)
    assert "held by 150 N/m" in e.label()


def test_refused_settings_name_the_problem() -> None:
    with pytest.raises(ValueError, match="along axes needs a chirp or a multisine"):
        Excitation("step", 1.0, along="axes")
    with pytest.raises(ValueError, match="low_hz < high_hz"):
        Excitation("chirp", 1.0, low_hz=5.0, high_hz=5.0)
    with pytest.raises(ValueError, match="0 multiples of 1/period_s"):
        Excitation("multisine", 1.0, low_hz=1.1, high_hz=1.2, period_s=1.0)
    with pytest.raises(ValueError, match="along must be one of normal, axes"):
        Excitation(along="diagonal")


def test_the_parameters_are_declared_and_build_it() -> None:
    specs = {s.name: s for s in specs_of(Excitation, "excitation.")}
    assert specs["excitation.kind"].choices == ("none", "step", "sine", "chirp", "multisine")
    assert specs["excitation.along"].choices == ("normal", "axes")
    assert specs["excitation.hold_at"].length == 3 and specs["excitation.period_s"].unit == "s"
    e = build(
        Excitation,
        {"excitation.kind": "multisine", "excitation.amplitude_n": 1, "excitation.along": "axes"},
        "excitation.",
    )
    assert e.label() == "1 N 1-8 Hz multisine along x, y and z"
    assert math.isfinite(e.force_n(3.3))
