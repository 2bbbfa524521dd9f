"""The recorder's shutdown drain: until nothing comes for a while, within its timeout."""

from __future__ import annotations

import time

from haptic_dob.recorder.drain import take_until_quiet


def test_the_drain_takes_until_quiet_within_its_timeout() -> None:
    queued = [3, 0, 2]  # messages per round, then nothing
    rounds: list[float] = []

    def take() -> int:
        rounds.append(time.monotonic())
        return queued.pop(0) if queued else 0

    start = time.monotonic()
    assert take_until_quiet(take, timeout_s=5.0, quiet_s=0.05) == 5
    assert 0.05 <= time.monotonic() - start < 2.0  # quiet for 0.05 s after the last message
    assert len(rounds) > 3
    start = time.monotonic()
    assert take_until_quiet(lambda: 1, timeout_s=0.1) > 0  # never quiet: the timeout ends it
    assert 0.1 <= time.monotonic() - start < 2.0
    assert take_until_quiet(take, timeout_s=0.0) == 0
