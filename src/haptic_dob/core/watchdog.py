"""The watchdog, counted in samples: the real-time device's (zero effort when valid commands stop)
and each end of the teleoperation channel's (``haptic_dob.teleop.delay``: a silent peer).

The device's watchdog counts the samples the device sent, not the wall clock: a stall of the
device's own process (the host, the garbage collector: an overrun of its ticks) never trips it,
while a silent controller trips it within the timeout's samples however late or bunched the ticks
come. The next valid command resumes the effort.
"""

from __future__ import annotations

from collections.abc import Callable

from haptic_msgs_py.stamps import NS_PER_S


def _quiet(*_args: str) -> None:
    """Report nowhere."""


class CommandWatchdog:
    """Trips when no valid command came for a timeout of simulated time (samples).

    Args:
        period_ns: the device's sample period (ns).
        tripped: called when it trips, with how long the newest command was held (``"ever"``
            when none came yet, else ``"<n> samples"``).
        resumed: called when a valid command ends a trip.
    """

    def __init__(
        self,
        period_ns: int,
        tripped: Callable[[str], None] = _quiet,
        resumed: Callable[[], None] = _quiet,
    ) -> None:
        self.period_ns = period_ns
        self.last_command_k = -1  # the sample k at which the newest valid command came
        self.tripped = False
        self.trips = 0
        self._on_tripped, self._on_resumed = tripped, resumed

    def fed(self, k: int) -> None:
        """A valid command came while the plant is at sample ``k``; it ends a trip."""
        self.last_command_k = k
        if self.tripped:
            self.tripped = False
            self._on_resumed()

    def due(self, k: int, timeout_s: float) -> bool:
        """Whether the effort applied at sample ``k`` must be zero: no valid command for more than
        ``timeout_s`` (s) of samples. Trips (reports once) on the first such sample."""
        silent = k - self.last_command_k  # periods the newest command was held
        if silent * self.period_ns <= timeout_s * NS_PER_S:
            return False
        if not self.tripped:
            self.tripped = True
            self.trips += 1
            self._on_tripped("ever" if self.last_command_k < 0 else f"{silent} samples")
        return True
