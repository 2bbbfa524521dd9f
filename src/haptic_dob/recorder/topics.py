"""What the recorder records: its ``topics`` entries and each topic's subscription kind."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from enum import Enum

from haptic_msgs_py.topics import PARAMETER_EVENTS, SESSION_TOPICS
from haptic_msgs_py.wire import TYPESTORE

PARAMETER_EVENT_TYPE = "rcl_interfaces/msg/ParameterEvent"


class TopicKind(Enum):
    """Which subscription a recorded topic gets."""

    EVENTS = "events"  # /parameter_events: the parameter-events profile
    SESSION = "session"  # a loop topic: reliable, deep queue (repaired from the writers' history)
    OTHER = "other"  # reliable, volatile


@dataclass(frozen=True)
class TopicEntry:
    """One ``topics`` entry: the name as given (relative names resolve in the namespace)."""

    name: str
    typename: str

    def kind(self, resolved: str) -> TopicKind:
        """The subscription kind of this topic, resolved to ``resolved``."""
        if resolved == PARAMETER_EVENTS and self.typename == PARAMETER_EVENT_TYPE:
            return TopicKind.EVENTS
        if self.name.lstrip("/") in SESSION_TOPICS:
            return TopicKind.SESSION
        return TopicKind.OTHER


def parse_topics(entries: Sequence[str]) -> list[TopicEntry]:
    """The ``topics`` entries (``NAME`` or ``NAME:pkg/msg/Type``); ``ValueError`` naming a bad
    or unknown one."""
    out: list[TopicEntry] = []
    for entry in entries:
        name, sep, typename = entry.partition(":")
        name = name.strip()
        if not name:
            raise ValueError(f"topics: empty topic name in {entry!r}")
        if not sep:
            if name == PARAMETER_EVENTS:
                typename = PARAMETER_EVENT_TYPE
            elif name.lstrip("/") in SESSION_TOPICS:
                typename = SESSION_TOPICS[name.lstrip("/")]
            else:
                raise ValueError(
                    f"topics: {name!r} is not a session topic; give its type as "
                    f"{name}:pkg/msg/Type (session topics: {', '.join(SESSION_TOPICS)})"
                )
        typename = typename.strip()
        if typename not in TYPESTORE.fielddefs:
            raise ValueError(f"topics: unknown message type {typename!r} for {name}")
        if any(t.name == name for t in out):
            raise ValueError(f"topics: {name} is listed twice")
        out.append(TopicEntry(name, typename))
    if not out:
        raise ValueError("topics: nothing to record")
    return out
