"""What the recorder did with each topic: received, written, missing stamps; its progress.

Stamps are the samples' header stamps (or the effort command's ``effort@<stamp>`` label). A
stamp two periods or more after the newest written so far counts the whole periods between as
missing (gaps): exact for lockstep stamps (``k * T``), a lower bound for a real-time device's
system-clock stamps, which may each come up to a period after their grid point. The progress is
the newest stamp written, minimum over the topics still flowing.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from haptic_msgs_py.stamps import NS_PER_S
from haptic_msgs_py.topics import PARAMETER_EVENTS

FLOWING_NS = 1_000_000_000  # a topic this far behind the newest one has stopped (ns)


@dataclass
class TopicCount:
    """What the recorder did with one topic."""

    topic: str
    typename: str
    received: int = 0
    written: int = 0
    gaps: int = 0  # stamps missing between consecutive written messages (stamped topics)
    first_ns: int | None = None  # smallest stamp written
    newest_ns: int | None = None  # largest stamp written
    durable_ns: int | None = None  # largest stamp written when the bag was last made durable

    def wrote(self, stamp_ns: int | None, period_ns: int) -> int:
        """Count a written message stamped ``stamp_ns`` (None: none); the loop period (ns)
        tells how many stamps are missing before it. Returns that number (0: none)."""
        self.written += 1
        if stamp_ns is None:
            return 0
        newest, missing = self.newest_ns, 0
        if newest is None:
            self.first_ns = self.newest_ns = stamp_ns
        elif stamp_ns > newest:
            if stamp_ns - newest >= 2 * period_ns:
                missing = (stamp_ns - newest) // period_ns - 1
                self.gaps += missing
            self.newest_ns = stamp_ns
        elif self.first_ns is not None and stamp_ns < self.first_ns:
            self.first_ns = stamp_ns
        return missing

    def gap_line(self, missing: int) -> str:
        """The line a recorder logs as soon as ``wrote`` found ``missing`` stamps missing before
        the newest one (they never reached it: lost on the way, or never sent)."""
        return (
            f"{self.topic}: {missing} stamp(s) missing before {self.newest_ns} ns "
            f"({self.gaps} in all so far)"
        )

    def log_line(self) -> str:
        """``<topic>: received N, written M[, G stamp(s) missing]``."""
        missing = f", {self.gaps} stamp(s) missing" if self.gaps else ""
        return f"{self.topic}: received {self.received}, written {self.written}{missing}"


@dataclass
class RecordingCounts:
    """The counts of every recorded topic, and the parameter snapshots written."""

    topics: list[TopicCount] = field(default_factory=list)
    snapshots: int = 0

    def add_topic(self, topic: str, typename: str) -> TopicCount:
        """Start counting ``topic`` (resolved name) of type ``typename``."""
        count = TopicCount(topic, typename)
        self.topics.append(count)
        return count

    def snapshot_written(self) -> None:
        """Count a parameter snapshot (written on ``/parameter_events`` beside the live ones)."""
        self.snapshots += 1
        for c in self.topics:
            if c.topic == PARAMETER_EVENTS:
                c.written += 1

    def progress_ns(self) -> int:
        """Newest stamp written (ns), minimum over the stamped topics that are flowing; 0 before
        the first.

        A topic counts while its newest stamp is within ``FLOWING_NS`` of the newest stamp of
        any topic: one that has stopped (its node died, or it publishes only on demand) must not
        hold a lockstep loop forever.
        """
        newest = [c.newest_ns for c in self.topics if c.newest_ns is not None]
        if not newest:
            return 0
        top = max(newest)
        return min(n for n in newest if n >= top - FLOWING_NS)

    def to_json(self) -> dict[str, Any]:
        """The counts as the bag's metadata holds them (JSON-ready)."""
        return {
            "topics": {
                c.topic: {
                    "type": c.typename,
                    "received": c.received,
                    "written": c.written,
                    "gaps": c.gaps,
                    "first_stamp_ns": c.first_ns,
                    "last_stamp_ns": c.newest_ns,
                }
                for c in self.topics
            },
            "parameter_snapshots": self.snapshots,
        }

    def table(self, path: Path, storage: str) -> str:
        """What was received and written, one line per topic, then the snapshots and the bag."""
        lines = [
            f"{'topic':<28} {'type':<34} {'received':>9} {'written':>9} {'gaps':>6}  stamps (s)"
        ]
        for c in self.topics:
            span = (
                f"{c.first_ns / NS_PER_S:.3f}-{c.newest_ns / NS_PER_S:.3f}"
                if c.first_ns is not None and c.newest_ns is not None
                else "-"
            )
            lines.append(
                f"{c.topic:<28} {c.typename:<34} {c.received:>9} {c.written:>9} {c.gaps:>6}  {span}"
            )
        lines.append(f"parameter snapshots written: {self.snapshots}")
        lines.append(f"bag: {path} ({storage})")
        return "\n".join(lines)
