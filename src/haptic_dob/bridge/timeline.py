"""Which command a driver had in force, by the driver's clock, for the bridge (``loop``).

``DriverClock`` puts each driver state's stamp on this process's monotonic clock (exactly, where
this machine's clock is the driver's); ``SentLog`` keeps the commands sent with their send
times, so the bridge can ask which was the newest sent before a driver cycle's instant.
"""

from __future__ import annotations

import math
from collections import deque


class RecentLeast:
    """The least of the values added over the last one or two blocks of ``block``."""

    def __init__(self, block: int) -> None:
        self._block = block
        self._older = self._newer = math.inf
        self._count = 0

    def add(self, value: float) -> float:
        """Add ``value``; the least now."""
        self._newer = min(self._newer, value)
        self._count += 1
        if self._count == self._block:
            self._older, self._newer, self._count = self._newer, math.inf, 0
        return self.value

    @property
    def value(self) -> float:
        return min(self._older, self._newer)


class DriverClock:
    """Where the driver's stamps fall on this process's monotonic clock.

    Given each state's receipt on the system clock (``now_ns``), a least age (receipt less
    stamp, over the last ``2 BLOCK`` states) from 0 to a period says the driver stamps on this
    machine's clock: from then on a state's instant is its stamp, put on the monotonic clock
    (``age_s``: that least age). Otherwise, or until then, it is the earliest the state could be
    heard: its stamp plus the least delay after it at which any recent state was (which takes
    up the clocks' offset; ``age_s`` NaN).

    A command counts from the driver's cycle whose instant it was sent before, not from the
    first state this process handled after it: a state can wait in the queue while this
    process is held up, and the command sent meanwhile is late for its cycle."""

    BLOCK = 500  # states

    def __init__(self, period_s: float) -> None:
        self._period_s = period_s
        self._origin_ns: int | None = None
        self._delay = RecentLeast(self.BLOCK)  # s, on the monotonic clock (takes up an offset)
        self._age = RecentLeast(self.BLOCK)  # s, receipt less stamp on the system clock
        self.one_clock = False  # the driver stamps on this machine's clock

    def heard(self, stamp_ns: int, now: float, now_ns: int | None = None) -> float:
        """State ``stamp_ns`` heard at monotonic ``now`` (s), system ``now_ns``: its instant
        (monotonic s)."""
        if self._origin_ns is None:
            self._origin_ns = stamp_ns
        t = (stamp_ns - self._origin_ns) * 1e-9
        least = self._delay.add(now - t)
        if now_ns is None:
            return t + least
        age = self._age.add((now_ns - stamp_ns) * 1e-9)
        self.one_clock = self.one_clock or 0.0 <= age < self._period_s
        if not self.one_clock:
            return t + least
        return now - (now_ns - stamp_ns) * 1e-9  # the stamp on the monotonic clock

    @property
    def age_s(self) -> float:
        """The least age (s) of a state on arrival; NaN unless the clocks are one."""
        return self._age.value if self.one_clock else math.nan


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
