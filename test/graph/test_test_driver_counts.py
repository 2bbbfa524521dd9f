"""The test drivers count a loop that falls behind as late, not as the session's end: a state
unanswered by its next instant is late once the loop answers it or a newer one; only the states
after the loop's last answer are its end (``ticks_after_last_command``)."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from support.drivers.node import DriverNode
from support.rosgraph import private_context


@pytest.fixture
def context():
    with private_context() as ctx:
        yield ctx


def test_a_late_answer_makes_the_states_up_to_it_late(context, tmp_path: Path) -> None:
    """State 0 answered on time, states 1-4 past their next instants unanswered, then an answer
    to state 2: states 1 and 2 are late (before: none, all four taken for the loop's end)."""
    node = DriverNode({"kind": "fd", "rate_hz": 1000.0, "out": str(tmp_path)}, context)
    zero = (0.0, 0.0, 0.0)
    try:
        first = node.deadline
        node.on_wakeup(first)
        node._got(node.tick_stamps[0], zero, time.time_ns())
        for k in range(1, 6):
            node.on_wakeup(first + k * node.period_s)
        node._got(node.tick_stamps[2], zero, time.time_ns())
        assert (node.on_time, node.late, list(node._unanswered)) == (
            1,
            2,
            node.tick_stamps[3:5],
        )
    finally:
        node.destroy_node()
