"""The tests' wait helper returns the condition's value, and gives up after its guard."""

from __future__ import annotations

import itertools

import pytest

from support.waits import wait_until


def test_returns_the_first_true_value() -> None:
    calls = itertools.count()
    assert wait_until(lambda: next(calls) >= 3 and "met", 5.0, poll_s=0.001) == "met"


def test_gives_up_with_the_last_false_value() -> None:
    assert wait_until(lambda: 0, 0.05, poll_s=0.01) == 0


def test_step_replaces_the_sleep_and_check_can_fail_early() -> None:
    steps = []
    assert wait_until(lambda: len(steps) >= 2, 5.0, step=lambda: steps.append(1))

    def dead() -> None:
        raise AssertionError("the process died")

    with pytest.raises(AssertionError, match="died"):
        wait_until(lambda: False, 5.0, check=dead)
