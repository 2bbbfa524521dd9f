"""What a simulated device's ``/diagnostics`` says: its cycle, the watchdog, the refused and
limited commands, the command authority's counts and, in real time, the cycle statistics."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from haptic_dob.runtime.status import Status
from haptic_sim.device.loop import DeviceLoop


def device_status(
    loop: DeviceLoop, authority: Mapping[str, Any], refusing_foreign: Callable[[], bool]
) -> Status:
    """The device's status: a warning while the watchdog holds zero effort, while invalid
    commands come, or when ``refusing_foreign()`` (commands of publishers not the loop's were
    refused since the last report; asked only when nothing worse is to say)."""
    tripped = loop.watchdog.tripped
    values: dict[str, Any] = {
        "clock_mode": "lockstep" if loop.lockstep else "realtime",
        "cycle": loop.device.k,
        "watchdog": "tripped: effort zeroed" if tripped else "ok",
        "watchdog_trips": loop.watchdog.trips,
        "refused_commands": loop.guard.refused,
        "limited_commands": loop.guard.limited,
        "effort_limits": list(loop.guard.limits),
        **authority,
    }
    if not loop.lockstep:
        rt = loop.realtime
        values.update(
            overruns=rt.overruns,
            missed_ticks=rt.missed_ticks,
            late_commands=rt.late,
            on_time_commands=rt.on_time,
        )
    if tripped:
        return Status(True, "watchdog tripped: no valid effort_command, effort zeroed", values)
    if loop.guard.refusing:
        return Status(True, "refusing invalid effort_command (zero effort)", values)
    if refusing_foreign():
        return Status(True, "refused effort_command from publishers other than the loop's", values)
    return Status(False, "running" if loop.started else "waiting for the graph", values)
