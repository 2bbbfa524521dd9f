"""The answer floor's count (``answer_floor.count``): on time is received before the next
instant, strictly; unanswered states count against it; the warm-up is left out."""

from __future__ import annotations

import pytest

from haptic_dob.runtime.ros.answer_floor import count

P = 1_000_000  # ns


def test_an_answer_at_the_next_instant_is_late_and_one_ns_before_is_on_time() -> None:
    sent = {k: 10 + k * P for k in range(40)}
    got = {k: (k + 1) * P - 1 for k in range(40)}  # each 1 ns before its next instant
    got[30] = 31 * P  # at the instant: late
    del got[35]  # never answered
    floor = count(sent, got, 0, P)
    assert floor.states == 38  # 5 % of 40 left out: states 2-39
    assert floor.on_time_pct == pytest.approx(100.0 * 36 / 38)
    assert floor.answered_pct == pytest.approx(100.0 * 37 / 38)


def test_instants_skipped_by_an_overrun_are_not_counted() -> None:
    sent = {k: k * P for k in (*range(20), *range(25, 45))}  # 20-24 skipped
    got = {k: t + 100_000 for k, t in sent.items()}
    floor = count(sent, got, 0, P)
    assert floor.states == 38 and floor.on_time_pct == 100.0
    assert floor.latency_p50_us == pytest.approx(100.0)


def test_nothing_answered_is_an_error() -> None:
    with pytest.raises(RuntimeError, match="no answer"):
        count({k: k * P for k in range(10)}, {}, 0, P)
