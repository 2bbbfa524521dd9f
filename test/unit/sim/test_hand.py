"""The hand's reference motion: generated block by block, the same whatever the block length."""

from __future__ import annotations

import numpy as np
import pytest

from haptic_sim.hand import BLOCK_S, HandParams, HandReference

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
