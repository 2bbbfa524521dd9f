"""The linear discrete model of the loop: the passivity bounds, and DOB against CL."""

from __future__ import annotations

import pytest

from haptic_dob.analysis.linear_loop import (
    chatter_gain,
    linear_onset,
    sample_rate_mode,
    spectral_radius,
)


@pytest.mark.parametrize("kf", [0.0, 1.0, 2.0, 25.0])
def test_ol_and_cl_onsets_are_the_sampled_spring_bound(kf: float) -> None:
    """An ideal force sensor makes the loop a sampled spring (1 + Kf) K: K (1+Kf) < 2 b / T."""
    bound = 2 * 1.272 / 1e-3 / (1 + kf)
    onset = linear_onset(kf, "OL" if kf == 0 else "CL")
    assert onset == pytest.approx(bound, rel=0.01)


def test_dob_is_less_stable_than_cl_and_more_so_for_a_fast_observer() -> None:
    cl = linear_onset(1.0, "CL")
    slow, fast = linear_onset(1.0, "DOB", gain=2.0), linear_onset(1.0, "DOB", gain=41.6)
    assert fast < cl
    assert fast < slow <= cl * 1.02


def test_dob_kf_100_is_unstable_at_any_stiffness_with_the_default_observer() -> None:
    assert linear_onset(100.0, "DOB", gain=41.6) == 0.0
    assert spectral_radius(0.0, 100.0, "DOB", 41.6, 0.416, 1.272, 1e-3) > 1.0


@pytest.mark.parametrize(("mode", "kf"), [("CL", 2.0), ("DOB", 1.0), ("DOB", 2.0)])
def test_the_model_matches_the_simulated_onset(mode: str, kf: float) -> None:
    """The protocol's batch onset (encoder, sensor noise, no Coulomb, the 20 N/m grip, the
    amplifier lag) is the linear model's with the same grip and lag, within 3 %; the grip
    matters (DOB Kf=1: 775 -> 661 N/m), and so does the lag (661 -> 589 N/m)."""
    from haptic_sim.slide.session import SessionConfig
    from haptic_sim.slide.stability import StabilityProtocol, law_for, sweep

    grip = StabilityProtocol().grip_n_per_m
    lag = SessionConfig().device.amplifier_lag_s
    lin = linear_onset(kf, mode, hand_stiffness=grip, amplifier_lag_s=lag)
    base = SessionConfig().replace(law=law_for(mode, kf))
    result = sweep([lin * 0.9, lin * 0.97, lin * 1.03, lin * 1.1], base)
    assert result.onset_stiffness_n_per_m == pytest.approx(lin, rel=0.03)


@pytest.mark.parametrize(("mode", "kf"), [("OL", 0.0), ("CL", 2.0), ("DOB", 1.0)])
def test_a_vanishing_amplifier_lag_is_no_lag_and_a_lag_lowers_the_onset(mode, kf) -> None:
    none = linear_onset(kf, mode, hand_stiffness=20.0)
    assert linear_onset(kf, mode, hand_stiffness=20.0, amplifier_lag_s=1e-9) == pytest.approx(
        none, abs=1.0
    )
    lags = [linear_onset(kf, mode, hand_stiffness=20.0, amplifier_lag_s=t) for t in (5e-5, 2e-4)]
    assert none > lags[0] > lags[1]


def test_bad_arguments() -> None:
    with pytest.raises(ValueError, match="mode"):
        spectral_radius(800.0, 1.0, "PID", 41.6, 0.416, 1.272, 1e-3)
    with pytest.raises(ValueError, match="gain"):
        spectral_radius(800.0, 1.0, "DOB", 0.0, 0.416, 1.272, 1e-3)


@pytest.mark.parametrize("kf", [25.0, 100.0])
def test_dob_chatters_at_the_sample_rate_above_2_m_over_kf_t(kf: float) -> None:
    """The estimate carries -(c T / 2 m) of the last command: with Kf the loop has a real mode
    near -Kf c T / (2 m), the command alternating its sign every period."""
    c = chatter_gain(kf, 0.416, 1.272, 1e-3)
    assert c == pytest.approx(2 * 0.416 / (kf * 1e-3), rel=0.01)  # 8.32 and 33.3 N s/m
    below = sample_rate_mode(800.0, kf, 0.95 * c, 0.416, 1.272, 1e-3)
    above = sample_rate_mode(800.0, kf, 1.05 * c, 0.416, 1.272, 1e-3)
    assert below < 1.0 < above
    # the wall and the grip hardly move it; the amplifier's lag lowers it (7.6 N s/m at Kf 100)
    assert chatter_gain(kf, 0.416, 1.272, 1e-3, 3200.0, 300.0) == pytest.approx(c, rel=0.01)
    lagged = chatter_gain(kf, 0.416, 1.272, 1e-3, amplifier_lag_s=5e-5)
    assert lagged is not None and 0.85 * c < lagged < 0.95 * c


def test_at_kf_1_no_observer_gain_chatters_without_a_lag() -> None:
    """-c T / (2 m) never reaches -1 before the observer settles within a period (c T / m = 50)."""
    assert chatter_gain(1.0, 0.416, 1.272, 1e-3) is None


def test_the_chattering_dob_loop_saturates_in_the_simulation_and_the_quiet_one_does_not() -> None:
    """Batch, the chapter-7 session at 800 N/m with DOB Kf=25: c = 41.6 N s/m is above that
    Kf's chatter gain (31 N s/m with the lag) and the command sits at the 4 N limit much of the
    time (measured 45 %); c = 7 N s/m is below it and the command does not."""
    from haptic_sim.slide.session import SessionConfig, run_session
    from haptic_sim.slide.stability import law_for

    base = SessionConfig().replace(
        law=law_for("DOB", 25.0), wall__stiffness_n_per_m=800.0, loop__duration_s=10.0
    )
    fast = run_session(base.replace(observer__gain=41.6)).summary().saturated_pct
    slow = run_session(base.replace(observer__gain=7.0)).summary().saturated_pct
    assert fast > 20.0 > 1.0 > slow, (fast, slow)
