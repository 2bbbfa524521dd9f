"""A known force the virtual environment adds along its normal: identification's input.

The thesis identified its slide (ch. 4.2) from the response to a 2.4 N force step under an
80 N/m virtual spring and verified the model (ch. 4.3) with 1.6 N and 3.2 N steps and a 0.6 N,
2 Hz sine. The environment node renders that input: its force is the spring's plus
``force_n(t) * normal``, with ``t`` the sample's time (its stamp), so a lockstep run is
deterministic and a batch run gives the same samples. The joint state's effort then carries the
input, which is all ``haptic-identify`` needs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from haptic_dob.core.validation import finite_scalar, nonnegative
from haptic_dob.runtime.params import param

KINDS = ("none", "step", "sine")


@dataclass(frozen=True)
class Excitation:
    """``none``, a ``step`` of ``amplitude_n`` from ``at_s``, or a ``sine`` of ``amplitude_n``
    at ``frequency_hz`` from ``at_s`` (starting at zero phase)."""

    kind: str = field(
        default="none",
        metadata=param("force added along the wall normal: none, step or sine", choices=KINDS),
    )
    amplitude_n: float = field(
        default=0.0, metadata=param("step size or sine amplitude", "N", -100.0, 100.0)
    )
    at_s: float = field(default=1.0, metadata=param("start (sample time)", "s", 0.0, 1e7))
    frequency_hz: float = field(
        default=2.0,
        metadata=param("frequency of the sine (well below the loop rate)", "Hz", 0.0, 200.0),
    )

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"kind must be one of {', '.join(KINDS)}, got {self.kind!r}")
        finite_scalar("amplitude_n", self.amplitude_n)
        nonnegative("at_s", self.at_s)
        nonnegative("frequency_hz", self.frequency_hz)

    @property
    def active(self) -> bool:
        """It adds a force at some time."""
        return self.kind != "none" and self.amplitude_n != 0.0

    def force_n(self, t_s: float) -> float:
        """The added force (N) at sample time ``t_s`` (s)."""
        if self.kind == "none" or t_s < self.at_s:
            return 0.0
        if self.kind == "step":
            return self.amplitude_n
        return self.amplitude_n * math.sin(2.0 * math.pi * self.frequency_hz * (t_s - self.at_s))

    def label(self) -> str:
        """A short description (``2.4 N step``, ``0.6 N 2 Hz sine``, ``none``)."""
        if self.kind == "step":
            return f"{self.amplitude_n:g} N step"
        if self.kind == "sine":
            return f"{self.amplitude_n:g} N {self.frequency_hz:g} Hz sine"
        return "none"
