"""A node stopped while inputs still come works them off, bounded in samples, not in time."""

from __future__ import annotations

import time
from typing import Any, cast

from haptic_dob.runtime.ros.spin import LoopNode
from haptic_dob.runtime.ros.stop import DRAIN_QUIET_S, work_off


class Draining:
    """A node whose marker moves once per spin while ``queued`` samples last."""

    def __init__(self, queued: int, spin_s: float = 0.0) -> None:
        self.queued, self.spin_s, self.marker = queued, spin_s, 0

    def spin_once(self, timeout_sec: float = 0.0) -> None:
        if self.queued:
            time.sleep(self.spin_s)  # a slow machine: each sample takes this long
            self.queued -= 1
            self.marker += 1
        else:
            time.sleep(timeout_sec)

    def drain_marker(self) -> int:
        return self.marker


def run(node: Draining, samples: int, until_s: float = 30.0) -> int:
    nodes = cast(list[LoopNode], [cast(Any, node)])
    return work_off(node.spin_once, nodes, time.monotonic() + until_s, samples)


def test_every_queued_sample_is_answered_however_slow_each_is() -> None:
    # 300 samples at 3 ms each take 0.9 s: longer than any fixed work-off of 0.5 s
    node = Draining(300, spin_s=0.003)
    assert run(node, samples=1000) == 300 and node.queued == 0


def test_it_ends_when_the_inputs_stop() -> None:
    node = Draining(5)
    start = time.monotonic()
    assert run(node, samples=1000) == 5
    assert DRAIN_QUIET_S <= time.monotonic() - start < 20 * DRAIN_QUIET_S


def test_inputs_that_keep_coming_end_it_after_a_queue_of_samples() -> None:
    node = Draining(10**9)  # real time: the device keeps sending
    assert run(node, samples=200) == 200 and node.marker == 200
