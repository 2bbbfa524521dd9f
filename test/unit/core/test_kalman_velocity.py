"""The steady-state Kalman velocity filter and its jerk density's identification.

Identities between algorithms: the steady gain is the Riccati recursion's limit; the record's
innovations by ``lfilter`` are the per-sample filter's; the filter tracks a parabola exactly;
maximum likelihood finds the density that generated a record."""

from __future__ import annotations

import numpy as np
import pytest

from haptic_dob.core.kalman_velocity import (
    KalmanState,
    innovations,
    process_noise,
    steady_gain,
    transition,
)
from haptic_dob.identification.filters import IdentificationError
from haptic_dob.identification.velocity_noise import identify_jerk_psd

DT = 0.002  # 500 Hz
COUNT = 4e-4  # a Touch's joint (rad)


def test_the_steady_gain_is_the_recursions_limit() -> None:
    """The time-varying filter from a wide prior, 3000 samples on, has the DARE's gain and
    innovation variance."""
    psd = 700.0
    F, Q, R = transition(DT), process_noise(psd, DT), COUNT**2 / 12.0
    P = np.diag([1.0, 1e2, 1e4])
    for _ in range(3000):
        P = F @ P @ F.T + Q  # prior
        s = P[0, 0] + R
        k = P[:, 0] / s
        P = P - np.outer(k, P[0, :])
    g = steady_gain(psd, COUNT, DT)
    np.testing.assert_allclose(g.gain, k, rtol=1e-9)
    assert g.innovation_var == pytest.approx(s, rel=1e-9)


def test_the_records_innovations_are_the_per_sample_filters() -> None:
    """``innovations`` (``lfilter``) against ``KalmanState.update`` on one record of counts."""
    rng = np.random.default_rng(1)
    y = COUNT * np.round(np.cumsum(np.cumsum(rng.normal(0.0, 1e-3, 2000))) * DT / COUNT) + 0.3
    g = steady_gain(300.0, COUNT, DT)
    f = KalmanState(g, y[0])
    by_sample = np.array([f.update(DT, v) for v in y[1:]])
    np.testing.assert_allclose(innovations(y, g), by_sample, rtol=0.0, atol=1e-12)


def test_it_tracks_a_parabola_exactly() -> None:
    """Constant acceleration is the model's own motion: once settled, the velocity is exact."""
    g = steady_gain(1000.0, COUNT, DT)
    t = np.arange(3000) * DT
    q = 0.1 + 0.4 * t - 1.5 * t * t
    f = KalmanState(g, q[0])
    v = [(f.update(DT, y), f.qd)[1] for y in q[1:]]
    np.testing.assert_allclose(v[-500:], (0.4 - 3.0 * t[1:])[-500:], rtol=0.0, atol=1e-9)


def white_jerk_record(psd: float, n: int, seed: int) -> np.ndarray:
    """``n`` samples of the model's own motion (white jerk of density ``psd``), read to
    ``COUNT``."""
    rng = np.random.default_rng(seed)
    F, L = transition(DT), np.linalg.cholesky(process_noise(psd, DT))
    x, q = np.zeros(3), np.empty(n)
    for k in range(n):
        x = F @ x + L @ rng.standard_normal(3)
        q[k] = x[0]
    return COUNT * np.round(q / COUNT)


@pytest.mark.parametrize("psd", [100.0, 1000.0, 10000.0])
def test_maximum_likelihood_finds_the_density_that_made_the_record(psd: float) -> None:
    """20 s of the model's own motion (white jerk), read to 4e-4 rad counts: the fit within
    15 %, 2.6 standard deviations of the estimate or more (over 12 seeds: biased 0.6 % at most,
    standard deviations 5.7, 4.6, 2.8 %; here 5.3, 5.1, 7.7 % off)."""
    y = white_jerk_record(psd, 10000, int(psd))
    stamps = np.arange(len(y), dtype=np.int64) * 2_000_000
    fit = identify_jerk_psd(stamps, y[:, None], ["j"], [COUNT])
    assert fit.psd == pytest.approx(psd, rel=0.15)
    assert fit.fitted == ("j",) and fit.period_s == pytest.approx(DT)


def test_a_record_that_loses_states_is_fitted_over_its_runs() -> None:
    """The same record with a state lost every 0.6 s (a best-effort stream on a busy machine):
    no run reaches a second, yet the runs' 13 s after their settling find the density within
    15 % as the whole record does."""
    y = white_jerk_record(1000.0, 10000, 1000)
    stamps = np.arange(len(y), dtype=np.int64) * 2_000_000
    kept = np.ones(len(y), dtype=bool)
    kept[150::300] = False
    fit = identify_jerk_psd(stamps[kept], y[kept, None], ["j"], [COUNT])
    assert fit.psd == pytest.approx(1000.0, rel=0.15)


def test_a_record_held_still_at_its_start_is_fitted_over_its_motion() -> None:
    """The same record after 2 s held still (a Touch in its inkwell before the user takes the
    stylus): the still stretch is left out, and the fit is the motion's alone (within 2 %;
    fitted with it, the still samples' zero innovations pulled it 10 % down: 858 for 949)."""
    y = white_jerk_record(1000.0, 10000, 1000)
    held = np.concatenate([np.zeros(1000), y])
    stamps = np.arange(len(held), dtype=np.int64) * 2_000_000
    alone = identify_jerk_psd(stamps[: len(y)], y[:, None], ["j"], [COUNT])
    fit = identify_jerk_psd(stamps, held[:, None], ["j"], [COUNT])
    assert fit.psd == pytest.approx(alone.psd, rel=0.02)


def test_a_record_without_motion_or_too_short_is_refused() -> None:
    stamps = np.arange(2000, dtype=np.int64) * 2_000_000
    still = np.zeros((2000, 2))
    still[:, 1] = COUNT * (np.arange(2000) // 400 % 2)  # one count back and forth
    with pytest.raises(IdentificationError, match="no joint moved 10 counts"):
        identify_jerk_psd(stamps, still, ["a", "b"], [COUNT, COUNT])
    y = white_jerk_record(1000.0, 2000, 7)[:, None]
    with pytest.raises(IdentificationError, match=r"hold 0\.8 s after .* needs 1 s"):
        identify_jerk_psd(stamps[:500], y[:500], ["j"], [COUNT])
    lossy = np.delete(stamps, np.arange(100, 2000, 200))  # a state lost every 0.4 s
    with pytest.raises(IdentificationError, match=r"hold 0 s after"):
        identify_jerk_psd(lossy, y[: len(lossy)], ["j"], [COUNT])
    parked = np.concatenate([y[:400], np.full((1600, 1), y[399, 0])])  # moved 0.8 s, then held
    with pytest.raises(IdentificationError, match=r"device moving hold 0\.6 s after"):
        identify_jerk_psd(stamps, parked, ["j"], [COUNT])
    moving = np.column_stack([COUNT * np.round(np.linspace(0.0, 0.2, 2000) / COUNT)])
    with pytest.raises(IdentificationError, match=r"j steps by 0\.0004, under half the count"):
        identify_jerk_psd(stamps, moving, ["j"], [1e-3])
    with pytest.raises(ValueError, match="count must be a positive number"):
        steady_gain(100.0, 0.0, DT)
