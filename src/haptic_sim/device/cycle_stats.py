"""Real-time cycle statistics of a device: commands on time or late, latency, overruns.

Command k is on time when it arrives before the tick that applies it (the plant still at sample k);
its latency is measured from sample k's send. A tick whose command did not come is late (counted
once the loop has closed, after the first command). The ticks are due on the wall clock's grid
(sample 0's time plus whole periods): a tick that runs a period or more after its time is an
overrun, and the grid points it passed are missed ticks (the simulated plant steps once a tick: a
missed tick is a period the simulation loses). ``CycleStats`` is what a run reports (the
``stats_file`` JSON, ``dataclasses.asdict``).
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass

from haptic_dob.runtime.latency import LatencyHistogram


@dataclass(frozen=True)
class CycleStats:
    """Real-time cycle statistics of a run so far (the ``stats_file`` keys, in order)."""

    cycles: int  # samples the plant moved
    commands_on_time: int
    commands_late: int
    on_time_pct: float  # % of on-time and late commands; NaN before the first
    missed_ticks: int  # grid points without a tick of their own
    overruns: int  # ticks that ran a period or more after their time
    latency_p50_ms: float  # sample k sent -> command k arrived, ms (NaN before the first)
    latency_p99_ms: float
    refused_commands: int
    limited_commands: int
    watchdog_trips: int

    def write(self, path: str) -> None:
        """Write these statistics to ``path`` as the ``stats_file`` JSON (NaN as ``NaN``)."""
        with open(path, "w", encoding="utf-8") as fh:
            json.dump(asdict(self), fh, indent=2)


class RealtimeStats:
    """Counts of a real-time loop, in constant memory however long it runs."""

    def __init__(self) -> None:
        self.on_time = 0
        self.late = 0
        self.missed_ticks = 0
        self.overruns = 0
        self.latency = LatencyHistogram()  # s
        self._command_k = -1  # the newest sample k whose command came on time

    def command(self, k: int, latency_s: float) -> bool:
        """Command k came while the plant is at sample k, ``latency_s`` (s) after sample k was
        sent: counted on time once per k; True when it is the first for k."""
        if k == self._command_k:
            return False
        self._command_k = k
        self.on_time += 1
        self.latency.add(latency_s)
        return True

    def tick(self, k: int) -> None:
        """The tick that applies the command of sample k: late when none came for k."""
        if self._command_k != k and self.on_time:
            self.late += 1

    def tick_at(self, last: int, elapsed_s: float, period_s: float) -> int:
        """The grid point (periods since sample 0) of a tick that runs ``elapsed_s`` (s) after
        sample 0, the last one having run at grid point ``last``: the latest point due, at least
        the next. More than one period past the next point is an overrun; the points passed are
        missed ticks."""
        grid = max(last + 1, math.floor(elapsed_s / period_s))
        if grid > last + 1:
            self.overruns += 1
            self.missed_ticks += grid - last - 1
        return grid

    def result(self, cycles: int, refused: int, limited: int, watchdog_trips: int) -> CycleStats:
        """The statistics so far, with the run's cycles and its guard's and watchdog's counts."""
        total = self.on_time + self.late
        return CycleStats(
            cycles=cycles,
            commands_on_time=self.on_time,
            commands_late=self.late,
            on_time_pct=100.0 * self.on_time / total if total else math.nan,
            missed_ticks=self.missed_ticks,
            overruns=self.overruns,
            latency_p50_ms=self.latency.percentile(50) * 1e3,
            latency_p99_ms=self.latency.percentile(99) * 1e3,
            refused_commands=refused,
            limited_commands=limited,
            watchdog_trips=watchdog_trips,
        )
