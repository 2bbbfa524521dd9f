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
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

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

    @property
    def vibrates(self) -> bool:
        """True when the motion is still there 2-3 s after the kick."""
        return self.residual_rms_m > VIBRATION_RMS_M


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


def linear_onsets(base: SessionConfig, gains: list[float], kfs: list[float]) -> list[dict]:
    """The linear model's DOB onsets (N/m) against c for each Kf, with the CL bound, no grip."""
    m, b = base.model.mass_kg, base.model.viscous_n_s_per_m
    T = 1.0 / base.loop.rate_hz
    rows = []
    for kf in kfs:
        for c in gains:
            rows.append(
                {
                    "kf": kf,
                    "gain": c,
                    "dob_onset_n_per_m": linear_onset(kf, "DOB", c, m, b, T),
                    "cl_onset_n_per_m": linear_onset(kf, "CL", c, m, b, T),
                }
            )
    return rows


def bandwidth_vs_gain(
    base: SessionConfig,
    gains: list[float],
    kf: float = 1.0,
    wall: float = 800.0,
    seed: int = 0,
    duration_s: float = 40.0,
    executor: Executor | None = None,
) -> list[dict]:
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
    return [{"gain": c, "kf": kf, "wall": wall, **s} for c, s in zip(gains, results, strict=True)]


def model_mismatch(
    base: SessionConfig,
    kfs: tuple[float, ...] = (1.0, 25.0),
    walls: tuple[float, ...] = (800.0, 1600.0),
    seed: int = 0,
    executor: Executor | None = None,
) -> list[dict]:
    """DOB transparency with the exact observer model and one without Coulomb friction (batch).

    The thesis (7.3.3.1) blames the high-gain DOB's narrower band on modelling errors: friction
    underestimated at low speed. Leaving Coulomb friction out of the observer's model is that
    error in its simplest form.
    """
    m = base.model
    models = {
        "exact": None,
        "no Coulomb": m.__class__(m.mass_kg, m.viscous_n_s_per_m, 0.0, m.axis),
    }
    cells, cfgs = [], []
    for wall in walls:
        offset, amplitude = reference_for_force(wall, base.hand.stiffness_n_per_m)
        for kf in kfs:
            for name, model in models.items():
                cells.append({"wall": wall, "kf": kf, "observer_model": name})
                cfgs.append(
                    base.replace(
                        law=law_for("DOB", kf, base.law.max_force_n),
                        observer_model=model,
                        wall__stiffness_n_per_m=wall,
                        hand__offset_m=offset,
                        hand__amplitude_m=amplitude,
                        loop__seed=seed,
                    )
                )
    results = list(executor.map(_summary, cfgs)) if executor else [_summary(c) for c in cfgs]
    return [{**c, **r} for c, r in zip(cells, results, strict=True)]


def _summary(cfg: SessionConfig) -> dict[str, Any]:
    s = run_session(cfg).summary()
    return {"bandwidth_hz": s["bandwidth_hz"], "impedance_error_pct": s["impedance_error_pct"]}


def traces(base: SessionConfig, stiffness: float, kf: float = 100.0) -> dict[str, SessionResult]:
    """The kick at one wall with c = 2: with Coulomb friction (sticks) and without (chatters)."""
    dob = base.replace(law=law_for("DOB", kf, base.law.max_force_n))
    p = KickProtocol()
    return {
        f"Coulomb {fc:g} N": run_session(p.session(dob, stiffness, 2.0, fc)) for fc in (0.24, 0.0)
    }


def plot_grid(points: list[KickPoint], path: Path) -> None:
    """Residual RMS against wall stiffness, one line per (c, Coulomb)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for c, fc in sorted({(p.gain, p.coulomb_n) for p in points}):
        row = sorted(
            (p for p in points if p.gain == c and p.coulomb_n == fc),
            key=lambda p: p.stiffness_n_per_m,
        )
        ax.semilogy(
            [p.stiffness_n_per_m for p in row],
            [max(p.residual_rms_m, 1e-9) * 1e6 for p in row],
            marker="o",
            label=f"c = {c:g} N s/m, Coulomb {fc:g} N",
        )
    ax.axhline(VIBRATION_RMS_M * 1e6, color="k", ls=":", lw=0.8, label="vibration threshold")
    ax.set_xlabel("wall stiffness (N/m)")
    ax.set_ylabel("residual motion 2-3 s after the kick (um RMS)")
    ax.set_title("DOB Kf = 100 on the slide: what stops the vibration")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_traces(runs: dict[str, SessionResult], stiffness: float, path: Path) -> None:
    """Depth and command around the kick, with and without Coulomb friction."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7.0, 5.0), sharex=True)
    for name, r in runs.items():
        ax1.plot(r.t, r.x_true * 1e3, lw=0.8, label=name)
        ax2.plot(r.t, r.effort, lw=0.6, label=name)
    ax1.set_ylabel("position (mm)")
    ax2.set_ylabel("applied effort (N)")
    ax2.set_xlabel("time (s)")
    ax1.set_title(f"DOB Kf = 100, c = 2 N s/m, {stiffness:g} N/m wall: the kick at 1.5 s")
    ax1.legend(fontsize=8)
    for ax in (ax1, ax2):
        ax.grid(True, alpha=0.3)
    ax2.set_xlim(1.3, 2.5)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def as_dicts(points: list[KickPoint]) -> list[dict]:
    """JSON-ready rows."""
    return [{**asdict(p), "vibrates": p.vibrates} for p in points]
