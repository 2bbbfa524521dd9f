"""When the bridge starts handing the driver's states to the loop, and when its run ends.

The gate looks at the graph every ``POLL_S`` until nothing is missing (the loop's nodes up, the
bridge's publishers matched), waits ``start_delay_s`` more and looks again (entities that came
late), then opens; a run with ``duration_s`` ends that long after. Times are monotonic seconds.
"""

from __future__ import annotations

POLL_S = 0.05  # how often the gate looks at the graph again


class StartGate:
    """The start after the graph is up and settled, the end after ``duration_s`` (0: none)."""

    def __init__(self, start_delay_s: float, duration_s: float, now: float) -> None:
        self.start_delay_s = start_delay_s
        self.duration_s = duration_s
        self.poll_at = now  # when to look at the graph again (before the start)
        self.ready_since: float | None = None  # when the graph was first seen up
        self.started_at: float | None = None

    @property
    def end(self) -> float | None:
        """When the run ends (None: it does not, or has not started)."""
        if self.started_at is None or self.duration_s <= 0.0:
            return None
        return self.started_at + self.duration_s

    def look(self, now: float, waiting: str) -> bool:
        """The graph at ``now`` still waits for ``waiting`` ('' for nothing): True when the
        gate opens now."""
        self.poll_at = now + POLL_S
        if waiting:
            self.ready_since = None
        elif self.ready_since is None:
            self.ready_since = now
            self.poll_at = now + self.start_delay_s
        elif now >= self.ready_since + self.start_delay_s:
            self.started_at = now
            return True
        return False
