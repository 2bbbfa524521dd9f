"""Which command a driver had in force, by the driver's clock, for the bridge (``loop``).

``DriverClock`` puts each driver state's stamp on this process's monotonic clock; ``SentLog``
keeps the commands sent with their send times, so the bridge can ask which was the newest sent
before a driver cycle's instant.
"""

from __future__ import annotations

import math
from collections import deque


class DriverClock:
    """Where the driver's stamps fall on this process's monotonic clock: a state's instant is
    its stamp plus the least delay after its stamp at which any state of the last ``2 BLOCK``
    was heard (a one-way hop when the driver's and this machine's clocks agree; it takes up an
    offset when they do not, and receipt stamps).

    A command counts from the driver's cycle whose instant it was sent before, not from the
    first state this process handled after it: a state can wait in the queue while this
    process is held up, and the command sent meanwhile is late for its cycle."""

    BLOCK = 500  # states

    def __init__(self) -> None:
        self._origin_ns: int | None = None
        self._older = self._newer = math.inf  # the least delay (s) in the last two blocks
        self._count = 0

    def heard(self, stamp_ns: int, now: float) -> float:
        """State ``stamp_ns`` heard at monotonic ``now`` (s): its instant (monotonic s)."""
        if self._origin_ns is None:
            self._origin_ns = stamp_ns
        t = (stamp_ns - self._origin_ns) * 1e-9
        self._newer = min(self._newer, now - t)
        self._count += 1
        if self._count == self.BLOCK:
            self._older, self._newer, self._count = self._newer, math.inf, 0
        return t + min(self._older, self._newer)


class SentLog:
    """The commands sent (the driver's elements, SI), with their monotonic send times: which
    was the newest at an instant (the ones before the log's reach: the last one it forgot)."""

    def __init__(self, zero: tuple[float, ...], size: int = 64) -> None:
        self._log: deque[tuple[float, tuple[float, ...]]] = deque(maxlen=size)
        self._before = zero

    def add(self, now: float, u: tuple[float, ...]) -> None:
        """Command ``u`` sent at monotonic ``now`` (s)."""
        if len(self._log) == self._log.maxlen:
            self._before = self._log[0][1]
        self._log.append((now, u))

    def newest_before(self, t: float) -> tuple[float, ...]:
        """The newest command sent strictly before monotonic ``t`` (s)."""
        for sent_at, u in reversed(self._log):
            if sent_at < t:
                return u
        return self._before
