"""A clean stop's steps: work the inputs off, wait for the readers' acknowledgements, last words.

An observer (a ``drain_marker``) first works off the inputs still coming, until its marker stays
still for ``DRAIN_QUIET_S`` and ``QUIET_SPINS`` spins, for at most a queue of samples
(``WORK_OFF_SAMPLES``); then every process waits for its reliable readers' acknowledgements,
within ``DRAIN_BUDGET_S``. After an error, ``last_words`` still sends each node's zero.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Sequence
from typing import Protocol

from rclpy.duration import Duration
from rclpy.node import Node

from haptic_msgs_py.ros.qos import LOOP_IN_DEPTH

DRAIN_BUDGET_S = 2.0  # at most this long for the acknowledgements at a stop
DRAIN_QUIET_S = 0.2  # inputs are worked off when the marker did not change for this long
QUIET_SPINS = 5  # ... and over this many spins
WORK_OFF_SAMPLES = LOOP_IN_DEPTH  # ... or after this many changes: what a queue held at the stop
LAST_WORDS_S = 0.5  # after an error: how long the zero's acknowledgement may take


class Stopping(Protocol):
    """What a stop needs of a loop node (``spin.LoopNode`` has it)."""

    def get_name(self) -> str: ...

    def on_shutdown(self) -> None: ...

    def drain_marker(self) -> int | None: ...


def last_words(nodes: Sequence[Stopping]) -> None:
    """Each node's ``on_shutdown`` after an error ended the spin loop (a device or a bridge
    zeroes its effort), whatever else fails meanwhile; then a short wait for the readers'
    acknowledgements."""
    for n in nodes:
        try:
            n.on_shutdown()
        except Exception as exc:  # the error that ended the loop is raised next
            print(f"ERROR: {n.get_name()}: shutdown after an error failed: {exc}", file=sys.stderr)
    readers = [n for n in nodes if isinstance(n, Node)]
    wait_for_acknowledgements(readers, time.monotonic() + LAST_WORDS_S)


def work_off(
    spin_once: Callable[..., None],
    nodes: Sequence[Stopping],
    until: float,
    samples: int = WORK_OFF_SAMPLES,
) -> int:
    """Spin until no node's ``drain_marker`` changed for ``DRAIN_QUIET_S`` and ``QUIET_SPINS``
    spins (a starved process's spins, not the wall clock, say its inputs stopped), or the
    markers changed ``samples`` times, or ``until`` (monotonic s); the number of changes."""
    last = [n.drain_marker() for n in nodes]
    quiet_since, quiet_spins, changes = time.monotonic(), 0, 0
    while time.monotonic() < until and changes < samples:
        if quiet_spins >= QUIET_SPINS and time.monotonic() - quiet_since >= DRAIN_QUIET_S:
            break
        spin_once(timeout_sec=DRAIN_QUIET_S / QUIET_SPINS)
        markers = [n.drain_marker() for n in nodes]
        if markers != last:
            last, quiet_since, quiet_spins = markers, time.monotonic(), 0
            changes += 1
        else:
            quiet_spins += 1
    return changes


def wait_for_acknowledgements(nodes: Sequence[Node], until: float) -> bool:
    """Wait until every reliable reader acknowledged what ``nodes`` published (or ``until``)."""
    for node in nodes:
        for pub in node.publishers:
            left = until - time.monotonic()
            if left <= 0.0 or not pub.wait_for_all_acked(Duration(nanoseconds=int(left * 1e9))):
                return False
    return True
