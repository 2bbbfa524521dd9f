"""Table 7.1's cells that stay off, each swept against the parameter responsible (batch).

- 2400 N/m against the hand's grip damping (OL renders that wall soft across the band, so its
  band edge is ill-conditioned and follows the grip); OL there with a loose grip against
  Coulomb friction (without it, in plant and model, the wall keeps vibrating);
- 80 N/m against the hand's depth (offset and amplitude scaled together; thesis 7.3.2);
- every wall against the observer gain (DOB: for a large Kf the rendering rises past +3 dB near
  the corner ``c / (2 pi m)``) and against the plant's breakaway friction, up to 2.5 times
  Coulomb (thesis 7.3.3.1);
- 1600 and 2400 N/m against the force sensor's bandwidth (CL), with chapter 6's CL onset beside.

Each sweep's first value is the chapter-7 session's (from the configuration; per Kf for the
observer gain); the cells show bandwidth, coherence, the rendering's magnitude at the first bin
and up to 5 Hz, and the time at the force limit: the mechanism, not a constant fitted to the table.
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import Executor
from dataclasses import dataclass, field

import numpy as np

from haptic_dob.analysis.transparency import transparency
from haptic_sim.experiments import spread
from haptic_sim.experiments.observer_gain import gain_at
from haptic_sim.experiments.plan import CH7_CONTROLLERS, CH7_WALLS
from haptic_sim.slide.session import SessionConfig, run_session
from haptic_sim.slide.stability import law_for
from haptic_sim.slide.stability import sweep as stability_sweep

SETTLE_S = 2.0  # the hand's ramp-in, left out as the sessions' summaries leave it out
SEED = 0  # the hand's seed: chapter 7's default
DURATION_S = 40.0  # each session, as chapter 7's
Controller = tuple[str, float]


def _law(cfg: SessionConfig, mode: str, kf: float) -> SessionConfig:
    """The chapter-7 law (DOB: with the observer gain of its Kf)."""
    out = cfg.replace(law=law_for(mode, kf, cfg.law.max_force_n))
    return out.replace(observer__gain=gain_at(kf, cfg)) if mode == "DOB" else out


def _grip(cfg: SessionConfig, mode: str, kf: float, damping: float) -> SessionConfig:
    """The chapter-7 law, the hand's grip damping (N s/m) at ``damping``."""
    return _law(cfg, mode, kf).replace(hand__damping_n_s_per_m=damping)


def _depth(cfg: SessionConfig, mode: str, kf: float, scale: float) -> SessionConfig:
    """The chapter-7 law, the hand's reference offset and amplitude times ``scale``."""
    h = cfg.hand
    return _law(cfg, mode, kf).replace(
        hand__offset_m=h.offset_m * scale, hand__amplitude_m=h.amplitude_m * scale
    )


def _observer_gain(cfg: SessionConfig, mode: str, kf: float, gain: float) -> SessionConfig:
    """The chapter-7 law, the observer gain (N s/m) at ``gain``."""
    return _law(cfg, mode, kf).replace(observer__gain=gain)


def _loose_coulomb(cfg: SessionConfig, mode: str, kf: float, coulomb: float) -> SessionConfig:
    """The chapter-7 law with a loose grip (no damping), Coulomb friction (N) at ``coulomb`` in
    the plant and the observer's model."""
    return _law(cfg, mode, kf).replace(
        hand__damping_n_s_per_m=0.0, device__coulomb_n=coulomb, model__coulomb_n=coulomb
    )


def _stiction(cfg: SessionConfig, mode: str, kf: float, ratio: float) -> SessionConfig:
    """The chapter-7 law, the plant's breakaway friction at ``ratio`` times Coulomb."""
    return _law(cfg, mode, kf).replace(device__stiction_ratio=ratio)


def _sensor(cfg: SessionConfig, mode: str, kf: float, bandwidth: float) -> SessionConfig:
    """The chapter-7 law, the force sensor's bandwidth (Hz) at ``bandwidth``."""
    return _law(cfg, mode, kf).replace(sensor__bandwidth_hz=bandwidth)


def _hand_damping(b: SessionConfig, _kf: float) -> float:
    return b.hand.damping_n_s_per_m


def _unit_scale(_b: SessionConfig, _kf: float) -> float:
    return 1.0


def _gain(b: SessionConfig, kf: float) -> float:
    return gain_at(kf, b)


def _coulomb(b: SessionConfig, _kf: float) -> float:
    return b.device.coulomb_n


def _stiction_ratio(b: SessionConfig, _kf: float) -> float:
    return b.device.stiction_ratio


def _sensor_bandwidth(b: SessionConfig, _kf: float) -> float:
    return b.sensor.bandwidth_hz


@dataclass(frozen=True)
class Sweep:
    """One parameter swept at some walls for some controllers of Table 7.1."""

    name: str
    walls: tuple[float, ...]  # N/m
    parameter: str  # with its unit
    current: Callable[[SessionConfig, float], float]  # the chapter-7 value at a Kf, swept first
    values: tuple[float, ...]  # the others
    apply: Callable[[SessionConfig, str, float, float], SessionConfig]  # (cfg, mode, Kf, value)
    controllers: tuple[Controller, ...] = tuple(CH7_CONTROLLERS)
    onset_walls: tuple[float, ...] = ()  # chapter 6's linear onset over these walls, if any
    # (once per value: the onset does not depend on chapter 7's wall)

    def values_for(self, base: SessionConfig, kf: float) -> tuple[float, ...]:
        """The chapter-7 value at ``kf`` first, then the others."""
        now = self.current(base, kf)
        return (now, *(v for v in self.values if v != now))

    def config(
        self, base: SessionConfig, mode: str, kf: float, wall: float, value: float
    ) -> SessionConfig:
        """The chapter-7 session at ``wall`` (N/m) with the parameter at ``value``."""
        at_wall = base.replace(
            wall__stiffness_n_per_m=wall, loop__seed=SEED, loop__duration_s=DURATION_S
        )
        return self.apply(at_wall, mode, kf, value)


GRIP = Sweep("grip", (2400.0,), "grip damping (N s/m)", _hand_damping, (5.0, 2.0), _grip)
VIBRATING = Sweep(
    "vibrating",
    (2400.0,),
    "Coulomb friction of the plant and the model (N), the grip without damping",
    _coulomb,
    (0.0,),
    _loose_coulomb,
    (("OL", 0.0),),
)
DEPTH = Sweep(
    "depth", (80.0,), "hand's depth (times the configuration's)", _unit_scale, (2.0, 4.0), _depth
)
OBSERVER = Sweep(
    "observer",
    tuple(CH7_WALLS),
    "observer gain (N s/m)",
    _gain,
    (7.0, 10.0, 30.0, 146.0),
    _observer_gain,
    (("DOB", 1.0), ("DOB", 25.0)),
)
FRICTION = Sweep(
    "friction",
    tuple(CH7_WALLS),
    "plant's breakaway friction (times Coulomb)",
    _stiction_ratio,
    (2.0, 2.5),
    _stiction,
    (("DOB", 1.0), ("DOB", 25.0)),
)
SENSOR = Sweep(
    "sensor",
    (1600.0, 2400.0),
    "force sensor's bandwidth (Hz)",
    _sensor_bandwidth,
    (20.0, 5.0),
    _sensor,
    (("CL", 2.0),),
    (400.0, 500.0, 600.0, 700.0, 800.0, 900.0, 1000.0),
)
SWEEPS = (GRIP, VIBRATING, DEPTH, OBSERVER, FRICTION, SENSOR)


@dataclass(frozen=True)
class SweepCell:
    """One batch transparency session of a sweep."""

    sweep: str
    mode: str
    kf: float
    wall: float  # N/m
    value: float
    bandwidth_hz: float | None
    impedance_error_pct: float | None
    coherence_in_band: float | None
    first_bin_db: float | None  # |Z_hat / Z_d| at the lowest frequency bin (dB)
    mean_db_to_5hz: float | None  # its mean over the bins up to 5 Hz (dB)
    saturated_pct: float  # of the samples, the command at the force limit
    onset_n_per_m: float | None = None  # chapter 6's linear onset (a sweep with onset walls)
    below_first_bin: bool = False  # the band ends below the first bin (bandwidth: that bin's)


@dataclass(frozen=True)
class SweepStudy:
    """The sweeps part's result: every (sweep, controller, value) cell, and Table 7.1's cells for
    the hand's other seeds."""

    cells: list[SweepCell]
    seeds: list[spread.SeedCell] = field(default_factory=list)

    def of(self, sweep: str, mode: str, kf: float, wall: float | None = None) -> list[SweepCell]:
        """One controller's cells of one sweep (at one wall, or all), in the order run."""
        return [
            c
            for c in self.cells
            if (c.sweep, c.mode, c.kf) == (sweep, mode, kf) and wall in (None, c.wall)
        ]


@dataclass(frozen=True)
class _Measured:
    """What one batch session gives: a sweep cell's figures and Table 7.1's bandwidth (Hz)."""

    bandwidth_hz: float | None
    impedance_error_pct: float | None
    coherence_in_band: float | None
    first_bin_db: float | None
    mean_db_to_5hz: float | None
    saturated_pct: float
    onset_n_per_m: float | None  # chapter 6's linear onset over the job's walls, if any
    table_bandwidth_hz: float | None  # the session summary's, as Table 7.1 and ``spread`` read it
    below: bool  # the summary's band ends below the first bin


Job = tuple[SessionConfig, tuple[float, ...]]  # a session, and the walls of its onset (or ())


def _measure(job: Job) -> _Measured:
    cfg, onset_walls = job
    res = run_session(cfg)
    k0 = round(SETTLE_S * cfg.loop.rate_hz)
    limit = cfg.device.max_force_n * (1.0 - 1e-9)
    saturated = float(np.mean(np.abs(res.effort[k0:]) >= limit) * 100.0)
    onset = None
    if onset_walls:
        onset = stability_sweep(list(onset_walls), cfg).onset_stiffness_n_per_m
    summary = res.summary(SETTLE_S)
    table_bw, below = summary.bandwidth_hz, summary.band_below_first_bin
    try:
        tr = transparency(
            res.q[k0:], res.force_measured[k0:], cfg.loop.rate_hz, cfg.wall.stiffness_n_per_m
        )
    except ValueError:  # no motion to measure
        return _Measured(None, None, None, None, None, saturated, onset, table_bw, below)
    db = tr.magnitude_db
    return _Measured(
        tr.bandwidth_hz,
        tr.impedance_error_pct,
        tr.mean_coherence_in_band,
        float(db[0]),
        float(np.mean(db[tr.freqs_hz <= 5.0])),
        saturated,
        onset,
        table_bw,
        below,
    )


def _onset_walls(sweep: Sweep, wall: float) -> tuple[float, ...]:
    """The walls of chapter 6's onset for this cell: once per value, at the sweep's first wall."""
    return sweep.onset_walls if sweep.onset_walls and wall == sweep.walls[0] else ()


def _cell(sweep: Sweep, mode: str, kf: float, wall: float, value: float, m: _Measured) -> SweepCell:
    onset = m.onset_n_per_m if _onset_walls(sweep, wall) else None
    return SweepCell(
        sweep.name,
        mode,
        kf,
        wall,
        value,
        m.bandwidth_hz,
        m.impedance_error_pct,
        m.coherence_in_band,
        m.first_bin_db,
        m.mean_db_to_5hz,
        m.saturated_pct,
        onset,
        m.below,
    )


def _session(args: tuple[SessionConfig, Sweep, str, float, float, float]) -> SweepCell:
    """One sweep cell, run on its own."""
    base, sweep, mode, kf, wall, value = args
    cfg = sweep.config(base, mode, kf, wall, value)
    return _cell(sweep, mode, kf, wall, value, _measure((cfg, _onset_walls(sweep, wall))))


def study(base: SessionConfig, executor: Executor | None = None) -> SweepStudy:
    """Every sweep for its controllers (``DURATION_S`` sessions, seed ``SEED``) and Table 7.1 for
    the hand's other seeds (``spread``). A session that two cells share (each sweep's first
    value is a chapter-7 cell, and so is seed 0's table) runs once."""
    specs = [
        (s, mode, kf, wall, v)
        for s in SWEEPS
        for (mode, kf) in s.controllers
        for wall in s.walls
        for v in s.values_for(base, kf)
    ]
    seeds = spread.cells(base)
    runs: dict[SessionConfig, tuple[float, ...]] = {}  # each distinct session: its onset walls
    for s, mode, kf, wall, v in specs:
        cfg = s.config(base, mode, kf, wall, v)
        runs[cfg] = runs.get(cfg, ()) or _onset_walls(s, wall)
    for seed_cell in seeds:
        runs.setdefault(seed_cell.config, ())
    jobs = list(runs.items())
    measured = list(executor.map(_measure, jobs)) if executor else [_measure(j) for j in jobs]
    by_config = {cfg: m for (cfg, _), m in zip(jobs, measured, strict=True)}
    cells = [
        _cell(s, mode, kf, wall, v, by_config[s.config(base, mode, kf, wall, v)])
        for s, mode, kf, wall, v in specs
    ]
    return SweepStudy(
        cells,
        [
            c.with_bandwidth(by_config[c.config].table_bandwidth_hz, by_config[c.config].below)
            for c in seeds
        ],
    )
