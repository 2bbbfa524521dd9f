"""In-process hand-over of loop values between the nodes of one process (ROS-free).

After rclcpp's intra-process manager, a publish

1. calls every subscriber of the topic in this process at once, depth first, with the immutable
   value (no serialization, no executor);
2. queues the middleware send for readers in other processes (only while some are matched) and
   sends the queue when the outermost publish returns: nothing goes out on DDS before the
   command has reached the device.

``begin()``/``end()`` (or ``batch()``) make several publishes one outermost publish. A publisher
published to from inside its own delivery (a cycle in the graph) is deferred, as is work given
to ``call_soon`` during a publish: ``run_soon`` runs it from the spin loop once the publish has
returned. One ``Bus`` per ROS context (``bus_for``). Why: docs/design/timing.md.
"""

from __future__ import annotations

import time
import weakref
from collections import deque
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

Callback = Callable[[Any], None]


class Topic:
    """One topic's subscribers and publishers in this process."""

    __slots__ = ("leading", "listeners", "name", "publishers", "subscribers")

    def __init__(self, name: str) -> None:
        self.name = name
        self.subscribers: list[Callback] = []  # shared with the publishers: no copy per publish
        self.leading = 0  # the first ``leading`` subscribers came with ``first``
        self.publishers: list[Any] = []
        self.listeners: list[Callable[[], None]] = []  # told when the publishers change


class Bus:
    """The process's registry of in-process topics, the outgoing queue and deferred work."""

    def __init__(self) -> None:
        self.topics: dict[str, Topic] = {}
        self.nodes: set[str] = set()  # nodes with loop endpoints here (fully qualified names)
        self.composed = False  # more than one: sends on DDS only serve readers elsewhere
        self.depth = 0  # publishes under way (nested)
        self.outbox: list[tuple[Callback, Any]] = []  # middleware sends after the command
        self.soon: deque[Callable[[], None]] = deque()

    def topic(self, name: str) -> Topic:
        """The topic ``name`` (fully qualified), created on first use."""
        t = self.topics.get(name)
        if t is None:
            t = self.topics[name] = Topic(name)
        return t

    # --- registration ---------------------------------------------------------------------
    def join(self, node_name: str) -> None:
        """A node with loop endpoints lives in this process."""
        self.nodes.add(node_name)
        self.composed = len(self.nodes) > 1

    def add_publisher(self, name: str, publisher: Any) -> Topic:
        """A publisher of ``name`` in this process: its subscribers here stop listening to DDS."""
        t = self.topic(name)
        t.publishers.append(publisher)
        for tell in list(t.listeners):
            tell()
        return t

    def remove_publisher(self, name: str, publisher: Any) -> None:
        """That publisher is gone: subscribers here listen to DDS again if none is left."""
        t = self.topic(name)
        if publisher in t.publishers:
            t.publishers.remove(publisher)
        for tell in list(t.listeners):
            tell()

    def publishers(self) -> list[Any]:
        """Every publisher in this process."""
        return [p for t in self.topics.values() for p in t.publishers]

    def add_subscriber(
        self, name: str, callback: Callback, listener: Callable[[], None], first: bool = False
    ) -> Topic:
        """``callback`` takes every value published on ``name`` in this process; ``listener`` is
        called whenever the number of publishers here changes. A ``first`` subscriber (a
        controller's input) is called before the others, whenever it joined: a command whose
        inputs are complete goes out before work off its path (docs/design/timing.md)."""
        t = self.topic(name)
        if first:  # nodes are built before the loop spins: never inside a delivery
            t.subscribers.insert(t.leading, callback)
            t.leading += 1
        else:
            t.subscribers.append(callback)
        t.listeners.append(listener)
        return t

    # --- the hand-over --------------------------------------------------------------------
    def deliver(self, subscribers: list[Callback], value: Any) -> None:
        """Call each subscriber with ``value`` (depth first), then, when this was the outermost
        publish, send what waits for other processes."""
        self.depth += 1
        try:
            for callback in subscribers:
                callback(value)
        finally:
            self.depth -= 1
        if not self.depth and self.outbox:
            self.flush()

    def send_later(self, send: Callback, value: Any) -> None:
        """Queue a middleware send; it goes out when the outermost publish returns."""
        self.outbox.append((send, value))

    def flush(self) -> None:
        """Send everything queued for other processes, in the order it was published."""
        out = self.outbox
        self.outbox = []
        self.depth += 1  # a send that publishes again (it never should) only queues
        try:
            for send, value in out:
                send(value)
        finally:
            self.depth -= 1
        if self.outbox and not self.depth:
            self.flush()

    def begin(self) -> None:
        """Start a batch: the publishes until ``end`` form one outermost publish."""
        self.depth += 1

    def end(self) -> None:
        """End a batch: when it was the outermost, send what waits for other processes."""
        self.depth -= 1
        if not self.depth and self.outbox:
            self.flush()

    @contextmanager
    def batch(self) -> Iterator[None]:
        """``begin`` ... ``end`` as a block (the loop's path calls the two directly)."""
        self.begin()
        try:
            yield
        finally:
            self.end()

    # --- deferred work ----------------------------------------------------------------------
    def call_soon(self, work: Callable[[], None]) -> None:
        """Run ``work`` now when no publish is under way, else once it has returned
        (``run_soon``)."""
        if self.depth:
            self.soon.append(work)
        else:
            work()

    def run_soon(self, budget_s: float = 0.002) -> None:
        """Run deferred work (and what it defers in turn) for about ``budget_s`` of wall time."""
        soon = self.soon
        end = time.monotonic() + budget_s
        monotonic = time.monotonic
        while soon:
            soon.popleft()()
            if monotonic() >= end:
                return


_BUSES: weakref.WeakKeyDictionary[Any, Bus] = weakref.WeakKeyDictionary()


def bus_for(context: Any) -> Bus:
    """The bus of a ROS context (one per process, or per private context in tests)."""
    bus = _BUSES.get(context)
    if bus is None:
        bus = _BUSES[context] = Bus()
    return bus
