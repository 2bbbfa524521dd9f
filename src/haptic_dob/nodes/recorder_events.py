"""The recorder's subscription events: a topic's lost match that comes back, samples the
middleware lost (``haptic_dob.recorder.publishers``), each said as a WARN line."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from rclpy.event_handler import SubscriptionEventCallbacks

from haptic_dob.recorder.counts import TopicCount
from haptic_dob.recorder.publishers import PublisherWatch


def publisher_events(
    count: TopicCount, say: Callable[[str], object]
) -> tuple[PublisherWatch, SubscriptionEventCallbacks]:
    """The watch of ``count``'s topic and the event callbacks that feed it, saying its lines
    with ``say``."""
    watch = PublisherWatch(count.topic)

    def matched(status: Any) -> None:
        line = watch.on_matched(status.current_count, time.monotonic(), count.received)
        if line:
            say(line)

    def lost(status: Any) -> None:
        line = watch.on_lost(status.total_count, status.total_count_change)
        if line:
            say(line)

    return watch, SubscriptionEventCallbacks(matched=matched, message_lost=lost)
