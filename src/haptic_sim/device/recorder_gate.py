"""Lockstep back-pressure from recorders: a recording of a lockstep run never loses a sample.

Each recorder reports the newest stamp it has written (``recorder/progress``, at least 20 times a
second), or, before it has written anything, that its readers have not all matched their writers
yet (``PROGRESS_NOT_MATCHED_NS``): the loop's topics are volatile, so the device sends sample 0
only once every recorder has said it matched (``unmatched``). The gate follows the slowest
recorder that still reports (one silent for ``stale_s`` no longer holds the loop), holds command
k while that recorder lags more than the allowed simulated time behind sample k, and at the end
of a run tells when the last sample is written (or the drain time is up).
"""

from __future__ import annotations

from enum import Enum

from haptic_msgs_py.stamps import NS_PER_S
from haptic_msgs_py.topics import PROGRESS_NOT_MATCHED_NS

RECORDER_STALE_S = 1.0  # a recorder silent this long no longer holds the loop
DRAIN_TIMEOUT_S = 10.0  # how long a finished run waits for a recorder to write its last sample


class Drain(Enum):
    """Where the end of a run stands."""

    WAITING = "waiting"  # a recorder still writes the last sample
    DONE = "done"  # written, or no recorder reports
    TIMED_OUT = "timed out"  # the drain time is up


class RecorderGate:
    """Follows the slowest reporting recorder; holds a command while it lags; drains the end."""

    def __init__(
        self, stale_s: float = RECORDER_STALE_S, drain_timeout_s: float = DRAIN_TIMEOUT_S
    ) -> None:
        self.stale_s = stale_s
        self.drain_timeout_s = drain_timeout_s
        self.written_ns: int | None = None  # newest stamp the slowest recorder has written
        self.held: list[float] | None = None  # a command waiting for the recorder
        self.drain_until: float | None = None  # monotonic s; set once the last sample went out
        self._reports: dict[str, tuple[float, int]] = {}  # name -> (monotonic s, stamp ns)
        self._matched: set[str] = set()  # recorders whose readers have matched their writers

    def report(self, name: str, stamp_ns: int, now: float) -> None:
        """Recorder ``name`` has written up to ``stamp_ns`` (reported at monotonic ``now``, s),
        or has not matched yet (``PROGRESS_NOT_MATCHED_NS``)."""
        if stamp_ns <= PROGRESS_NOT_MATCHED_NS:
            self._matched.discard(name)
            return
        self._matched.add(name)
        reports = self._reports
        reports[name] = (now, stamp_ns)
        self.written_ns = min(ns for t, ns in reports.values() if t >= now - self.stale_s)

    def unmatched(self, recorders: int) -> bool:
        """Fewer recorders have said they matched than the ``recorders`` the graph shows."""
        return len(self._matched) < recorders

    def lags(self, sample_ns: int, max_lag_s: float) -> bool:
        """A recorder reports and is more than ``max_lag_s`` (s) behind the sample's stamp."""
        if self.written_ns is None:
            return False
        return sample_ns - self.written_ns > max_lag_s * NS_PER_S

    def behind_s(self, sample_ns: int) -> float:
        """How far (s) the slowest recorder is behind the sample's stamp."""
        return (sample_ns - (self.written_ns or 0)) * 1e-9

    def hold(self, effort: list[float]) -> None:
        """Keep a command until the recorder catches up (``release``) or goes (``let_go``)."""
        self.held = effort

    def release(self, sample_ns: int, max_lag_s: float) -> list[float] | None:
        """The held command once the recorder no longer lags (None: nothing to release)."""
        if self.held is None or self.lags(sample_ns, max_lag_s):
            return None
        effort, self.held = self.held, None
        return effort

    def let_go(self) -> None:
        """The recorder stopped reporting: forget its progress and the held command (the caller
        applies it)."""
        self.written_ns = None
        self.held = None

    @property
    def draining(self) -> bool:
        """The last sample went out: the run waits for the recorder."""
        return self.drain_until is not None

    def start_drain(self, now: float) -> None:
        """The last sample went out at monotonic ``now`` (s)."""
        self.drain_until = now + self.drain_timeout_s

    def drain(self, last_ns: int, recorders: int, now: float) -> Drain:
        """Whether the run may end: ``recorders`` publishers of progress; the last sample's stamp
        ``last_ns``; monotonic ``now`` (s)."""
        if recorders == 0 or (self.written_ns is not None and self.written_ns >= last_ns):
            return Drain.DONE
        if self.drain_until is not None and now >= self.drain_until:
            return Drain.TIMED_OUT
        return Drain.WAITING
