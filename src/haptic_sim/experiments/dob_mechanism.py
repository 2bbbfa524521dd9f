"""Why the thesis's DOB wall (Kf = 100) kept quiet to 2400 N/m: the mechanism, with its knobs.

The linear loop model (``haptic_dob.analysis.linear_loop``) says the DOB loop at Kf = 100 is
unstable at every wall, yet the thesis saw sustained vibration only at 3200 N/m. Chapter 6's tap
protocol (``haptic_sim.slide.stability.TAP``: the light grip, the configuration's plant and
model with their friction, a 3 N x 20 ms tap) finds the first wall that keeps vibrating; the
study repeats it in batch and varies what the linear model leaves out or cannot decide: the
actuator saturation and the observer's output limit (4 N each), Coulomb friction (the plant's
and the model's, or none), the observer gain ``c`` up to ``chatter_gain`` (about
``2 m / (Kf T)``), and the hand's grip. Why each matters: docs/design/stability.md.

``residual`` (``haptic_sim.slide.stability``) measures what is left 2 to 3 s after the tap; a wall
vibrates when the hand would feel it (``felt``: its peak above the vibrotactile detection
threshold at its frequency).
"""

from __future__ import annotations

import dataclasses
from concurrent.futures import Executor
from dataclasses import dataclass
from typing import ClassVar

from haptic_dob.analysis.linear_loop import chatter_gain, linear_onset
from haptic_sim.experiments.observer_gain import gain_at
from haptic_sim.slide.session import SessionConfig, SessionResult, run_session
from haptic_sim.slide.stability import TAP, felt, law_for, tap_residual

WALLS = [800.0, 1600.0, 2000.0, 2400.0, 2800.0, 3200.0, 4000.0]
#: observer gains c (N s/m) of the grid, beside the configuration's
GAINS = [2.0, 4.0, 10.0, 41.6]
#: the linear model's table: Kf values (each with the grid's gains)
LINEAR_KFS = [1.0, 2.0, 25.0, 100.0]
#: the wall (N/m) of the stick-or-chatter traces
TRACES_WALL = 1600.0


def gains_of(base: SessionConfig) -> list[float]:
    """The grid's observer gains with the configuration's, ascending."""
    return sorted({*GAINS, base.observer.gain})


@dataclass(frozen=True)
class KickPoint:
    """The residual vibration of one (wall, c, friction) cell after the tap; ``coulomb_n`` is the
    plant's Coulomb friction (0: friction off in the plant and the model)."""

    stiffness_n_per_m: float
    gain: float
    coulomb_n: float
    residual_rms_m: float
    frequency_hz: float

    JSON_DERIVED: ClassVar[tuple[str, ...]] = ("vibrates",)

    @property
    def vibrates(self) -> bool:
        """True when the motion is still there 2-3 s after the tap."""
        return felt(self.residual_rms_m, self.frequency_hz)


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
class ChatterGain:
    """The observer gain (N s/m) above which DOB at ``kf`` chatters at the sample rate, on the
    simulated plant with its amplifier lag and without (the ``2 m / (Kf T)`` of the text)."""

    kf: float
    gain: float | None
    gain_without_lag: float | None


@dataclass(frozen=True)
class MismatchCell:
    """DOB transparency at one wall and Kf with one observer model (``assumed``, ``no Coulomb``)."""

    wall: float
    kf: float
    observer_model: str
    bandwidth_hz: float | None
    impedance_error_pct: float | None


@dataclass(frozen=True)
class Grip:
    """A hand holding the handle for the tap: its mass (kg), grip stiffness (N/m) and damping
    (N s/m)."""

    name: str
    mass_kg: float
    stiffness_n_per_m: float
    damping_n_s_per_m: float


#: chapter 6's light grip, and a hand as on the bench
GRIPS = (Grip("light grip", 0.0, 20.0, 0.0), Grip("bench hand", 0.1, 300.0, 5.0))


@dataclass(frozen=True)
class GripPoint:
    """The residual vibration after the tap at one wall with one hand (the configuration's
    observer and friction)."""

    grip: str
    stiffness_n_per_m: float
    residual_rms_m: float
    frequency_hz: float

    JSON_DERIVED: ClassVar[tuple[str, ...]] = ("vibrates",)

    @property
    def vibrates(self) -> bool:
        """True when the motion is still there 2-3 s after the tap."""
        return felt(self.residual_rms_m, self.frequency_hz)


@dataclass(frozen=True)
class DobStudy:
    """The dob part's result: the tap grid and its first vibrating walls, the linear model's
    onsets and chatter gains, the transparency with a mismatched observer model, and the tap
    with another hand."""

    kick: list[KickPoint]
    first_vibrating: list[FirstVibrating]
    linear: list[LinearOnset]
    chatter: list[ChatterGain]
    model_mismatch: list[MismatchCell]
    grips: list[GripPoint]

    def first_wall(self, gain: float, coulomb_n: float) -> float | None:
        """The first vibrating wall (N/m) of one (c, Coulomb) row; None if none or not run."""
        return next(
            (r.wall for r in self.first_vibrating if r.gain == gain and r.coulomb_n == coulomb_n),
            None,
        )

    def chatter_at(self, kf: float) -> float | None:
        """The chatter gain (N s/m, with the amplifier lag) at ``kf``; None if not computed."""
        return next((c.gain for c in self.chatter if c.kf == kf), None)


def tapped(base: SessionConfig, stiffness: float, gain: float, friction: bool) -> SessionConfig:
    """Chapter 6's tap session at one wall with observer gain ``gain`` (N s/m), the
    configuration's friction kept or (``friction`` False) off in the plant and the model."""
    protocol = TAP if friction else dataclasses.replace(TAP, coulomb_n=0.0)
    return protocol.session(base.replace(observer__gain=gain), stiffness)


def kick_point(base: SessionConfig, stiffness: float, gain: float, friction: bool) -> KickPoint:
    """Run one cell (DOB, the base's Kf) and measure what is left of the tap."""
    cfg = tapped(base, stiffness, gain, friction)
    rms, freq = tap_residual(run_session(cfg).q, cfg.loop.rate_hz)
    return KickPoint(stiffness, gain, cfg.device.coulomb_n, rms, freq)


def grip_point(base: SessionConfig, stiffness: float, grip: Grip) -> GripPoint:
    """The tap at one wall with ``grip`` holding the handle (DOB, the base's Kf, gain, friction)."""
    cfg = tapped(base, stiffness, base.observer.gain, True).replace(
        hand__mass_kg=grip.mass_kg,
        hand__stiffness_n_per_m=grip.stiffness_n_per_m,
        hand__damping_n_s_per_m=grip.damping_n_s_per_m,
        hand__offset_m=TAP.push_n * (1.0 / stiffness + 1.0 / grip.stiffness_n_per_m),
    )
    rms, freq = tap_residual(run_session(cfg).q, cfg.loop.rate_hz)
    return GripPoint(grip.name, stiffness, rms, freq)


def kick_grid(
    base: SessionConfig,
    kf: float = 100.0,
    walls: list[float] | None = None,
    gains: list[float] | None = None,
    executor: Executor | None = None,
) -> list[KickPoint]:
    """DOB at ``kf`` over walls x gains x (friction kept, off)."""
    dob = base.replace(law=law_for("DOB", kf, base.law.max_force_n))
    cells = [
        (k, c, f) for c in (gains or gains_of(base)) for f in (True, False) for k in walls or WALLS
    ]
    args = ([dob] * len(cells), *(list(x) for x in zip(*cells, strict=True)))
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


def chatter_gains(base: SessionConfig, kfs: list[float]) -> list[ChatterGain]:
    """The gain above which DOB chatters at the sample rate, per Kf: the observer's model mass
    and viscous friction (what its estimate divides by), the plant's amplifier lag."""
    m, b = base.model.mass_kg, base.model.viscous_n_s_per_m
    T, lag = 1.0 / base.loop.rate_hz, base.device.amplifier_lag_s
    return [
        ChatterGain(
            kf,
            chatter_gain(kf, m, b, T, amplifier_lag_s=lag),
            chatter_gain(kf, m, b, T),
        )
        for kf in kfs
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
        for kf in kfs:
            for name, model in models.items():
                cells.append((wall, kf, name))
                cfgs.append(
                    base.replace(
                        law=law_for("DOB", kf, base.law.max_force_n),
                        model=model,
                        observer__gain=gain_at(kf, base),
                        wall__stiffness_n_per_m=wall,
                        loop__seed=seed,
                    )
                )
    results = list(executor.map(_summary, cfgs)) if executor else [_summary(c) for c in cfgs]
    return [MismatchCell(*c, *r) for c, r in zip(cells, results, strict=True)]


def _summary(cfg: SessionConfig) -> tuple[float | None, float | None]:
    """(bandwidth Hz, impedance error %) of one batch session."""
    s = run_session(cfg).summary()
    return s.bandwidth_hz, s.impedance_error_pct


def traces(base: SessionConfig, stiffness: float, kf: float = 100.0) -> dict[str, SessionResult]:
    """The tap at one wall with the configuration's gain: with friction (sticks), without
    (chatters)."""
    dob = base.replace(law=law_for("DOB", kf, base.law.max_force_n))
    c = base.observer.gain
    return {
        name: run_session(tapped(dob, stiffness, c, friction))
        for name, friction in (("the plant's friction", True), ("no Coulomb friction", False))
    }


def study(base: SessionConfig, executor: Executor | None = None) -> DobStudy:
    """The whole mechanism study (batch; ``executor``: a shared process pool)."""
    kick = kick_grid(base, executor=executor)
    rows = sorted({(p.gain, p.coulomb_n) for p in kick})
    dob = base.replace(law=law_for("DOB", 100.0, base.law.max_force_n))
    cells = [(w, g) for g in GRIPS for w in WALLS]
    args = ([dob] * len(cells), [w for w, _ in cells], [g for _, g in cells])
    grips = list(executor.map(grip_point, *args)) if executor else list(map(grip_point, *args))
    return DobStudy(
        kick,
        [FirstVibrating(c, fc, first_vibrating(kick, c, fc)) for c, fc in rows],
        linear_onsets(base, gains_of(base), LINEAR_KFS),
        chatter_gains(base, LINEAR_KFS),
        model_mismatch(base, executor=executor),
        grips,
    )


def first_vibrating_with(points: list[GripPoint], grip: str) -> float | None:
    """The lowest wall (N/m) that keeps vibrating after the tap with one hand; None if none."""
    row = sorted((p for p in points if p.grip == grip), key=lambda p: p.stiffness_n_per_m)
    return next((p.stiffness_n_per_m for p in row if p.vibrates), None)
