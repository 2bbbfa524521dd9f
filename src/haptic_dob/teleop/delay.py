"""One direction of the teleoperation channel, at its receiving end: delay, jitter, loss, counted
in samples, and the watchdog that tells a silent peer.

The receiver decides every message's fate as it is handed over (``push``, in the order of the
messages' stamps): lost, or due at sample ``j + delay + u`` with ``u`` drawn from
``[0, jitter]`` (``j`` the message's own sample, counted from the sender's first:
``SampleClock``). ``take(k)`` then gives the newest message due by
sample ``k``. The draws come from the receiver's own seeded generator, one pair per message, so a
batch run and a node graph that hand over the same messages see the same channel, bit for bit.
In lockstep a receiver must have been handed every message that can be due by ``k`` (those of
samples up to ``k - delay``) before it takes: ``complete(k)``.

The watchdog (``haptic_dob.core.watchdog``) counts the samples since the newest arrival: the peer is
lost when nothing arrived for more than ``timeout_s`` of sample time.
"""

from __future__ import annotations

import heapq
import random
from collections.abc import Callable
from typing import Generic, TypeVar

from haptic_dob.core.watchdog import CommandWatchdog
from haptic_dob.teleop.settings import ChannelSettings

M = TypeVar("M")


def _quiet(*_args: str) -> None:
    """Report nowhere."""


class SampleClock:
    """One device's sample indices from its stamps: the whole periods since its first stamp
    (the nearest: a real-time device stamps each sample with the system clock when it takes
    it, a period apart give or take its wake-up jitter; lockstep stamps are ``k * T``)."""

    def __init__(self, period_ns: int) -> None:
        self.period_ns = period_ns
        self.origin_ns: int | None = None  # the first stamp: sample 0

    def index(self, stamp_ns: int) -> int:
        """The sample index of stamp ``stamp_ns`` (ns)."""
        if self.origin_ns is None:
            self.origin_ns = stamp_ns
        return (stamp_ns - self.origin_ns + self.period_ns // 2) // self.period_ns


class DelayLine(Generic[M]):
    """The receiving end of one direction of the channel (messages of type ``M``).

    Args:
        settings: delay, jitter, loss, seed, cut and timeout.
        period_ns: the sample period (ns).
        salt: told apart the two directions' generators (0 master to slave, 1 back).
        lost, back: called when the peer falls silent (with how long) and when it is back.
    """

    def __init__(
        self,
        settings: ChannelSettings,
        period_ns: int,
        salt: int,
        lost: Callable[[str], None] = _quiet,
        back: Callable[[], None] = _quiet,
    ) -> None:
        self.period_ns = period_ns
        self.sender = SampleClock(period_ns)  # the sender's sample indices
        self.delay = settings.delay_samples(period_ns)
        self.jitter = settings.jitter_samples(period_ns)
        self.loss = settings.loss
        self.cut = settings.cut_sample(period_ns)
        self.timeout_s = settings.timeout_s
        self._rng = random.Random(settings.seed * 2 + salt)
        self._pending: list[tuple[int, int, M]] = []  # (due sample, sample, message)
        self.newest: M | None = None  # the newest message that arrived
        self.newest_j = -1  # its sample
        self.pushed_j = -1  # the sample of the newest message handed over
        self.dropped = 0
        self.watchdog = CommandWatchdog(period_ns, lost, back)
        # the first message is due at sample ``delay``: the silence counts from there
        self.watchdog.last_command_k = self.delay

    def push(self, stamp_ns: int, message: M) -> None:
        """Hand over the message of sample ``stamp_ns`` (stamps in increasing order)."""
        j = self.sender.index(stamp_ns)
        if j <= self.pushed_j:
            return  # a repeated sample (lockstep re-send): decided already
        self.pushed_j = j
        u = self._rng.randint(0, self.jitter) if self.jitter else 0
        lost = self.loss > 0.0 and self._rng.random() < self.loss
        if lost or (self.cut is not None and j >= self.cut):
            self.dropped += 1
            return
        heapq.heappush(self._pending, (j + self.delay + u, j, message))

    def complete(self, k: int) -> bool:
        """Every message that can be due by sample ``k`` has been handed over (lockstep)."""
        return self.pushed_j >= k - self.delay or (
            self.cut is not None and k - self.delay >= self.cut
        )

    def take(self, k: int) -> M | None:
        """The newest message due by sample ``k`` (None before the first); feeds the watchdog."""
        pending = self._pending
        arrived = False
        while pending and pending[0][0] <= k:
            _, j, message = heapq.heappop(pending)
            arrived = True
            if j > self.newest_j:
                self.newest_j, self.newest = j, message
        if arrived:
            self.watchdog.fed(k)
        return self.newest

    def silent(self, k: int) -> bool:
        """The peer counts as lost at sample ``k`` (nothing arrived for ``timeout_s``)."""
        return self.watchdog.due(k, self.timeout_s)
