"""The bridge's count of its commands against the driver's states: on time, late, latency.

A command answering the newest state is on time when it is taken before the driver's next
instant, else late; a state that got no command before the next one is late too. Every taken
command is timed from the arrival of the state it answers (``ARRIVALS_KEPT`` kept; an older
one from the oldest kept, a lower bound). ``taken`` only notes a command: ``book`` counts it
after its send, off the command's path.
"""

from __future__ import annotations

from collections import deque

from haptic_dob.runtime.latency import LatencyHistogram

#: states whose arrival the bridge keeps for its latency: a command answering an older one is
#: timed from the oldest kept (a lower bound, as the histogram's top bin is)
ARRIVALS_KEPT = 32


class AnswerTiming:
    """Commands on time and late, and their latency (s) from their states' arrival."""

    def __init__(self) -> None:
        #: (stamp ns, monotonic arrival s) of the newest states handed on
        self._arrivals: deque[tuple[int, float]] = deque(maxlen=ARRIVALS_KEPT)
        self.latency = LatencyHistogram()  # s, state arrival -> a command for it taken
        #: the newest command taken and not yet booked: its stamp, monotonic s taken, whether
        #: it answers the newest state, and that state's deadline (monotonic s)
        self._taken: tuple[int, float, bool, float] | None = None
        self.on_time = self.late = 0

    def arrived(self, stamp_ns: int, now: float, unanswered: bool) -> None:
        """State ``stamp_ns`` handed on at monotonic ``now``; ``unanswered``: the previous
        state got no command at all (late, once any command was counted)."""
        if unanswered and self.on_time + self.late:
            self.late += 1
        self._arrivals.append((stamp_ns, now))

    def taken(self, stamp_ns: int, now: float, newest: bool, deadline: float) -> None:
        """A command for state ``stamp_ns`` taken at monotonic ``now``: ``newest`` whether it
        answers the newest state, whose next instant is ``deadline`` (monotonic s)."""
        self._taken = (stamp_ns, now, newest, deadline)

    def book(self) -> None:
        """Count the command taken last as on time or late and time it from its state's
        arrival: off the command's path, after its send (each call in books it first too)."""
        if self._taken is None:
            return
        stamp, now, newest, deadline = self._taken
        self._taken = None
        if newest:  # before the driver's next cycle, or late for it
            if now < deadline:
                self.on_time += 1
            else:
                self.late += 1
        arrived = next((t for k, t in reversed(self._arrivals) if k == stamp), None)
        if arrived is None and stamp < self._arrivals[0][0]:  # older than kept: at least this
            arrived = self._arrivals[0][1]
        if arrived is not None:  # an unlabelled command answers the newest: found too
            self.latency.add(now - arrived)


__all__ = ["ARRIVALS_KEPT", "AnswerTiming"]
