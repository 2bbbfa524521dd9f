"""The command guard: refusals, clipping with the one saturation, limit requests."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from haptic_dob.core.command_guard import CommandGuard
from haptic_dob.core.control import saturate


def test_a_valid_command_passes_and_an_oversized_one_is_clipped_and_counted() -> None:
    guard = CommandGuard((4.0, 2.0))
    assert guard.check((1.0, -1.0)) == [1.0, -1.0] and guard.limited == 0
    assert guard.check((5.0, -3.0)) == [4.0, -2.0] and guard.limited == 1
    assert guard.check((4.0, -2.0)) == [4.0, -2.0] and guard.limited == 1  # at the limit
    assert guard.refused == 0


@pytest.mark.parametrize(
    "bad", [(), (1.0,), (1.0, 2.0, 3.0), (math.nan, 0.0), (0.0, math.inf), (-math.inf, 0.0)]
)
def test_a_wrong_length_or_non_finite_command_is_refused(bad: tuple[float, ...]) -> None:
    guard = CommandGuard((4.0, 4.0))
    assert guard.check(bad) is None
    assert guard.refused == 1 and guard.refusing and guard.limited == 0


def test_refusals_are_reported_once_per_burst() -> None:
    heard: list[tuple[float, ...]] = []
    guard = CommandGuard((4.0,), heard.append)
    for cmd in [(math.nan,), (), (math.inf,)]:
        assert guard.check(cmd) is None
    assert len(heard) == 1 and math.isnan(heard[0][0])  # the first of the burst only
    assert guard.refused == 3 and guard.refusing
    assert guard.check((1.0,)) == [1.0] and not guard.refusing  # a valid command ends the burst
    guard.check((1.0, 2.0))
    assert len(heard) == 2 and heard[1] == (1.0, 2.0) and guard.refused == 4


def test_limits_follow_the_request_and_are_checked_against_the_saturation() -> None:
    guard = CommandGuard((4.0, 2.0))
    assert guard.limits == (4.0, 2.0)
    assert guard.limits_for([0.0]) == (4.0, 2.0)  # [0.0]: the actuator's saturation
    assert guard.limits_for([3, 2]) == (3.0, 2.0)
    with pytest.raises(ValueError, match=r"effort_limits needs 2 values \(one per joint\)"):
        guard.limits_for([1.0])
    with pytest.raises(ValueError, match=r"effort_limits\[1\] must be in \(0, 2\]"):
        guard.limits_for([1.0, 2.5])
    with pytest.raises(ValueError, match=r"effort_limits\[0\] must be in \(0, 4\]"):
        guard.limits_for([0.0, 1.0])
    guard.limits = guard.limits_for([1.0, 1.0])
    assert guard.check((3.0, -0.5)) == [1.0, -0.5] and guard.limited == 1


finite = st.floats(allow_nan=False, allow_infinity=False)


@given(
    effort=st.lists(finite, min_size=1, max_size=6),
    limits=st.lists(st.floats(min_value=1e-6, max_value=1e6), min_size=6, max_size=6),
)
def test_the_guard_clips_exactly_as_numpy_clip(effort: list[float], limits: list[float]) -> None:
    """The one saturation is bit-identical to ``np.clip`` (the sign of zero included)."""
    lim = tuple(limits[: len(effort)])
    guard = CommandGuard(lim)
    got = guard.check(tuple(effort))
    want = np.clip(np.array(effort), -np.array(lim), np.array(lim)).tolist()
    assert got == want and saturate(effort, lim) == want
    assert [math.copysign(1.0, x) for x in got] == [math.copysign(1.0, x) for x in want]
    assert guard.limited == (got != effort)


def test_saturate_takes_one_limit_or_one_per_joint_and_refuses_a_mismatch() -> None:
    assert saturate((5, -5), 4) == [4.0, -4.0]
    with pytest.raises(ValueError, match="one limit per joint"):
        saturate([1.0, 2.0], [1.0])
    with pytest.raises(ValueError, match="limit must be finite"):
        saturate([1.0], [math.inf])
