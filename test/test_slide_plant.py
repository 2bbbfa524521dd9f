"""The simulated slide's own truth: stiction with a Stribeck fall-off, and the amplifier's lag."""

from __future__ import annotations

import math

import pytest

from haptic_dob.models.slide import SlideParams
from haptic_sim.hand import HandParams
from haptic_sim.slide import SimulatedSlide, SlideDeviceParams

NO_HAND = HandParams(behaviour="none")


def test_the_friction_falls_from_static_to_coulomb_over_the_stribeck_speed() -> None:
    d = SlideDeviceParams()  # Fc 0.24 N, static 1.5 Fc, 5 mm/s
    assert d.friction_n(1e-9) == pytest.approx(0.36)
    assert d.friction_n(0.005) == pytest.approx(0.24 + 0.12 / math.e)
    assert d.friction_n(0.1) == pytest.approx(0.24)
    flat = SlideDeviceParams.matching(SlideParams())
    assert flat.friction_n(1e-9) == flat.friction_n(0.1) == 0.24
    with pytest.raises(ValueError, match="stiction_ratio must be >= 1"):
        SlideDeviceParams(stiction_ratio=0.5)


def moved_m(device: SlideDeviceParams, force_n: float, cycles: int = 200) -> float:
    """How far the slide at rest moves under a constant actuator force (m)."""
    slide = SimulatedSlide(device, hand=NO_HAND)
    for _ in range(cycles):
        slide.apply([force_n])
    return slide.x


def test_a_force_between_coulomb_and_static_friction_does_not_break_the_slide_away() -> None:
    sticky, plain = SlideDeviceParams(), SlideDeviceParams.matching(SlideParams())
    assert moved_m(sticky, 0.30) == 0.0  # 0.24 < 0.30 < 0.36 N
    assert moved_m(sticky, 0.40) > 1e-3
    assert moved_m(plain, 0.30) > 1e-4  # the model's plant has no stiction


def test_the_applied_force_lags_the_command_by_the_amplifier_time_constant() -> None:
    """Free mass, no friction: v(t) = (u / m) (t - tau (1 - exp(-t / tau))) after a step u."""
    tau, m, u = 1e-3, 0.416, 1.0
    device = SlideDeviceParams(mass_kg=m, viscous_n_s_per_m=0.0, coulomb_n=0.0, amplifier_lag_s=tau)
    slide = SimulatedSlide(device, hand=NO_HAND)
    for k in range(1, 11):
        slide.apply([u])
        t = k * slide.dt
        assert slide.v == pytest.approx((u / m) * (t - tau * (1.0 - math.exp(-t / tau))), rel=1e-9)
        assert slide.applied_force == pytest.approx(u * (1.0 - math.exp(-t / tau)), rel=1e-9)
    assert slide.sample().effort == (u,)  # the driver reports the command, not the lagged force
