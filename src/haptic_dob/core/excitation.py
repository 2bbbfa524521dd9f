"""A known force the virtual environment adds: identification's input.

The environment's force is the wall's plus the excitation at ``t``, the sample's time (its
stamp), so a lockstep run is deterministic and a batch run gives the same samples; the joint
state's effort then carries the input that ``haptic-identify`` fits. ``along``: ``normal`` adds
``force_n(t)`` along the wall normal; ``axes`` adds a signal of the same kind along each of the
base frame's x, y and z, each axis a third of ``period_s`` later than the one before. ``chirp``:
a logarithmic sweep from ``low_hz`` to ``high_hz`` over ``period_s``, repeated; ``multisine``:
every multiple of ``1 / period_s`` in [low_hz, high_hz] at equal amplitude with Schroeder's
phases, scaled so that its peak is ``amplitude_n``; every kind stays within +-``amplitude_n``
per axis. ``hold_n_per_m`` > 0 adds an isotropic spring toward ``hold_at``, its force in the
command like the rest. Why these inputs: docs/design/identification.md.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from haptic_dob.core.validation import finite_scalar, nonnegative, vector
from haptic_dob.runtime.params import param

KINDS = ("none", "step", "sine", "chirp", "multisine")
ALONG = ("normal", "axes")
Force = tuple[float, float, float]
#: points per period of the highest frequency on which the multisine's peak is found
PEAK_GRID = 40
#: the most components a multisine may have (its cost per sample grows with them)
MAX_COMPONENTS = 2000


@dataclass(frozen=True)
class Excitation:
    """``none``, a ``step`` or a ``sine`` (from ``at_s``), a ``chirp`` or a ``multisine`` (see
    the module), along the wall normal or along each axis, and an optional holding spring."""

    kind: str = field(
        default="none",
        metadata=param(
            description="force added: none, step, sine, chirp or multisine", choices=KINDS
        ),
    )
    amplitude_n: float = field(
        default=0.0,
        metadata=param(
            description="step size, or the peak of the other kinds per axis",
            unit="N",
            bounds=(-100.0, 100.0),
        ),
    )
    at_s: float = field(
        default=1.0, metadata=param(description="start (sample time)", unit="s", bounds=(0.0, 1e7))
    )
    frequency_hz: float = field(
        default=2.0,
        metadata=param(
            description="frequency of the sine (well below the loop rate)",
            unit="Hz",
            bounds=(0.0, 200.0),
        ),
    )
    low_hz: float = field(
        default=1.0,
        metadata=param(
            description="chirp and multisine: lowest frequency", unit="Hz", bounds=(1e-3, 200.0)
        ),
    )
    high_hz: float = field(
        default=8.0,
        metadata=param(
            description="chirp and multisine: highest frequency",
            unit="Hz",
            bounds=(1e-3, 200.0),
            details=("Identification's filters bias the mass upward above about 10 Hz."),
        ),
    )
    period_s: float = field(
        default=10.0,
        metadata=param(
            description="chirp: one sweep (then it repeats); multisine: its period",
            unit="s",
            bounds=(0.1, 1e4),
            details="The multisine's frequency step is 1/period.",
        ),
    )
    along: str = field(
        default="normal",
        metadata=param(
            description=(
                "normal: along the wall normal; axes: a signal of its own along each of x, y, z"
            ),
            choices=ALONG,
        ),
    )
    hold_n_per_m: float = field(
        default=0.0,
        metadata=param(
            description="stiffness of an isotropic spring toward hold_at; 0 = none",
            unit="N/m",
            bounds=(0.0, 1e4),
            details="It keeps a device that nothing else holds in its workspace.",
        ),
    )
    hold_at: tuple[float, float, float] = field(
        default=(0.0, 0.0, 0.0),
        metadata=param(description="where the holding spring pulls (x, y, z)", unit="m"),
    )
    # the multisine's components: angular frequencies (rad/s), each axis's phases (rad, (3, n)),
    # the scale of a unit peak
    _w: np.ndarray = field(init=False, repr=False, compare=False)
    _phase: np.ndarray = field(init=False, repr=False, compare=False)
    _scale: float = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"kind must be one of {', '.join(KINDS)}, got {self.kind!r}")
        if self.along not in ALONG:
            raise ValueError(f"along must be one of {', '.join(ALONG)}, got {self.along!r}")
        finite_scalar("amplitude_n", self.amplitude_n)
        nonnegative("at_s", self.at_s)
        nonnegative("frequency_hz", self.frequency_hz)
        if not 0.0 < self.low_hz < self.high_hz:
            raise ValueError(f"need 0 < low_hz < high_hz, got {self.low_hz:g}, {self.high_hz:g}")
        if not self.period_s > 0.0:
            raise ValueError(f"period_s must be > 0, got {self.period_s!r}")
        if self.along == "axes" and self.kind in ("step", "sine"):
            raise ValueError(f"along axes needs a chirp or a multisine, got a {self.kind}")
        nonnegative("hold_n_per_m", self.hold_n_per_m)
        hold = vector("hold_at", self.hold_at, 3)
        object.__setattr__(self, "hold_at", (float(hold[0]), float(hold[1]), float(hold[2])))
        w, phase, scale = np.zeros(0), np.zeros(0), 0.0
        if self.kind == "multisine":
            w, phase, scale = self._multisine()
        object.__setattr__(self, "_w", w)
        object.__setattr__(self, "_phase", phase)
        object.__setattr__(self, "_scale", scale)

    def _multisine(self) -> tuple[np.ndarray, np.ndarray, float]:
        """Components (angular frequencies, Schroeder's phases) and the scale of a unit peak.

        The peak: one period on a grid of ``PEAK_GRID`` points per period of the highest
        component (one inverse FFT), its largest points then moved to where the derivative
        vanishes (Newton).
        """
        k = np.arange(math.ceil(self.low_hz * self.period_s), int(self.high_hz * self.period_s) + 1)
        if k.size == 0 or k.size > MAX_COMPONENTS:
            raise ValueError(
                f"multisine: {k.size} multiples of 1/period_s ({1.0 / self.period_s:g} Hz) between "
                f"low_hz and high_hz; it needs 1 to {MAX_COMPONENTS} (period_s or the band)"
            )
        n = k.size
        i = np.arange(1, n + 1)
        phase = -math.pi * i * (i - 1) / n
        w = 2.0 * math.pi * k / self.period_s
        size = 1 << math.ceil(math.log2(PEAK_GRID * int(k[-1])))
        spectrum = np.zeros(size, dtype=np.complex128)
        spectrum[k] = np.exp(1j * phase)
        s = np.fft.ifft(spectrum).imag * size  # sum of sin(w t + phase) on the grid
        top = np.argsort(np.abs(s))[-PEAK_GRID:] * (self.period_s / size)
        for _ in range(8):
            arg = np.outer(top, w) + phase
            d1, d2 = np.cos(arg) @ w, -(np.sin(arg) @ (w * w))
            top = top - d1 / np.where(d2 == 0.0, 1.0, d2)
        refined = np.sin(np.outer(top, w) + phase).sum(axis=1)
        peak = max(float(np.max(np.abs(s))), float(np.max(np.abs(refined))))
        # axis i a third of the period later: its phases advanced by w i period / 3
        shifts = np.arange(3)[:, None] * (self.period_s / 3.0)
        return w, phase + w * shifts, 1.0 / peak

    @property
    def active(self) -> bool:
        """It adds a force at some time."""
        return (self.kind != "none" and self.amplitude_n != 0.0) or self.hold_n_per_m > 0.0

    def force_n(self, t_s: float) -> float:
        """The added force (N) at sample time ``t_s`` (s), the first axis's for ``along: axes``."""
        if self.kind == "none" or t_s < self.at_s:
            return 0.0
        if self.kind == "step":
            return self.amplitude_n
        if self.kind == "sine":
            return self.amplitude_n * math.sin(
                2.0 * math.pi * self.frequency_hz * (t_s - self.at_s)
            )
        return self._signal(t_s - self.at_s)

    def _signal(self, t: float) -> float:
        """Chirp or multisine ``t`` (s) after its start, within +-amplitude_n."""
        a = self.amplitude_n
        if self.kind == "chirp":
            lo, ratio = self.low_hz, math.log(self.high_hz / self.low_hz)
            tau = math.fmod(t, self.period_s) / self.period_s
            x = a * math.sin(2.0 * math.pi * lo * self.period_s / ratio * math.expm1(ratio * tau))
        else:
            x = a * float(self._sum3(t)[0])
        return min(max(x, -abs(a)), abs(a))

    def _sum3(self, t: float) -> np.ndarray:
        """The unit-peak multisine of each axis ``t`` (s) after its start, (3,)."""
        s: np.ndarray = np.sin(self._w * t + self._phase).sum(axis=1) * self._scale
        return s

    def force(self, t_s: float, normal: Sequence[float], position: Sequence[float]) -> Force:
        """The added force (N, base frame) at sample time ``t_s`` (s): along the wall ``normal``
        or per axis, plus the holding spring at the end-effector ``position`` (m)."""
        if self.along == "normal" or self.kind == "none" or t_s < self.at_s:
            e = self.force_n(t_s)
            fx, fy, fz = e * normal[0], e * normal[1], e * normal[2]
        elif self.kind == "multisine":  # the three axes in one pass
            a = abs(self.amplitude_n)
            s = self._sum3(t_s - self.at_s)
            fx, fy, fz = (min(max(float(x) * self.amplitude_n, -a), a) for x in s)
        else:
            t, shift = t_s - self.at_s, self.period_s / 3.0
            fx, fy, fz = self._signal(t), self._signal(t + shift), self._signal(t + 2.0 * shift)
        k = self.hold_n_per_m
        if k > 0.0:
            c = self.hold_at
            fx -= k * (position[0] - c[0])
            fy -= k * (position[1] - c[1])
            fz -= k * (position[2] - c[2])
        return (fx, fy, fz)

    def label(self) -> str:
        """A short description (``2.4 N step``, ``0.6 N 2 Hz sine``, ``none``...)."""
        if self.kind == "step":
            text = f"{self.amplitude_n:g} N step"
        elif self.kind == "sine":
            text = f"{self.amplitude_n:g} N {self.frequency_hz:g} Hz sine"
        elif self.kind in ("chirp", "multisine"):
            text = f"{self.amplitude_n:g} N {self.low_hz:g}-{self.high_hz:g} Hz {self.kind}"
        else:
            text = "none"
        if self.kind != "none" and self.along == "axes":
            text += " along x, y and z"
        if self.hold_n_per_m > 0.0:
            text += f", held by {self.hold_n_per_m:g} N/m"
        return text
