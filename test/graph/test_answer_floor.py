"""The on-time floor (``runtime.ros.answer_floor``) counts what the bridge benchmark counts: an
answer is on time when DDS received it in the driver's process before the next instant."""

from __future__ import annotations

from haptic_dob.runtime.ros.answer_floor import answer_floor
from support.rosgraph import random_domain

RATE_HZ = 200.0  # a slow rate: the test asks nothing of this machine's real time
SECONDS = 1.5


def test_a_prompt_answerer_is_on_time() -> None:
    """No work at 200 Hz: the answers (a hop or two, well under the 5 ms period) are on time."""
    floor = answer_floor(RATE_HZ, SECONDS, domain_id=random_domain())
    assert floor.states >= 0.8 * RATE_HZ * SECONDS  # the warm-up left out, an overrun skipped
    assert floor.answered_pct > 99.0
    assert floor.on_time_pct > 50.0
    assert 0.0 < floor.latency_p50_us <= floor.latency_p99_us < 1e6 / RATE_HZ * 100


def test_a_loop_slower_than_the_period_is_never_on_time() -> None:
    """1.5 periods of work before each answer: every answer comes after the next instant,
    however fast DDS is (a floor counting the answers at all would pass each one)."""
    period_us = 1e6 / RATE_HZ
    floor = answer_floor(RATE_HZ, SECONDS, (1.5 * period_us, 0.0), domain_id=random_domain())
    assert floor.answered_pct > 0.0
    assert floor.on_time_pct == 0.0
    assert floor.latency_p50_us > period_us
