"""Velocity from positions alone: the adaptive window, the low-pass, the Kalman filter
(``bridge.velocity``).

Identities: on a straight line the window is the line's slope exactly, whatever the stamps'
jitter; after a kink it holds only the samples on the new line. On coarse counts each is what
it is for: the window less noisy than the low-pass for the same motion, the Kalman filter (its
density identified from the counts) less wrong than the window without delay."""

from __future__ import annotations

import numpy as np
import pytest

from haptic_dob.bridge.driver_settings import FrameSettings
from haptic_dob.bridge.state import StateReader
from haptic_dob.bridge.state_settings import StateSettings
from haptic_dob.bridge.velocity import KalmanVelocity, Velocity, VelocityFilter, WindowVelocity
from haptic_dob.core.kalman_velocity import KalmanState, steady_gain
from haptic_dob.identification.velocity_noise import identify_jerk_psd

T_NS = 2_000_000  # 500 Hz


def stamps(n: int, jitter_ns: int = 0, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.arange(n) * T_NS + rng.integers(-jitter_ns, jitter_ns + 1, n)


def test_on_a_line_the_window_is_its_slope_whatever_the_stamps() -> None:
    """Jittered stamps of the wall clock (1.8e18 ns: in float seconds their differences would
    keep only 0.2 us)."""
    w = WindowVelocity([4e-4, 1e-3], 8, 0.01)
    t0 = 1_795_000_000 * 10**9
    t = stamps(40, jitter_ns=300_000)
    v = np.array([0.3, -1.7])
    out = [w.update(t0 + int(s), tuple(0.01 + v * s * 1e-9)) for s in t]
    assert out[0] == (0.0, 0.0)
    np.testing.assert_allclose(out[1:], np.tile(v, (39, 1)), rtol=1e-9)


def test_after_a_kink_the_window_holds_only_the_new_line() -> None:
    """Still, then 0.5 rad/s from sample 20: two samples on, the window is the new slope (a
    fixed 8-sample fit would still be at 3/8 of it); a count of 4e-4 rad, no quantization."""
    w = WindowVelocity([4e-4], 8, 0.01)
    q = [0.0 if k <= 20 else 0.5 * (k - 20) * T_NS * 1e-9 for k in range(30)]
    out = [w.update(k * T_NS, (q[k],))[0] for k in range(30)]
    assert out[20] == 0.0
    # 1 ms of 0.5 rad/s is 5e-4 rad off the still line: out of every window that spans it
    assert out[22] == pytest.approx(0.5, rel=1e-9)
    assert out[29] == pytest.approx(0.5, rel=1e-9)


COUNT = 4e-4  # a Touch's joint (rad)


def random_motion(accel_rad_s2: float, n: int = 5000) -> tuple[np.ndarray, np.ndarray]:
    """A joint's true velocity in random motion (acceleration held 0.1 s, no drift) and its
    positions read to ``COUNT`` every 2 ms."""
    rng = np.random.default_rng(3)
    dt = T_NS * 1e-9
    accel = np.repeat(rng.normal(0.0, accel_rad_s2, n // 50), 50)  # held 0.1 s
    v_true = np.cumsum(accel) * dt
    v_true -= np.convolve(v_true, np.ones(500) / 500, mode="same")  # no drift
    return v_true, np.round(np.cumsum(v_true) * dt / COUNT) * COUNT


def velocity_rms(got: np.ndarray, v_true: np.ndarray, lags: range) -> float:
    """The RMS error against the true velocity after 100 samples, at the best of ``lags``."""
    n = len(v_true)
    return min(float(np.sqrt(np.mean((got[100 + d :] - v_true[100 : n - d]) ** 2))) for d in lags)


def run(estimator: Velocity, counts: np.ndarray) -> np.ndarray:
    """The estimator's velocity at every sample of ``counts`` (500 Hz)."""
    return np.array([estimator.update(k * T_NS, (c,))[0] for k, c in enumerate(counts)])


@pytest.mark.parametrize("accel_rad_s2", [3.0, 1.0, 0.3, 0.1])
def test_on_coarse_counts_the_window_is_quieter_than_the_low_pass(accel_rad_s2: float) -> None:
    """A Touch's joint (4e-4 rad counts at 500 Hz) in random motion from 0.27 to 0.009 rad/s
    RMS: the window's RMS error against the true velocity is under 3/4 of the 40 Hz low-pass's
    (the config's estimator before the window), each at its best lag (measured 0.40-0.66)."""
    v_true, counts = random_motion(accel_rad_s2)
    got_w = run(WindowVelocity([COUNT], 8, 0.01), counts)
    got_f = run(VelocityFilter(40.0, 0.01), counts)
    lags = range(6)
    assert velocity_rms(got_w, v_true, lags) < 0.75 * velocity_rms(got_f, v_true, lags)


@pytest.mark.parametrize(("accel_rad_s2", "at_most"), [(3.0, 0.75), (1.0, 0.75), (0.3, 0.75)])
def test_on_coarse_counts_the_kalman_filter_is_less_wrong_than_the_window_now(
    accel_rad_s2: float, at_most: float
) -> None:
    """The three faster of those motions, the Kalman filter's density identified from the counts
    alone (``haptic-identify --velocity-noise``'s fit): its error at the sample (what the
    observer takes) under 3/4 of the window's (measured 0.66, 0.67, 0.44), and no worse than
    the window's at the window's best lag (0.99, 0.75, 0.43 of it). The slowest (0.009 rad/s
    RMS, under a count a sample) gains nothing: ``test_..._slowest_motion``."""
    v_true, counts = random_motion(accel_rad_s2)
    stamps = np.arange(len(counts), dtype=np.int64) * T_NS
    psd = identify_jerk_psd(stamps, counts[:, None], ["j"], [COUNT]).psd
    got_k = run(KalmanVelocity([COUNT], [psd], T_NS * 1e-9, 0.01), counts)
    got_w = run(WindowVelocity([COUNT], 8, 0.01), counts)
    now = range(1)
    assert velocity_rms(got_k, v_true, now) < at_most * velocity_rms(got_w, v_true, now)
    assert velocity_rms(got_k, v_true, now) <= velocity_rms(got_w, v_true, range(6))


def test_on_the_slowest_motion_the_kalman_filter_is_the_windows_equal() -> None:
    """0.009 rad/s RMS, a count every 20 samples or so: the rounding is no white noise there,
    and the fitted filter is as wrong as the window, within 1 % (measured 1.00)."""
    v_true, counts = random_motion(0.1)
    stamps = np.arange(len(counts), dtype=np.int64) * T_NS
    psd = identify_jerk_psd(stamps, counts[:, None], ["j"], [COUNT]).psd
    got_k = run(KalmanVelocity([COUNT], [psd], T_NS * 1e-9, 0.01), counts)
    got_w = run(WindowVelocity([COUNT], 8, 0.01), counts)
    now = range(1)
    assert velocity_rms(got_k, v_true, now) <= 1.01 * velocity_rms(got_w, v_true, now)


def test_the_kalman_filter_per_joint_is_the_cores_and_starts_again_after_a_gap() -> None:
    """Two joints, each its own gain; the same positions through ``KalmanState``; a 20 ms gap
    (past max_gap_s) or a repeated stamp starts from zero velocity at that sample."""
    k = KalmanVelocity([4e-4, 1e-3], [500.0, 50.0], 0.002, 0.01)
    g = [steady_gain(500.0, 4e-4, 0.002), steady_gain(50.0, 1e-3, 0.002)]
    q = [(0.001 * i, -0.003 * i) for i in range(50)]
    ref = [KalmanState(gj, qj) for gj, qj in zip(g, q[0], strict=True)]
    assert k.update(0, q[0]) == (0.0, 0.0)
    for i in range(1, 50):
        got = k.update(i * T_NS, q[i])
        for f, y in zip(ref, q[i], strict=True):
            f.update(0.002, y)
        assert got == (ref[0].qd, ref[1].qd)
    assert k.update(49 * T_NS, (0.0, 0.0)) == (0.0, 0.0)  # the same stamp
    assert k.update(50 * T_NS, (0.002, 0.0))[0] > 0.0
    assert k.update(50 * T_NS + 20_000_000, (0.0, 0.0)) == (0.0, 0.0)  # the gap


def test_a_gap_or_a_repeated_stamp_starts_again() -> None:
    w = WindowVelocity([1e-3], 4, 0.01)
    for k in range(5):
        w.update(k * T_NS, (0.001 * k,))
    assert w.update(5 * T_NS, (0.005,))[0] == pytest.approx(0.5)
    assert w.update(5 * T_NS, (0.006,)) == (0.0,)  # the same stamp: from zero
    assert w.update(6 * T_NS, (0.007,))[0] == pytest.approx(0.5)
    t = 6 * T_NS + 20_000_000
    assert w.update(t, (0.0,)) == (0.0,)  # 20 ms gap past max_gap_s
    assert w.update(t + T_NS, (0.0,)) == (0.0,)  # nothing from before the gap is kept


def test_the_band_is_half_each_joints_count_and_the_window_its_whole_length() -> None:
    """Joint a (count 1e-3): samples 0, 0, 0, 1e-3, newest last. The 3-sample line leaves them
    1/6, 1/3, 1/6 of a count off, the 4-sample line 0.2, 0.1, 0.4, 0.3: both inside half, so
    the slope is the 4-sample one, 0.3 counts a period. Joint b, the same positions with a count
    of 5e-4: the 3-sample line is out already, so the backward difference, 1e-3 a period. With
    at most 2 intervals, joint a's window is the 3-sample one (0.5e-3 a period)."""
    up = [(0.0, 0.0), (0.0, 0.0), (0.0, 0.0), (1e-3, 1e-3)]
    w = WindowVelocity([1e-3, 5e-4], 3, 0.01)
    got = [w.update(k * T_NS, q) for k, q in enumerate(up)][-1]
    period = T_NS * 1e-9
    assert got[0] == pytest.approx(0.3e-3 / period) and got[1] == pytest.approx(1e-3 / period)
    w2 = WindowVelocity([1e-3], 2, 0.01)
    got2 = [w2.update(k * T_NS, (q[0],)) for k, q in enumerate(up)][-1]
    assert got2[0] == pytest.approx(0.5e-3 / period)


def reader(**state: object) -> StateReader:
    settings = StateSettings(**{"topic": "t", "velocity": "difference", **state})  # type: ignore[arg-type]
    return StateReader(settings, FrameSettings(), ("a", "b", "c"), 0.002)


def test_the_settings_choose_the_estimator() -> None:
    assert isinstance(reader().velocity, VelocityFilter)
    assert isinstance(reader(encoder_resolution=[4e-4]).velocity, WindowVelocity)
    np.testing.assert_allclose(
        reader(encoder_resolution=[1e-4, 2e-4, 3e-4]).velocity.half,  # type: ignore[attr-defined]
        [0.5e-4, 1e-4, 1.5e-4],
        rtol=1e-6,
    )
    with pytest.raises(ValueError, match="every joint's"):
        reader(encoder_resolution=[4e-4, 0.0, 4e-4])
    with pytest.raises(ValueError, match="1 or 3 values"):
        reader(encoder_resolution=[4e-4, 4e-4])
    kalman = reader(encoder_resolution=[4e-4], velocity_jerk_psd=[800.0]).velocity
    assert isinstance(kalman, KalmanVelocity)
    assert kalman.gains[0] == steady_gain(800.0, 4e-4, 0.002)  # at the driver's period
    with pytest.raises(ValueError, match="needs every joint's state\\.encoder_resolution"):
        reader(velocity_jerk_psd=[800.0])
    with pytest.raises(ValueError, match="velocity_jerk_psd: set every joint's"):
        reader(encoder_resolution=[4e-4], velocity_jerk_psd=[800.0, 0.0, 800.0])


def test_a_count_set_too_coarse_is_said_once_per_joint() -> None:
    """Set 4e-4 rad where joint b steps 1e-4 (a finer encoder, or mm read as m): one line names
    b and the step, once; joints stepping whole counts and steps of half a count say nothing."""
    r = reader(joints=["a", "b", "c"], encoder_resolution=[4e-4])
    lines = []  # as the bridge node asks, after each cycle's command
    for k, q in enumerate([(0.0, 0.0, 0.0), (4e-4, 0.0, 2e-4), (4e-4, 1e-4, 0.0), (0.0, 0.0, 0.0)]):
        r.joints(k * T_NS, ("a", "b", "c"), list(q), [], [])
        lines += r.count_warnings()
    assert len(lines) == 1 and "b stepped 0.0001" in lines[0] and "(0.0004)" in lines[0], lines
    assert reader(encoder_resolution=[0.0]).count_warnings() == []


def test_a_step_of_floating_point_rounding_is_no_count() -> None:
    """A driver that computes a joint from two others (a Touch's elbow) steps it by rounding
    now and then, 5.55e-17 rad between equal counts: said nothing (it once was)."""
    count = 8e-4
    a, b = 0.1 + 0.2, 0.3  # equal in counts, apart in the last bit
    assert a != b
    for kalman in ({}, {"velocity_jerk_psd": [800.0]}):  # the window, the Kalman filter
        r = reader(joints=["a", "b", "c"], encoder_resolution=[count], **kalman)
        lines = []
        for k, q in enumerate([a, b, a, b + count]):
            r.joints(k * T_NS, ("a", "b", "c"), [q, 0.0, 0.0], [], [])
            lines += r.count_warnings()
        assert lines == [], lines


def test_with_the_kalman_filter_a_count_set_too_coarse_is_said_too() -> None:
    """The filter takes the count as its noise: a joint stepping under half of it is named
    once, as with the window."""
    r = reader(joints=["a", "b", "c"], encoder_resolution=[4e-4], velocity_jerk_psd=[800.0])
    lines = []
    for k, q in enumerate([(0.0, 0.0, 0.0), (4e-4, 1e-4, 0.0), (0.0, 0.0, 0.0), (0.0, 1e-4, 0.0)]):
        r.joints(k * T_NS, ("a", "b", "c"), list(q), [], [])
        lines += r.count_warnings()
    assert len(lines) == 1 and "b stepped 0.0001" in lines[0], lines
