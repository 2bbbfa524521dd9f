"""The test drivers keep a real driver's timing when they run late: an overrun skips cycles.

Jazzy's controller manager (``overruns.manage``, on by default) moves its next cycle to the grid's
next instant after an overrun, as rclcpp's timers and rates do: no burst of states goes out to
catch up. The test drivers (``support.drivers.node``) do the same, the plant moving through the
skipped periods with the command in force (docs/devices.md, "Tests without hardware").
"""

from __future__ import annotations

from itertools import pairwise
from pathlib import Path

import pytest

from support.drivers.node import DriverNode
from support.rosgraph import private_context


@pytest.fixture
def context():
    with private_context() as ctx:
        yield ctx


@pytest.mark.parametrize("kind", ["fd", "arm", "touch"])
def test_a_late_tick_skips_the_cycles_it_missed(context, tmp_path: Path, kind: str) -> None:
    """A tick run 2.5 periods late: the two instants it missed are stepped through without a
    state, then the newest instant's state goes out (before: all three went out at once)."""
    node = DriverNode({"kind": kind, "rate_hz": 1000.0, "out": str(tmp_path)}, context)
    try:
        first = node.deadline
        node.on_wakeup(first)  # instant 0, on time
        node.on_wakeup(first + 3.5 * node.period_s)  # instants 1 and 2 overrun, 3 due
        stamps = node.tick_stamps
        assert [b - a for a, b in pairwise(stamps)] == [node.period_ns] * 3
        assert [row[2] for row in node.ticks] == [1.0, -1.0, -1.0, 1.0]  # out; skipped
        assert node.states == 2 and node.missed_ticks == 2
    finally:
        node.destroy_node()
