"""The one polling loop of the tests: wait until a condition holds, or give up after a guard.

The timeout is a guard against hanging, never a bound on the code under test: tests that bound
timing do it in samples or cycles. ``step`` replaces the sleep when the wait must also do work
(spin an executor); ``check`` runs every round and may fail the test early (a process died).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Protocol, TypeVar

T = TypeVar("T")


class Future(Protocol):
    """The part of an rclpy future a wait uses."""

    def done(self) -> bool: ...


F = TypeVar("F", bound=Future)


def wait_until(
    done: Callable[[], T],
    timeout_s: float,
    *,
    poll_s: float = 0.05,
    step: Callable[[], object] | None = None,
    check: Callable[[], object] | None = None,
) -> T:
    """Call ``done`` until it returns a true value or ``timeout_s`` (s) passed; return its last
    value (true when the condition held). Between calls: ``step()`` if given, else sleep
    ``poll_s`` (s); ``check()`` if given (to fail early, e.g. assert a process still runs)."""
    end = time.monotonic() + timeout_s
    while True:
        value = done()
        if value or time.monotonic() >= end:
            return value
        if check is not None:
            check()
        if step is not None:
            step()
        else:
            time.sleep(poll_s)


#: wall seconds without an answer after which a service request is sent again: rmw_fastrtps
#: drops a response when the server has not matched the client's response reader within 100 ms
#: of answering (ros2/rmw_fastrtps#390), which happens on a loaded machine right after discovery;
#: the client then waits for an answer that never comes
RESEND_S = 5.0


def answered(
    send: Callable[[], F],
    timeout_s: float,
    *,
    step: Callable[[], object],
    resend_s: float = RESEND_S,
) -> F:
    """The future of a service request that answered: ``send()`` a request (it returns an rclpy
    future), ``step()`` (spin) until it is done, and send it again after ``resend_s`` (s) without
    an answer (an earlier request that answers late counts); after ``timeout_s`` (s, a hang
    guard) the last future, not done."""
    end = time.monotonic() + timeout_s
    sent: list[F] = []
    while True:
        sent.append(send())
        again = min(end, time.monotonic() + resend_s)
        while time.monotonic() < again:
            done = next((f for f in sent if f.done()), None)
            if done is not None:
                return done
            step()
        done = next((f for f in sent if f.done()), None)
        if done is not None or time.monotonic() >= end:
            return done if done is not None else sent[-1]
