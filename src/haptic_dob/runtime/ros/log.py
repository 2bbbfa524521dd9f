"""A node's logger for the loop's path: rclpy's output, without rclpy's cost per call.

rclpy's ``RcutilsLogger.log`` finds its caller with ``inspect`` on every call, said or throttled
away (``inspect.getframeinfo`` reads the caller's source, ``os.path.realpath`` resolves files):
0.3-0.6 ms a call on a 2-core lab PC, and 50-90 ms for a process's first (``inspect`` maps every
loaded module to its file). A watchdog trip said from a 1 kHz tick then costs the loop a period
or a hundred, and the late samples trip it again. ``LoopLog`` says the same lines through the
same rcutils output (format, severity, ``--log-level``, the caller's function, file and line)
from the caller's frame alone, and throttles before it looks anything up: about 15 µs a line
said, 1 µs a line throttled away (``BENCHMARKS.md``).
"""

from __future__ import annotations

import math
import os
import sys
import time
from typing import Any

from rclpy.impl.implementation_singleton import rclpy_implementation as _impl
from rclpy.impl.logging_severity import LoggingSeverity
from rclpy.impl.rcutils_logger import RcutilsLogger

#: rcutils' log call, which ``RcutilsLogger.log`` ends with
_emit = _impl.rclpy_logging_rcutils_log


class LoopLog:
    """``info`` / ``warning`` / ``error`` / ``debug`` of a node's logger, as rclpy's take them
    (``throttle_duration_sec`` the one filter), cheap enough for a 1 kHz callback.

    A throttled call site (its code and bytecode offset, as rclpy keys it) says at most one line
    every ``throttle_duration_sec``, the first at once; each call says whether it was said. The
    period runs on the monotonic clock (rclpy's filter reads the system clock, which a time
    adjustment moves).
    """

    def __init__(self, logger: RcutilsLogger) -> None:
        self.logger = logger
        self.name: str = logger.name
        self._next: dict[tuple[Any, int], float] = {}
        self._files: dict[Any, str] = {}  # code -> its file as rclpy names it (absolute)

    def debug(self, message: str, **kwargs: Any) -> bool:
        """Say ``message`` at DEBUG severity."""
        return self._log(LoggingSeverity.DEBUG, message, kwargs)

    def info(self, message: str, **kwargs: Any) -> bool:
        """Say ``message`` at INFO severity."""
        return self._log(LoggingSeverity.INFO, message, kwargs)

    def warning(self, message: str, **kwargs: Any) -> bool:
        """Say ``message`` at WARN severity."""
        return self._log(LoggingSeverity.WARN, message, kwargs)

    def error(self, message: str, **kwargs: Any) -> bool:
        """Say ``message`` at ERROR severity."""
        return self._log(LoggingSeverity.ERROR, message, kwargs)

    def _log(self, severity: LoggingSeverity, message: str, kwargs: dict[str, Any]) -> bool:
        every = float(kwargs.pop("throttle_duration_sec", 0.0))
        if kwargs:
            raise TypeError(f"LoopLog takes throttle_duration_sec only, not {sorted(kwargs)}")
        if not math.isfinite(every) or every < 0.0:
            raise ValueError(f"throttle_duration_sec must be finite and >= 0, got {every}")
        if not self.logger.is_enabled_for(severity):
            return False
        caller = sys._getframe(2)  # the caller of info / warning / ...
        if every > 0.0:
            site = (caller.f_code, caller.f_lasti)
            now = time.monotonic()
            if now < self._next.get(site, -math.inf):
                return False
            self._next[site] = now + every
        code = caller.f_code
        path = self._files.get(code)
        if path is None:
            path = self._files[code] = os.path.abspath(code.co_filename)
        _emit(severity, self.name, message, code.co_name, path, caller.f_lineno)
        return True
