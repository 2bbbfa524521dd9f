"""The recorder's shutdown drain: take what is still queued until it stays quiet, or a deadline."""

from __future__ import annotations

import time
from collections.abc import Callable

QUIET_S = 0.1  # the drain ends after this long without a message (s)
IDLE_S = 0.005  # sleep between rounds that took nothing (s)


def take_until_quiet(
    take_round: Callable[[], int], timeout_s: float, quiet_s: float = QUIET_S
) -> int:
    """Call ``take_round`` (takes what is queued, returns how many) until nothing came for
    ``quiet_s`` (s), for at most ``timeout_s`` (s); returns the number taken in all."""
    deadline = time.monotonic() + timeout_s
    quiet_since = time.monotonic()
    total = 0
    while time.monotonic() < deadline:
        got = take_round()
        total += got
        if got:
            quiet_since = time.monotonic()
        elif time.monotonic() - quiet_since >= quiet_s:
            break
        else:
            time.sleep(IDLE_S)
    return total
