"""The hand's reference motion: generated block by block, the same whatever the block length."""

from __future__ import annotations

import numpy as np
import pytest

from haptic_sim.hand import BLOCK_S, HandParams, HandReference, depth_reference

DT_S = 1e-4  # the slide's physics step at 1 kHz control, 10 substeps


def _samples(params: HandParams, block_s: float, n: int, ahead: int = 0) -> np.ndarray:
    """(n, 3) position, velocity, feed-forward force of a seeded reference read sample by sample;
    with ``ahead``, each read is preceded by ``prepare`` of the sample that many later."""
    ref = HandReference(params, DT_S, np.random.default_rng(7), block_s=block_s)
    out = np.empty((n, 3))
    for i in range(n):
        if ahead:
            ref.prepare(i + ahead)
        x, v, f, j = ref.arrays(i)
        out[i] = x[j], v[j], f[j]
    return out


@pytest.mark.parametrize(
    "params",
    [
        HandParams(behaviour="semi_random"),
        HandParams(behaviour="push_hold", perturbation_n=1.0, perturbation_at_s=0.5),
    ],
    ids=["semi_random", "push_hold"],
)
@pytest.mark.parametrize("block_s", [1.0, 0.0137, 1e-4])
def test_the_block_length_changes_no_sample(params: HandParams, block_s: float) -> None:
    """Short blocks (a real-time device fills one inside a period) give the one-block samples."""
    n = 25_000  # 2.5 s: crosses blocks of every length above, the ramp and the pulse
    reference = _samples(params, 10.0, n)  # one block holds the whole run
    got = _samples(params, block_s, n)
    assert np.array_equal(got, reference)
    assert np.array_equal(_samples(params, BLOCK_S, n), reference)
    assert np.ptp(reference[:, 0]) > 0.0  # the comparison is not between two zero signals


@pytest.mark.parametrize("ahead", [1, 9, 999, 1000, 5000])
def test_preparing_ahead_changes_no_sample(ahead: int) -> None:
    """A device generates the next block early (``prepare``) while it waits: same samples, also
    when it asks for a sample further ahead than one block (which prepares nothing)."""
    params = HandParams(behaviour="semi_random")
    n = 5_000
    block_s = 1000 * DT_S
    reference = _samples(params, 10.0, n)
    assert np.array_equal(_samples(params, block_s, n, ahead=ahead), reference)


def test_prepare_generates_the_next_block_early() -> None:
    """After ``prepare``, reading into the next block generates nothing more."""
    ref = HandReference(HandParams(), DT_S, np.random.default_rng(7), block_s=1000 * DT_S)
    ref.prepare(1000)
    rng_state = ref._rng.bit_generator.state
    ref.arrays(1500)
    assert ref._rng.bit_generator.state == rng_state  # no random numbers drawn on the read
    ref.arrays(2000)
    assert ref._rng.bit_generator.state != rng_state  # the block after was not prepared


def _psd(params: HandParams, seconds: float = 60.0) -> tuple[np.ndarray, np.ndarray]:
    """Welch PSD of the reference's motion (ramp left out) at 1 kHz."""
    from scipy import signal

    ref = HandReference(params, 1e-3, np.random.default_rng(3), block_s=seconds)
    x = ref.arrays(0)[0]
    f, p = signal.welch(x[2000:] - np.mean(x[2000:]), fs=1000.0, nperseg=8000)
    return f, p


def test_the_roll_off_takes_the_motion_above_it_and_keeps_its_std() -> None:
    """A 2nd-order roll-off at 5 Hz: above it the reference has a fraction of the flat band's
    motion (at 8-10 Hz, (5/9)^4 of it or less), below it about the same; the std is still
    ``amplitude_m``."""
    flat = HandParams(rolloff_hz=0.0, ramp_s=0.0)
    rolled = HandParams(rolloff_hz=5.0, ramp_s=0.0)
    f, p_flat = _psd(flat)
    _, p_roll = _psd(rolled)
    high = (f >= 8.0) & (f <= 10.0)
    low = (f >= 0.2) & (f <= 2.0)
    ratio_high = np.sum(p_roll[high]) / np.sum(p_roll[low])
    ratio_flat = np.sum(p_flat[high]) / np.sum(p_flat[low])
    assert ratio_high < (5.0 / 9.0) ** 4 * ratio_flat
    ref = HandReference(rolled, 1e-3, np.random.default_rng(3), block_s=60.0)
    x = ref.arrays(0)[0]
    assert np.std(x) == pytest.approx(rolled.amplitude_m, rel=0.1)


def test_the_depth_reference_pushes_half_the_force_at_the_stiffest_wall_and_keeps_contact() -> None:
    """``depth_reference``: the push at the stiffest wall is half the actuator's force, the force
    swing there is at most a sixth of it (3 sigma to each limit), and at every wall the position's
    std is at most a third of its mean depth, one of the two limits binding."""
    walls = (80.0, 800.0, 1600.0, 2400.0)
    ref = depth_reference(HandParams(), walls, 0.4193, 1.273, 4.0)
    assert ref.push_n[2400.0] == pytest.approx(2.0)
    assert ref.swing_n[2400.0] <= 2.0 / 3.0 + 1e-12
    assert max(ref.depth_std_ratio.values()) <= 1.0 / 3.0 + 1e-12
    binds = max(ref.depth_std_ratio.values()) == pytest.approx(1.0 / 3.0) or ref.swing_n[
        2400.0
    ] == pytest.approx(2.0 / 3.0)
    assert binds
    # the push rises with the wall: a depth, not a force
    pushes = [ref.push_n[w] for w in walls]
    assert pushes == sorted(pushes) and pushes[0] < 0.25 * pushes[-1]


def test_the_configs_hand_is_the_depth_rule_to_the_digits_it_states() -> None:
    """``config/slide_sim.yaml``'s hand reference is ``depth_reference`` for chapter 7's walls,
    the observer's model and the actuator's limit (5 significant digits), and the dataclass
    defaults are the same hand."""
    from haptic_sim.experiments.plan import CH7_WALLS
    from haptic_sim.slide.session import SessionConfig
    from support.paths import ROOT

    cfg = SessionConfig.from_yaml(ROOT / "config" / "slide_sim.yaml")
    m = cfg.model
    ref = depth_reference(
        cfg.hand, tuple(CH7_WALLS), m.mass_kg, m.viscous_n_s_per_m, cfg.device.max_force_n
    )
    stated = (cfg.hand.offset_m, cfg.hand.amplitude_m)
    assert (float(f"{ref.offset_m:.5g}"), float(f"{ref.amplitude_m:.5g}")) == stated
    assert HandParams() == cfg.hand
