"""Chapter 6's tap protocol: the residual motion of a record, the first vibrating wall, checks."""

from __future__ import annotations

import numpy as np

from haptic_sim.experiments import tap
from haptic_sim.experiments.records import TapPoint
from haptic_sim.slide.stability import TAP, detection_threshold_m, felt

RATE = 1000.0


def _record(amplitude_m: float, freq_hz: float) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(round(TAP.duration_s * RATE)) / RATE
    push = 4e-4 + 1e-5 * t  # the held push, creeping a little: the slow trend is left out
    return t, push + amplitude_m * np.sin(2 * np.pi * freq_hz * t)


def test_a_sustained_oscillation_vibrates_and_a_still_slide_does_not() -> None:
    t, x = _record(300e-6, 25.0)
    loud = tap.tap_point_of(2400.0, t, x, RATE)
    assert loud.vibrates and abs(loud.frequency_hz - 25.0) < 1.5
    assert abs(loud.residual_rms_m - 300e-6 / np.sqrt(2)) < 10e-6
    t, x = _record(0.0, 25.0)
    quiet = tap.tap_point_of(2000.0, t, np.round(x / 1e-6) * 1e-6, RATE)  # 1 um encoder
    assert not quiet.vibrates and quiet.residual_rms_m < 1e-6
    # only the last second counts: a ringing that died 2 s after the tap is no vibration
    t, x = _record(300e-6, 25.0)
    x[t >= TAP.duration_s - 1.0] = 4e-4
    assert not tap.tap_point_of(2400.0, t, x, RATE).vibrates


def test_a_wall_vibrates_when_the_hand_would_feel_it() -> None:
    """The criterion is perceptual (thesis 6.2: a user judged it): a 25 Hz oscillation of 15 um
    peak is below the hand's detection threshold (20 um up to 40 Hz), one of 30 um above; the
    Pacinian channel feels far smaller motion near 250 Hz (0.5 um), less again at 500 Hz."""
    t, x = _record(15e-6, 25.0)
    assert not tap.tap_point_of(2400.0, t, x, RATE).vibrates
    t, x = _record(30e-6, 25.0)
    assert tap.tap_point_of(2400.0, t, x, RATE).vibrates
    assert detection_threshold_m(10.0) == detection_threshold_m(40.0) == 20e-6
    assert detection_threshold_m(250.0) < detection_threshold_m(500.0) < detection_threshold_m(80.0)
    assert detection_threshold_m(250.0) == np.float64(20e-6 * (40.0 / 250.0) ** 2)
    assert felt(1e-6, 250.0) and not felt(1e-6, 25.0)


def _sweep(mode: str, kf: float, vibrating: dict[float, bool]) -> list[TapPoint]:
    return [TapPoint(w, 3e-4 if v else 0.0, 25.0, v) for w, v in vibrating.items()]


def test_the_first_vibrating_wall_and_the_checks() -> None:
    points = {
        ("OL", 0.0): _sweep("OL", 0.0, {3200.0: False, 2400.0: False}),
        ("CL", 2.0): _sweep("CL", 2.0, {800.0: False, 3200.0: False}),
        ("DOB", 100.0): _sweep(
            "DOB", 100.0, {3600.0: True, 2400.0: False, 2800.0: True, 3200.0: True}
        ),
    }
    taps = tap.tap_sweeps(points)
    assert [t.controller for t in taps] == ["OL", "CL Kf=2", "DOB Kf=100"]
    assert [p.wall for p in taps[0].points] == [2400.0, 3200.0]  # by wall
    assert taps[2].first_vibrating_n_per_m == 2800.0 and taps[0].first_vibrating_n_per_m is None
    quiet, dob = tap.tap_checks(taps)
    assert quiet.passed and "OL at 2400, 3200 N/m" in quiet.text
    assert dob.passed  # 2800 N/m is within 15 % of 3200
    assert "the first wall that keeps vibrating (2800 N/m; walls 2400, 2800, 3200, 3600 N/m)" in (
        dob.text
    )
    points[("DOB", 100.0)][1] = TapPoint(2400.0, 3e-4, 25.0, True)
    points[("CL", 2.0)][0] = TapPoint(800.0, 3e-4, 25.0, True)
    quiet, dob = tap.tap_checks(tap.tap_sweeps(points))
    assert not quiet.passed and not dob.passed and "(2400 N/m;" in dob.text
