"""What the middleware tells the recorder about a topic's publishers, as lines worth logging.

A reliable stream that stops mid-session and resumes has usually lost its match: the DDS
participants stopped hearing each other for a lease (20 s in Fast DDS), the writer dropped the
reader, and when they match again a volatile reader gets only what is sent after
(docs/recording-and-analysis.md, "Recording sessions"). The recorder says so once the topic
has publishers again: that the samples of the gap were lost on the way, not never sent. A topic
that loses its last publisher and never gets one back (the session ended) says nothing. Samples
the middleware itself reports lost (``message_lost``) are said as they are reported.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass
class PublisherWatch:
    """One recorded topic's matched publishers (DDS ``matched`` events), and samples reported
    lost (``message_lost`` events); times on the monotonic clock (s)."""

    topic: str
    matched: int = 0  # publishers matched now
    lost_at_s: float | None = None  # when the topic lost its last publisher after data came
    rematches: int = 0  # times it had publishers again after such a loss
    lost_messages: int = 0  # samples the middleware reported lost

    def on_matched(self, current: int, now_s: float, received: int) -> str | None:
        """The topic now has ``current`` matched publishers, ``received`` messages so far: the
        line to log when it has publishers again after losing all of them mid-stream."""
        before, self.matched = self.matched, current
        if current == 0 and before > 0 and received > 0:
            self.lost_at_s = now_s
            return None
        if current > 0 and self.lost_at_s is not None:
            gone_s, self.lost_at_s = now_s - self.lost_at_s, None
            self.rematches += 1
            return (
                f"{self.topic}: publisher(s) matched again after {gone_s:.1f} s without any "
                "(what they sent meanwhile did not reach the recorder)"
            )
        return None

    def on_lost(self, total: int, change: int) -> str | None:
        """The middleware reports ``change`` more samples lost (``total`` in all): its line."""
        if change <= 0:
            return None
        self.lost_messages = total
        return f"{self.topic}: the middleware reports {change} sample(s) lost ({total} in all)"
