"""The recorder's side of the start handshake: have its readers matched the loop's writers?

The loop's topics are volatile (a late ``ros2 topic echo`` sees the live stream at once, not a
replay), so a reader gets only what is sent after it has matched the writer, and a reader can
match a writer some time after that writer matched it. The device sees only its writers' side;
before it has written a loop sample, a recorder therefore reports ``PROGRESS_NOT_MATCHED_NS``
while one of its readers has matched fewer writers than its graph shows (or, for the device's
``joint_states``, none yet), and the device holds sample 0 until every recorder has matched.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from haptic_dob.recorder.counts import RecordingCounts
from haptic_msgs_py.topics import JOINT_STATES, PROGRESS_NOT_MATCHED_NS, SESSION_TOPICS


@dataclass(frozen=True)
class ReaderMatch:
    """One reader: its (resolved) topic, the writers it has matched, the writers the graph shows."""

    topic: str
    matched: int
    graph: int


def unmatched(readers: Iterable[ReaderMatch]) -> list[str]:
    """Loop topics whose reader has matched fewer writers than the graph shows; ``joint_states``
    needs one (a recorder that does not see a device yet has nothing to be matched with). Other
    topics never hold the start: a writer of one may offer a QoS the reader cannot match."""
    out = []
    for r in readers:
        name = r.topic.rsplit("/", 1)[-1]
        if name not in SESSION_TOPICS:
            continue
        need = max(r.graph, 1 if name == JOINT_STATES else 0)
        if r.matched < need:
            out.append(r.topic)
    return out


def loop_started(counts: RecordingCounts) -> bool:
    """A stamped loop sample has been written (the handshake is over)."""
    return any(
        c.newest_ns is not None and c.topic.rsplit("/", 1)[-1] in SESSION_TOPICS
        for c in counts.topics
    )


def reported_progress(
    progress_ns: int, counts: RecordingCounts, readers: Iterable[ReaderMatch]
) -> int:
    """What a recorder reports: ``progress_ns``, or ``PROGRESS_NOT_MATCHED_NS`` before the loop
    started while a reader has not matched (``readers`` is only read then)."""
    if not loop_started(counts) and unmatched(readers):
        return PROGRESS_NOT_MATCHED_NS
    return progress_ns
