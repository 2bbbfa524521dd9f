"""Vibration onset of a virtual wall in batch simulation: the protocol and the sweep.

Protocol (linear in-contact onset, thesis 6.1; docs/recording-and-analysis.md, "Vibration onset"):
``push_n`` (1 N) into the wall through a light grip (``grip_n_per_m``, no hand mass or damping),
Coulomb friction off in plant and model (``coulomb_n``: a value in both; None: the config's),
then a ``pulse_n`` (0.5 N) 5 ms pulse at 1.5 s. The growth rate is the slope of ln(envelope) of
the position about ``push / K`` into the wall over ``observe_s`` (2.5 s), ended at half the
penetration depth (a wall already oscillating that much vibrates: NaN); the onset stiffness is
its first zero crossing along the sweep, interpolated. Bound beside it: ``K (1 + Kf) < 2 b / T``.

``TAP`` (chapter 6's other protocol, docs/reproduction.md), for a loop only a nonlinearity keeps
quiet: the configuration's friction, a 3 N x 20 ms tap; a wall vibrates when the motion 2-3 s
later is ``felt``: its peak (``sqrt 2`` times the RMS about the slow trend, ``residual``) above
``detection_threshold_m`` at its dominant frequency.
"""

from __future__ import annotations

import itertools
import math
from concurrent.futures import Executor, ProcessPoolExecutor
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy import signal

from haptic_dob.analysis.vibration import perturbation_response
from haptic_dob.core.control import ControlMode, ImpedanceLaw
from haptic_dob.core.environment import VirtualWall
from haptic_dob.core.observers.factory import ObserverSettings
from haptic_dob.core.validation import nonnegative, positive
from haptic_sim.hand import HandParams
from haptic_sim.slide.session import SessionConfig, run_session


@dataclass(frozen=True)
class StabilityProtocol:
    """Settings of the push-and-hold onset protocol (see the module docstring)."""

    push_n: float = 1.0
    grip_n_per_m: float = 20.0
    pulse_n: float = 0.5
    pulse_s: float = 0.005
    ramp_s: float = 1.0
    pulse_at_s: float = 1.5
    observe_s: float = 2.5
    coulomb_n: float | None = 0.0  # None: the configuration's plant and model as they are

    def __post_init__(self) -> None:
        positive("push_n", self.push_n)
        positive("grip_n_per_m", self.grip_n_per_m)
        positive("pulse_s", self.pulse_s)
        positive("observe_s", self.observe_s)
        if self.coulomb_n is not None:
            nonnegative("coulomb_n", self.coulomb_n)
        if self.pulse_at_s < self.ramp_s:
            raise ValueError("pulse_at_s must not come before the end of the ramp")

    def session(self, base: SessionConfig, stiffness_n_per_m: float) -> SessionConfig:
        """The batch session of this protocol at one wall stiffness."""
        k = positive("stiffness_n_per_m", stiffness_n_per_m)
        hand = HandParams(
            behaviour="push_hold",
            mass_kg=0.0,
            stiffness_n_per_m=self.grip_n_per_m,
            damping_n_s_per_m=0.0,
            offset_m=self.push_n * (1.0 / k + 1.0 / self.grip_n_per_m),
            amplitude_m=0.0,
            ramp_s=self.ramp_s,
            perturbation_n=self.pulse_n,
            perturbation_at_s=self.pulse_at_s,
            perturbation_s=self.pulse_s,
        )
        wall = VirtualWall(k, base.wall.damping_n_s_per_m, base.wall.position, base.wall.normal)
        if self.coulomb_n is not None:  # the plant's and the assumed model's alike
            base = base.replace(model__coulomb_n=self.coulomb_n, device__coulomb_n=self.coulomb_n)
        return base.replace(hand=hand, wall=wall, loop__duration_s=self.duration_s)

    @property
    def duration_s(self) -> float:
        """The session's length (s): the pulse's time and the observation after it."""
        return self.pulse_at_s + self.observe_s


#: chapter 6's protocol for DOB at Kf = 100: the friction kept, a tap that breaks it
TAP = StabilityProtocol(pulse_n=3.0, pulse_s=0.02, observe_s=3.0, coulomb_n=None)
#: the vibrotactile detection threshold of the glabrous hand (peak displacement, m), after
#: Bolanowski, Gescheider, Verrillo and Checkosky (1988), "Four channels mediate the mechanical
#: aspects of touch", J. Acoust. Soc. Am. 84(5): the non-Pacinian I channel's plateau (about
#: 26 dB re 1 um) up to 40 Hz; above it the Pacinian channel's U, falling 12 dB per octave to its
#: minimum near 250 Hz and rising 9 dB per octave beyond (the slopes of Verrillo's curves)
THRESHOLD_PLATEAU_M = 20e-6
THRESHOLD_PLATEAU_HZ = 40.0
THRESHOLD_MINIMUM_HZ = 250.0


def detection_threshold_m(frequency_hz: float) -> float:
    """The smallest vibration (peak displacement, m) a hand holding the handle detects at
    ``frequency_hz`` (see ``THRESHOLD_PLATEAU_M``)."""
    f = float(positive("frequency_hz", frequency_hz))
    if f <= THRESHOLD_PLATEAU_HZ:
        return THRESHOLD_PLATEAU_M
    low = THRESHOLD_PLATEAU_M * (THRESHOLD_PLATEAU_HZ / min(f, THRESHOLD_MINIMUM_HZ)) ** 2
    return float(low * (max(f, THRESHOLD_MINIMUM_HZ) / THRESHOLD_MINIMUM_HZ) ** 1.5)


def felt(rms_m: float, frequency_hz: float) -> bool:
    """True when a vibration of ``rms_m`` RMS at ``frequency_hz`` (a sinusoid: peak sqrt 2 times
    the RMS) is above the hand's detection threshold."""
    return math.sqrt(2.0) * rms_m > detection_threshold_m(frequency_hz)


def residual(x: np.ndarray, rate_hz: float, start_s: float, end_s: float) -> tuple[float, float]:
    """(RMS about the slow trend in m, dominant frequency in Hz) of ``x`` over [start, end)."""
    seg = np.asarray(x, dtype=np.float64)[int(start_s * rate_hz) : int(end_s * rate_hz)]
    window = min(201, seg.size - (1 - seg.size % 2))
    fast = seg - signal.savgol_filter(seg, window, 2)
    freqs, power = signal.periodogram(fast, fs=rate_hz)
    return float(np.sqrt(np.mean(fast * fast))), float(freqs[1 + int(np.argmax(power[1:]))])


def tap_residual(
    x: np.ndarray, rate_hz: float, protocol: StabilityProtocol = TAP
) -> tuple[float, float]:
    """``residual`` over the last second of a ``protocol`` session's record ``x`` (m)."""
    end = protocol.duration_s
    return residual(x, rate_hz, end - 1.0, end)


@dataclass(frozen=True)
class StabilityPoint:
    """Result at one stiffness."""

    stiffness_n_per_m: float
    growth_per_s: float  # NaN when it already vibrated before the pulse
    frequency_hz: float
    amplitude_m: float  # envelope at the end of the fit
    vibrating_before_pulse: bool = False

    @property
    def vibrates(self) -> bool:
        """True when the oscillation grows (or was already sustained before the pulse)."""
        return bool(self.vibrating_before_pulse or self.growth_per_s > 0.0)


@dataclass(frozen=True)
class StabilitySweep:
    """A sweep's points, the onset and the theory bound."""

    controller: str
    kf: float
    observer_gain: float
    points: list[StabilityPoint] = field(default_factory=list)
    onset_stiffness_n_per_m: float | None = None
    theory_bound_n_per_m: float = math.nan

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready summary (``controller``, ``kf``, ``onset_stiffness_n_per_m`` ...)."""

        def num(x: float | None) -> float | None:
            return None if x is None or not math.isfinite(x) else float(x)

        return {
            "controller": self.controller,
            "kf": self.kf,
            "observer_gain": self.observer_gain,
            "onset_stiffness_n_per_m": self.onset_stiffness_n_per_m,
            "theory_bound_n_per_m": self.theory_bound_n_per_m,
            "points": [
                {
                    "stiffness_n_per_m": p.stiffness_n_per_m,
                    "growth_per_s": num(p.growth_per_s),
                    "frequency_hz": p.frequency_hz,
                    "amplitude_m": p.amplitude_m,
                    "vibrates": p.vibrates,
                    "vibrating_before_pulse": p.vibrating_before_pulse,
                }
                for p in self.points
            ],
        }


def theory_bound(base: SessionConfig, kf: float) -> float:
    """``2 b / (T (1 + Kf))`` (N/m) for the simulated plant's viscous friction b and the rate."""
    return 2.0 * base.device.viscous_n_s_per_m * base.loop.rate_hz / (1.0 + kf)


def growth_at(protocol: StabilityProtocol, base: SessionConfig, stiffness: float) -> StabilityPoint:
    """Run the protocol at one stiffness and measure the envelope growth."""
    cfg = protocol.session(base, stiffness)
    res = run_session(cfg)
    normal = np.asarray(cfg.wall.normal)
    depth = res.x_true * float(np.dot(cfg.model.axis, normal)) - float(
        np.dot(cfg.wall.position, normal)
    )
    r = perturbation_response(
        depth, cfg.loop.rate_hz, protocol.pulse_at_s, protocol.pulse_s, protocol.push_n / stiffness
    )
    return StabilityPoint(
        float(stiffness), r.growth_per_s, r.frequency_hz, r.amplitude_m, r.vibrating_before_pulse
    )


def sweep(
    stiffnesses: list[float] | np.ndarray,
    base: SessionConfig | None = None,
    protocol: StabilityProtocol | None = None,
    workers: int = 1,
    executor: Executor | None = None,
) -> StabilitySweep:
    """Run the protocol over ``stiffnesses`` (N/m, ascending) and locate the onset.

    ``executor`` (a process pool) runs the points in parallel and may be shared across sweeps;
    without one, ``workers > 1`` makes a pool for this sweep.
    """
    base = base or SessionConfig()
    protocol = protocol or StabilityProtocol()
    ks = [float(k) for k in stiffnesses]
    if not ks:
        raise ValueError("stiffnesses must not be empty")
    if any(b <= a for a, b in itertools.pairwise(ks)):
        raise ValueError("stiffnesses must be strictly ascending")
    args = ([protocol] * len(ks), [base] * len(ks), ks)
    if executor is not None:
        points = list(executor.map(growth_at, *args))
    elif workers > 1:
        with ProcessPoolExecutor(workers) as ex:
            points = list(ex.map(growth_at, *args))
    else:
        points = [growth_at(protocol, base, k) for k in ks]
    law = base.law
    kf = law.kf if law.mode is not ControlMode.OL else 0.0
    return StabilitySweep(
        controller=law.mode.value,
        kf=kf,
        observer_gain=base.observer.gain,
        points=points,
        onset_stiffness_n_per_m=onset(points),
        theory_bound_n_per_m=theory_bound(base, kf),
    )


def onset(points: list[StabilityPoint]) -> float | None:
    """First zero crossing of the growth rate (interpolated); None if nothing vibrates.

    If the first point already grows, its stiffness is the onset (the sweep started too high).
    """
    for i, p in enumerate(points):
        if p.vibrates:
            if i == 0 or not math.isfinite(p.growth_per_s):
                return p.stiffness_n_per_m
            q = points[i - 1]
            frac = -q.growth_per_s / (p.growth_per_s - q.growth_per_s)
            return q.stiffness_n_per_m + frac * (p.stiffness_n_per_m - q.stiffness_n_per_m)
    return None


def law_for(controller: str, kf: float, max_force_n: float = 4.0) -> ImpedanceLaw:
    """The ``ImpedanceLaw`` of a controller name and gain (Kf ignored for OL)."""
    mode = ControlMode.parse(controller)
    kf = nonnegative("kf", kf)
    return ImpedanceLaw(mode, kf if mode is not ControlMode.OL else 0.0, max_force_n)


__all__ = [
    "TAP",
    "THRESHOLD_PLATEAU_M",
    "ObserverSettings",
    "StabilityPoint",
    "StabilityProtocol",
    "StabilitySweep",
    "detection_threshold_m",
    "felt",
    "growth_at",
    "law_for",
    "onset",
    "residual",
    "sweep",
    "tap_residual",
    "theory_bound",
]
