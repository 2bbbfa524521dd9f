"""The simulated human hand: a mass-spring-damper grip coupled to a reference motion.

The hand's mass ``m_h`` moves with the device, held by a spring ``k_h`` and damper ``b_h`` to a
reference ``x_r(t)``; the force on the device (a handle sensor's reading, 1-D along its axis, SI)
is ``F_h = k_h (x_r - x) + b_h (x_r' - x') + f_ff(t) - m_h x''``. ``HandParams.behaviour``:

- ``semi_random``: ``x_r = ramp(t) * offset + amplitude * n(t)``, ``n`` unit-variance Gaussian
  noise band-passed to [band_low_hz, band_high_hz] (4th-order Butterworth) and rolled off above
  ``rolloff_hz`` (2nd order; 0: none); a depth, the same at every wall (``depth_reference``);
- ``push_hold``: ``x_r = ramp(t) * offset`` held, plus a force pulse ``f_ff`` of ``perturbation_n``
  for ``perturbation_s`` at ``perturbation_at_s``; ``none``: no hand (zero force).

Generated in ``BLOCK_S`` blocks from a seeded generator, bit-identical whatever the block length
(batch and real time see one hand); ``prepare`` makes the next ahead (docs/design/timing.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from haptic_dob.core.validation import finite_scalar, nonnegative, positive
from haptic_dob.runtime.params import param

BEHAVIOURS = ("semi_random", "push_hold", "none")
BLOCK_S = 0.1  # s of reference per generated block (numpy, 1000 physics steps at 10 kHz)
Block = tuple[np.ndarray, np.ndarray, np.ndarray]  # position (m), velocity (m/s), force (N)


class Reference(Protocol):
    """What a 1-D plant asks its hand's reference for (``HandReference``, one axis of a 3-D
    one)."""

    def arrays(self, i: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]: ...

    def prepare(self, i: int) -> None: ...


@dataclass(frozen=True)
class HandParams:
    """Hand grip and reference-motion settings (SI units; see the module docstring)."""

    behaviour: str = field(
        default="semi_random",
        metadata=param(
            description="what the simulated hand does", choices=BEHAVIOURS, read_only=True
        ),
    )
    mass_kg: float = field(
        default=0.1,
        metadata=param(
            description="hand mass moving with the handle", unit="kg", bounds=(0.0, 10.0)
        ),
    )
    stiffness_n_per_m: float = field(
        default=300.0,
        metadata=param(
            description="grip stiffness toward the reference", unit="N/m", bounds=(0.0, 1e5)
        ),
    )
    damping_n_s_per_m: float = field(
        default=10.0,
        metadata=param(
            description="grip damping toward the reference", unit="N s/m", bounds=(0.0, 1e3)
        ),
    )
    offset_m: float = field(
        default=0.0075,
        metadata=param(
            description="reference push past the start position", unit="m", bounds=(-1.0, 1.0)
        ),
    )
    amplitude_m: float = field(
        default=0.0013554,
        metadata=param(
            description="std of the semi-random reference motion", unit="m", bounds=(0.0, 1.0)
        ),
    )
    band_low_hz: float = field(
        default=0.05,
        metadata=param(
            description="low edge of the semi-random motion band", unit="Hz", bounds=(1e-3, 1e3)
        ),
    )
    band_high_hz: float = field(
        default=10.0,
        metadata=param(
            description="high edge of the semi-random motion band", unit="Hz", bounds=(1e-3, 1e3)
        ),
    )
    rolloff_hz: float = field(
        default=5.0,
        metadata=param(
            description="corner of the motion's 2nd-order roll-off; 0 = none",
            unit="Hz",
            bounds=(0.0, 1e3),
        ),
    )
    ramp_s: float = field(
        default=1.0,
        metadata=param(
            description="smooth ramp-in time of the reference", unit="s", bounds=(0.0, 1e3)
        ),
    )
    perturbation_n: float = field(
        default=0.0,
        metadata=param(
            description="push_hold: force pulse amplitude", unit="N", bounds=(-100.0, 100.0)
        ),
    )
    perturbation_at_s: float = field(
        default=1.5,
        metadata=param(description="push_hold: pulse start time", unit="s", bounds=(0.0, 1e6)),
    )
    perturbation_s: float = field(
        default=0.005,
        metadata=param(description="push_hold: pulse duration", unit="s", bounds=(0.0, 10.0)),
    )

    def __post_init__(self) -> None:
        if self.behaviour not in BEHAVIOURS:
            raise ValueError(
                f"behaviour must be one of {', '.join(BEHAVIOURS)}, got {self.behaviour!r}"
            )
        nonnegative("mass_kg", self.mass_kg)
        nonnegative("stiffness_n_per_m", self.stiffness_n_per_m)
        nonnegative("damping_n_s_per_m", self.damping_n_s_per_m)
        finite_scalar("offset_m", self.offset_m)
        nonnegative("amplitude_m", self.amplitude_m)
        lo, hi = (
            positive("band_low_hz", self.band_low_hz),
            positive("band_high_hz", self.band_high_hz),
        )
        if lo >= hi:
            raise ValueError(f"band_low_hz ({lo}) must be below band_high_hz ({hi})")
        nonnegative("rolloff_hz", self.rolloff_hz)
        nonnegative("ramp_s", self.ramp_s)
        finite_scalar("perturbation_n", self.perturbation_n)
        nonnegative("perturbation_at_s", self.perturbation_at_s)
        nonnegative("perturbation_s", self.perturbation_s)

    @property
    def active(self) -> bool:
        """False for ``behaviour='none'``."""
        return self.behaviour != "none"


@dataclass(frozen=True)
class DepthReference:
    """A depth-regulating hand's reference (m) and what it gives at the walls it was set for."""

    offset_m: float
    amplitude_m: float
    push_n: dict[float, float]  # wall (N/m) -> mean push (N), static
    swing_n: dict[float, float]  # wall -> the force's std (N), linear model
    depth_std_ratio: dict[float, float]  # wall -> the position's std over its mean depth


def _responses(
    params: HandParams, wall: float, mass_kg: float, viscous: float, dt: float
) -> tuple[float, float, float]:
    """(static push per m of reference offset, force std and position std per m of reference
    std) at one wall, for the linear model of hand, slide and an ideally rendered wall."""
    from scipy import signal  # lazy: a device without a band starts without scipy.signal

    m, b = mass_kg + params.mass_kg, viscous + params.damping_n_s_per_m
    kh, bh, mh = params.stiffness_n_per_m, params.damping_n_s_per_m, params.mass_kg
    f = np.geomspace(params.band_low_hz * 1e-3, 0.5 / dt, 200_000)
    _, h_ref = signal.sosfreqz(_band_filter(params, dt), worN=f, fs=1.0 / dt)
    weight = np.abs(h_ref) ** 2
    s = 2j * np.pi * f
    x = (kh + bh * s) / (m * s * s + b * s + wall + kh)  # X / X_r
    force = (kh + bh * s) * (1.0 - x) - mh * s * s * x  # F_h / X_r

    def rms(h: np.ndarray) -> float:
        return math.sqrt(float(np.trapezoid(np.abs(h) ** 2 * weight, f) / np.trapezoid(weight, f)))

    return kh * wall / (wall + kh), rms(force), rms(x)


def depth_reference(
    params: HandParams,
    walls: tuple[float, ...],
    mass_kg: float,
    viscous_n_s_per_m: float,
    max_force_n: float,
    sigmas: float = 3.0,
    dt: float = 1e-4,
) -> DepthReference:
    """One reference (offset, amplitude in m) for every wall: a person pushing to a depth.

    The hand acts through its grip on the slide (``mass_kg``, ``viscous_n_s_per_m``) and an
    ideally rendered wall (no friction, no delay), with the reference's spectrum of ``params``
    (band, roll-off; period ``dt`` s). At the stiffest wall the push is half the actuator's
    ``max_force_n`` and the force stays within [0, max_force_n] over ``sigmas`` standard
    deviations; at every wall the slide's position swing stays inside the wall over ``sigmas``
    (its std at most its mean depth over ``sigmas``). The amplitude is the smaller of the two.
    """
    ks = [positive("wall", w) for w in walls]
    if not ks:
        raise ValueError("walls must not be empty")
    positive("mass_kg", mass_kg)
    nonnegative("viscous_n_s_per_m", viscous_n_s_per_m)
    limit, n = positive("max_force_n", max_force_n), positive("sigmas", sigmas)
    resp = {k: _responses(params, k, mass_kg, viscous_n_s_per_m, dt) for k in ks}
    top = max(ks)
    offset = 0.5 * limit / resp[top][0]
    by_force = 0.5 * limit / n / resp[top][1]
    # mean depth X_off k_h / (K + k_h) against the position's std: both per m of reference
    kh = params.stiffness_n_per_m
    by_contact = min(offset * kh / (k + kh) / n / resp[k][2] for k in ks)
    amp = min(by_force, by_contact)
    return DepthReference(
        offset,
        amp,
        {k: offset * resp[k][0] for k in ks},
        {k: amp * resp[k][1] for k in ks},
        {k: amp * resp[k][2] / (offset * kh / (k + kh)) for k in ks},
    )


def _band_filter(params: HandParams, dt: float) -> np.ndarray:
    """The reference's band-pass (4th-order Butterworth) at sample period ``dt`` (s), followed by
    the 2nd-order Butterworth low-pass at ``rolloff_hz`` when it is set."""
    from scipy import signal  # lazy: a device without a band starts without scipy.signal

    nyq = 0.5 / dt
    sos: np.ndarray = signal.butter(
        4, [params.band_low_hz / nyq, params.band_high_hz / nyq], btype="bandpass", output="sos"
    )
    if params.rolloff_hz > 0.0:
        low = signal.butter(2, params.rolloff_hz / nyq, output="sos")
        sos = np.concatenate([sos, low])
    return sos


class HandReference:
    """Block-wise generator of the reference position, velocity and feed-forward force.

    Args:
        params: the hand's settings.
        dt: sample period of the reference (s), the plant's physics step.
        rng: the random generator (seeded by the caller).
        block_s: length of one generated block (s); it changes when the work is done, not the
            samples.
    """

    def __init__(
        self, params: HandParams, dt: float, rng: np.random.Generator, block_s: float = BLOCK_S
    ) -> None:
        self.params = params
        self.dt = positive("dt", dt)
        self._rng = rng
        self._block = max(1, round(block_s / dt))
        self._start = 0
        self._ahead: Block | None = None  # the next block, generated early by ``prepare``
        self._last_x = 0.0
        self._sos = None
        self._zi = None
        self._scale = 0.0
        if params.behaviour == "semi_random" and params.amplitude_m > 0.0:
            self._sos = _band_filter(params, dt)
            self._zi = np.zeros((self._sos.shape[0], 2))
            self._scale = params.amplitude_m / _noise_gain(self._sos, dt, params.band_low_hz)
        self._pos, self._vel, self._ff = self._generate(0)

    def arrays(self, i: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
        """(position, velocity, feed-forward force) arrays holding sample ``i``, and its index.

        Samples are generated strictly in order; ``i`` must not go back before the current block.
        """
        while i >= self._start + self._block:
            start = self._start + self._block
            block, self._ahead = self._ahead or self._generate(start), None
            self._pos, self._vel, self._ff = block
            self._start = start
        if i < self._start:
            raise ValueError(f"hand reference sample {i} is before the current block")
        return self._pos, self._vel, self._ff, i - self._start

    def prepare(self, i: int) -> None:
        """Generate now the block that sample ``i`` will need, if it is the next one (a real-time
        device calls this while it waits, so no control period pays for a block)."""
        start = self._start + self._block
        if self._ahead is None and start <= i < start + self._block:
            self._ahead = self._generate(start)

    def _generate(self, start: int) -> Block:
        """The block starting at sample ``start`` (the next one: the generator moves on)."""
        p = self.params
        n = self._block
        t = (start + np.arange(n)) * self.dt
        if p.ramp_s > 0.0:
            ramp = np.where(
                t < p.ramp_s, 0.5 - 0.5 * np.cos(np.pi * np.minimum(t / p.ramp_s, 1.0)), 1.0
            )
        else:
            ramp = np.ones(n)
        pos = ramp * p.offset_m if p.active else np.zeros(n)
        if self._sos is not None:
            from scipy import signal  # lazy: loaded by _band_filter already

            noise, self._zi = signal.sosfilt(self._sos, self._rng.standard_normal(n), zi=self._zi)
            pos = pos + self._scale * ramp * noise
        prev = np.concatenate(([self._last_x], pos[:-1]))
        self._last_x = float(pos[-1])
        ff = np.zeros(n)
        if p.behaviour == "push_hold" and p.perturbation_n != 0.0 and p.perturbation_s > 0.0:
            on = (t >= p.perturbation_at_s) & (t < p.perturbation_at_s + p.perturbation_s)
            ff[on] = p.perturbation_n
        return pos, (pos - prev) / self.dt, ff


def _noise_gain(sos: np.ndarray, dt: float, low_hz: float) -> float:
    """Standard deviation of the filter's output for unit white noise at period ``dt`` (s).

    ``sigma^2 = 2 dt * integral_0^{fs/2} |H(f)|^2 df``, integrated on a log-spaced grid dense
    around the pass band.
    """
    from scipy import signal  # lazy: a device without a band starts without scipy.signal

    fs = 1.0 / dt
    f = np.geomspace(low_hz * 1e-3, fs / 2.0, 200_000)
    _, h = signal.sosfreqz(sos, worN=f, fs=fs)
    return math.sqrt(2.0 * dt * float(np.trapezoid(np.abs(h) ** 2, f)))
