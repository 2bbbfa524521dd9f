"""What the simulated device says about the commands it gets: a refused command at once, the
command watchdog's trips and resumes after the tick's sample is out, at most one line every
``SAY_EVERY_S``.

A controller that comes and goes does not flood the log, and a trip soon after another (a
start-up trip, then a lost link) is said late rather than not at all: a resume merges into a
trip not said yet.
"""

from __future__ import annotations

from haptic_msgs_py.topics import EFFORT_COMMAND
from haptic_sim.device.port import Log

SAY_EVERY_S = 1.0  # the watchdog says at most a line this often; news waits, never lost


class CommandNews:
    """The lines of a device with ``dof`` joints; the watchdog's newest unsaid one goes out when
    ``say`` (monotonic s) finds its time has come."""

    def __init__(self, log: Log, dof: int) -> None:
        self.log = log
        self.dof = dof
        self._news: tuple[bool, str] | None = None  # the watchdog's unsaid line (warning?, text)
        self._say_after = -float("inf")  # monotonic s before which the watchdog says nothing

    def refusing(self, effort: tuple[float, ...]) -> None:
        """The first of a burst of refused commands (``CommandGuard``), said at once."""
        self.log.warning(
            f"refusing {EFFORT_COMMAND} {list(effort)!r}: need {self.dof} finite values; "
            "zero effort until a valid command"
        )

    def tripped(self, held: str, timeout_s: float, trips: int) -> None:
        """A trip after ``held`` without a valid command (limit ``timeout_s``, s)."""
        self._news = (
            True,
            f"watchdog: no valid {EFFORT_COMMAND} for {held} (limit {timeout_s * 1e3:g} ms of "
            f"samples sent): effort zeroed ({trips} trips so far)",
        )

    def resumed(self, trips: int) -> None:
        """The end of trip number ``trips``; a trip not said yet is said with it."""
        resumed = f"valid {EFFORT_COMMAND} again: effort resumed"
        if self._news is not None and self._news[0]:
            self._news = (True, f"{self._news[1]}; {resumed}")
        else:
            self._news = (False, f"{resumed} (after trip {trips})")

    def say(self, now: float) -> None:
        """Say the watchdog's newest news if a line may go out at monotonic ``now`` (s)."""
        if self._news is not None and now >= self._say_after:
            warning, line = self._news
            (self.log.warning if warning else self.log.info)(line)
            self._news = None
            self._say_after = now + SAY_EVERY_S
