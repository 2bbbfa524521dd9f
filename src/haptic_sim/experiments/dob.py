"""Why the thesis's DOB wall (Kf = 100) stayed quiet to 3200 N/m: the mechanism, with the knobs.

The force-feedback bound ``2 b / (T (1 + Kf))`` is 25 N/m at Kf = 100, and the linear loop model
(``haptic_dob.analysis.linear_loop``) says the DOB loop is even less stable than that. Yet the
thesis saw no sustained vibration below 3200 N/m. The study here runs the slide in batch with a
hand as on the bench (``KickProtocol``: a 0.1 kg hand holding the handle through a 300 N/m grip
with 5 N s/m, pushing 1.5 N into the wall, kicked with 3 N for 20 ms) and varies what the linear
model leaves out:

- the actuator saturation (4 N) and the observer's output limit (4 N): the high-gain loop is
  linear only in a band of ``2 u_max / (Kf K)`` of position around equilibrium, so a growing
  oscillation soon saturates and the loop acts as a relay (bang-bang) of bounded amplitude;
- Coulomb friction (0.24 N): a relay chatter of small amplitude sticks, and the slide stays where
  the wall's push and the hand balance, the observer then reading the steady hand force;
- the observer gain ``c``: a slow observer (c = 2 N s/m, the only gain the thesis states, for the
  PHANToM) leaves the stuck state alone; a fast one (41.6 N s/m, tuned for the chapter-7 bandwidth)
  keeps re-exciting it.

``residual`` measures what is left 2 to 3 s after the kick (RMS of the depth about its slow
trend, and its dominant frequency); a wall vibrates when that exceeds ``VIBRATION_RMS_M``.
"""

from __future__ import annotations

from concurrent.futures import Executor
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from scipy import signal

from haptic_dob.analysis.linear_loop import linear_onset
from haptic_dob.observer import ObserverSettings
from haptic_sim.hand import reference_for_force
from haptic_sim.session import SessionConfig, SessionResult, run_session
from haptic_sim.stability import StabilityProtocol, law_for

#: a wall vibrates when the residual motion 2-3 s after the kick exceeds this RMS (m)
VIBRATION_RMS_M = 2e-6
WALLS = [400.0, 800.0, 1600.0, 2400.0, 3200.0, 4000.0]
#: (observer gain c in N s/m, Coulomb friction in N) combinations of the grid
KNOBS = [(2.0, 0.24), (2.0, 0.0), (41.6, 0.24), (41.6, 0.0)]
GAINS_FOR_BANDWIDTH = [2.0, 5.0, 10.0, 20.0, 41.6]
#: the linear model's table: observer gains c (N s/m) for each Kf
LINEAR_GAINS = [2.0, 10.0, 41.6]
LINEAR_KFS = [1.0, 2.0, 25.0, 100.0]
#: the wall (N/m) of the stick-or-chatter traces
TRACES_WALL = 1600.0


@dataclass(frozen=True)
class KickProtocol:
    """A hand as on the bench holds the handle against the wall and is kicked once."""

    push_n: float = 1.5
    grip_n_per_m: float = 300.0
    hand_mass_kg: float = 0.1
    hand_damping_n_s_per_m: float = 5.0
    kick_n: float = 3.0
    kick_s: float = 0.02
    kick_at_s: float = 1.5
    observe_s: float = 3.0

    def session(
        self, base: SessionConfig, stiffness: float, gain: float, coulomb_n: float
    ) -> SessionConfig:
        """The batch session at one wall, observer gain (N s/m) and Coulomb friction (N)."""
        onset = StabilityProtocol(
            push_n=self.push_n,
            grip_n_per_m=self.grip_n_per_m,
            pulse_n=self.kick_n,
            pulse_s=self.kick_s,
            pulse_at_s=self.kick_at_s,
            observe_s=self.observe_s,
            coulomb_n=coulomb_n,
        )
        with_gain = base.replace(observer=ObserverSettings(gain, base.observer.output_limit))
        return onset.session(with_gain, stiffness).replace(
            hand__mass_kg=self.hand_mass_kg,
            hand__damping_n_s_per_m=self.hand_damping_n_s_per_m,
        )


@dataclass(frozen=True)
class KickPoint:
    """The residual vibration of one (wall, c, Coulomb) cell."""

    stiffness_n_per_m: float
    gain: float
    coulomb_n: float
    residual_rms_m: float
    frequency_hz: float

    JSON_DERIVED: ClassVar[tuple[str, ...]] = ("vibrates",)

    @property
    def vibrates(self) -> bool:
        """True when the motion is still there 2-3 s after the kick."""
        return self.residual_rms_m > VIBRATION_RMS_M


@dataclass(frozen=True)
class FirstVibrating:
    """The lowest wall (N/m) that vibrates in one (c, Coulomb) row of the grid; None if none."""

    gain: float
    coulomb_n: float
    wall: float | None


@dataclass(frozen=True)
class LinearOnset:
    """The linear model's lowest unstable wall (N/m; 0: any, None: stable) at one Kf and c."""

    kf: float
    gain: float
    dob_onset_n_per_m: float | None
    cl_onset_n_per_m: float | None  # CL with an ideal sensor, for comparison


@dataclass(frozen=True)
class GainBandwidth:
    """DOB transparency (batch, the chapter-7 hand) at one observer gain c (N s/m)."""

    gain: float
    kf: float
    wall: float
    bandwidth_hz: float | None
    impedance_error_pct: float | None


@dataclass(frozen=True)
class MismatchCell:
    """DOB transparency at one wall and Kf with one observer model (``assumed``, ``no Coulomb``)."""

    wall: float
    kf: float
    observer_model: str
    bandwidth_hz: float | None
    impedance_error_pct: float | None


@dataclass(frozen=True)
class DobStudy:
    """The dob part's result: the kick grid, its first vibrating walls, the linear model, and
    the transparency against the observer gain and with a mismatched observer model."""

    kick: list[KickPoint]
    first_vibrating: list[FirstVibrating]
    linear: list[LinearOnset]
    bandwidth_vs_gain: list[GainBandwidth]
    model_mismatch: list[MismatchCell]

    def first_wall(self, gain: float, coulomb_n: float) -> float | None:
        """The first vibrating wall (N/m) of one (c, Coulomb) row; None if none or not run."""
        return next(
            (r.wall for r in self.first_vibrating if r.gain == gain and r.coulomb_n == coulomb_n),
            None,
        )


def residual(x: np.ndarray, rate_hz: float, start_s: float, end_s: float) -> tuple[float, float]:
    """(RMS about the slow trend in m, dominant frequency in Hz) of ``x`` over [start, end)."""
    seg = x[int(start_s * rate_hz) : int(end_s * rate_hz)]
    window = min(201, seg.size - (1 - seg.size % 2))
    fast = seg - signal.savgol_filter(seg, window, 2)
    freqs, power = signal.periodogram(fast, fs=rate_hz)
    return float(np.sqrt(np.mean(fast * fast))), float(freqs[1 + int(np.argmax(power[1:]))])


def kick_point(
    protocol: KickProtocol,
    base: SessionConfig,
    stiffness: float,
    gain: float,
    coulomb_n: float,
) -> KickPoint:
    """Run one cell (DOB, the base's Kf) and measure what is left of the kick."""
    cfg = protocol.session(base, stiffness, gain, coulomb_n)
    res = run_session(cfg)
    end = protocol.kick_at_s + protocol.observe_s
    rms, freq = residual(res.x_true, cfg.loop.rate_hz, end - 1.0, end)
    return KickPoint(stiffness, gain, coulomb_n, rms, freq)


def kick_grid(
    base: SessionConfig,
    kf: float = 100.0,
    walls: list[float] | None = None,
    knobs: list[tuple[float, float]] | None = None,
    executor: Executor | None = None,
) -> list[KickPoint]:
    """DOB at ``kf`` over walls x (c, Coulomb)."""
    dob = base.replace(law=law_for("DOB", kf, base.law.max_force_n))
    cells = [(k, c, fc) for c, fc in (knobs or KNOBS) for k in (walls or WALLS)]
    args = (
        [KickProtocol()] * len(cells),
        [dob] * len(cells),
        [k for k, _, _ in cells],
        [c for _, c, _ in cells],
        [fc for _, _, fc in cells],
    )
    if executor is None:
        return [kick_point(*a) for a in zip(*args, strict=True)]
    return list(executor.map(kick_point, *args))


def first_vibrating(points: list[KickPoint], gain: float, coulomb_n: float) -> float | None:
    """The lowest wall (N/m) that vibrates in one (c, Coulomb) row; None if none does."""
    row = sorted(
        (p for p in points if p.gain == gain and p.coulomb_n == coulomb_n),
        key=lambda p: p.stiffness_n_per_m,
    )
    return next((p.stiffness_n_per_m for p in row if p.vibrates), None)


def linear_onsets(base: SessionConfig, gains: list[float], kfs: list[float]) -> list[LinearOnset]:
    """The linear model's DOB onsets (N/m) against c for each Kf, with the CL bound, no grip, on
    the simulated plant (its mass, viscous friction and amplifier lag)."""
    d = base.device
    m, b, lag = d.mass_kg, d.viscous_n_s_per_m, d.amplifier_lag_s
    T = 1.0 / base.loop.rate_hz

    def onset(kf: float, mode: str, c: float) -> float | None:
        return linear_onset(kf, mode, c, m, b, T, amplifier_lag_s=lag)

    return [
        LinearOnset(kf, c, onset(kf, "DOB", c), onset(kf, "CL", c)) for kf in kfs for c in gains
    ]


def bandwidth_vs_gain(
    base: SessionConfig,
    gains: list[float],
    kf: float = 1.0,
    wall: float = 800.0,
    seed: int = 0,
    duration_s: float = 40.0,
    executor: Executor | None = None,
) -> list[GainBandwidth]:
    """DOB transparency bandwidth (Hz) at one wall against the observer gain (batch, ch. 7 hand)."""
    offset, amplitude = reference_for_force(wall, base.hand.stiffness_n_per_m)
    cfgs = [
        base.replace(
            law=law_for("DOB", kf, base.law.max_force_n),
            observer=ObserverSettings(c, base.observer.output_limit),
            wall__stiffness_n_per_m=wall,
            hand__offset_m=offset,
            hand__amplitude_m=amplitude,
            loop__seed=seed,
            loop__duration_s=duration_s,
        )
        for c in gains
    ]
    results = list(executor.map(_summary, cfgs)) if executor else [_summary(c) for c in cfgs]
    return [
        GainBandwidth(c, kf, wall, bw, err) for c, (bw, err) in zip(gains, results, strict=True)
    ]


def model_mismatch(
    base: SessionConfig,
    kfs: tuple[float, ...] = (1.0, 25.0),
    walls: tuple[float, ...] = (800.0, 1600.0),
    seed: int = 0,
    executor: Executor | None = None,
) -> list[MismatchCell]:
    """DOB transparency with the assumed model and the same without Coulomb friction (batch).

    The thesis (7.3.3.1) blames the high-gain DOB's narrower band on modelling errors: friction
    underestimated at low speed. Leaving Coulomb friction out of the observer's model is that
    error in its simplest form.
    """
    m = base.model
    models = {
        "assumed": m,
        "no Coulomb": m.__class__(m.mass_kg, m.viscous_n_s_per_m, 0.0, m.axis),
    }
    cells: list[tuple[float, float, str]] = []
    cfgs = []
    for wall in walls:
        offset, amplitude = reference_for_force(wall, base.hand.stiffness_n_per_m)
        for kf in kfs:
            for name, model in models.items():
                cells.append((wall, kf, name))
                cfgs.append(
                    base.replace(
                        law=law_for("DOB", kf, base.law.max_force_n),
                        model=model,
                        wall__stiffness_n_per_m=wall,
                        hand__offset_m=offset,
                        hand__amplitude_m=amplitude,
                        loop__seed=seed,
                    )
                )
    results = list(executor.map(_summary, cfgs)) if executor else [_summary(c) for c in cfgs]
    return [MismatchCell(*c, *r) for c, r in zip(cells, results, strict=True)]


def _summary(cfg: SessionConfig) -> tuple[float | None, float | None]:
    """(bandwidth Hz, impedance error %) of one batch session."""
    s = run_session(cfg).summary()
    return s["bandwidth_hz"], s["impedance_error_pct"]


def traces(base: SessionConfig, stiffness: float, kf: float = 100.0) -> dict[str, SessionResult]:
    """The kick at one wall with c = 2: with Coulomb friction (sticks) and without (chatters)."""
    dob = base.replace(law=law_for("DOB", kf, base.law.max_force_n))
    p = KickProtocol()
    return {
        f"Coulomb {fc:g} N": run_session(p.session(dob, stiffness, 2.0, fc)) for fc in (0.24, 0.0)
    }


def study(base: SessionConfig, executor: Executor | None = None) -> DobStudy:
    """The whole mechanism study (batch; ``executor``: a shared process pool)."""
    kick = kick_grid(base, executor=executor)
    return DobStudy(
        kick,
        [FirstVibrating(c, fc, first_vibrating(kick, c, fc)) for c, fc in KNOBS],
        linear_onsets(base, LINEAR_GAINS, LINEAR_KFS),
        bandwidth_vs_gain(base, GAINS_FOR_BANDWIDTH, executor=executor),
        model_mismatch(base, executor=executor),
    )
