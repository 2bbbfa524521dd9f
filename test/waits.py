"""The one polling loop of the tests: wait until a condition holds, or give up after a guard.

The timeout is a guard against hanging, never a bound on the code under test: tests that bound
timing do it in samples or cycles. ``step`` replaces the sleep when the wait must also do work
(spin an executor); ``check`` runs every round and may fail the test early (a process died).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TypeVar

T = TypeVar("T")


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
