"""The command guard: no malformed or oversized effort command reaches an actuator.

A command of the wrong length or with NaN/inf is refused: it counts as zero effort, is counted,
and the first refusal of a burst is reported (a valid command ends the burst). A valid command is
clipped to the per-joint effort limits by the suite's one saturation (``control.saturate``) and
counted when it was clipped. The limits are at most the actuator's own saturation and may change
at run time (``limits_for`` checks a request, ``limits`` holds the limits in force).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from operator import ne

from haptic_dob.core.control import saturate


def _quiet(_effort: tuple[float, ...]) -> None:
    """Report nowhere."""


class CommandGuard:
    """Refuses, clips and counts the effort commands (N or N m per joint) of one device.

    Args:
        saturation: the actuator's own effort limit per joint (N or N m), each > 0.
        refusing: called with the refused command at the first refusal of a burst.
    """

    def __init__(
        self,
        saturation: Sequence[float],
        refusing: Callable[[tuple[float, ...]], None] = _quiet,
    ) -> None:
        self.saturation = tuple(float(s) for s in saturation)
        self.dof = len(self.saturation)
        self.limits = self.saturation  # per joint (N or N m), in force
        self.refused = 0  # commands refused (wrong length, NaN or inf)
        self.limited = 0  # commands clipped to the limits
        self.refusing = False  # within a burst of refused commands
        self._on_refusing = refusing

    def limits_for(self, asked: Sequence[float]) -> tuple[float, ...]:
        """The limits an ``effort_limits`` request asks for (N or N m per joint; ``[0.0]``: the
        actuator's saturation); ``ValueError`` with the reason when it is refused."""
        asked = list(asked)
        if asked == [0.0]:
            return self.saturation
        if len(asked) != self.dof:
            raise ValueError(f"effort_limits needs {self.dof} values (one per joint), got {asked}")
        for i, (a, hw) in enumerate(zip(asked, self.saturation, strict=True)):
            if not 0.0 < a <= hw:
                raise ValueError(
                    f"effort_limits[{i}] must be in (0, {hw:g}] (actuator saturation), got {a}"
                )
        return tuple(float(a) for a in asked)

    def check(self, effort: tuple[float, ...]) -> list[float] | None:
        """The command clipped to the limits, or None when it is refused (zero effort)."""
        if len(effort) != self.dof or not all(map(math.isfinite, effort)):
            self.refused += 1
            if not self.refusing:
                self._on_refusing(effort)
                self.refusing = True
            return None
        self.refusing = False
        out = saturate(effort, self.limits)
        if any(map(ne, out, effort)):
            self.limited += 1
        return out
