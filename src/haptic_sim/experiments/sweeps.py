"""Table 7.1's cells that stay off, each swept against the parameter responsible (batch).

- **2400 N/m against the hand's grip damping.** The bandwidth is the first frequency where the
  rendered impedance falls 3 dB below the wall's. At 2400 N/m OL renders the wall 1.5-3 dB soft
  across the whole band, so that edge is ill-conditioned: with the chapter-7 grip (10 N s/m) it
  lies near 6 Hz, with a looser one (the bench hand's 5 N s/m, and below) the first bin passes
  -3 dB and the band ends there, which fits the thesis's 0.6 Hz.
- **80 N/m against the actuator's force limit.** At a soft wall the hand's swing moves the
  handle centimetres; force feedback multiplies the force error by ``1 + Kf``, and CL Kf = 2 and
  DOB Kf = 25 spend much of the session at the 4 N limit: the loop is not linear there, the
  coherence collapses and the band ends at the first bin. A larger limit restores the coherence.
- **Every wall against the observer gain (DOB).** For a large Kf the rendered impedance rises past
  +3 dB near the observer's corner ``c / (2 pi m)``, so DOB Kf = 25's band follows c; DOB Kf = 1
  needs a fast observer to reach the mass line ``m / 2`` the thesis's cells sit near, and a gain
  that fast chatters at Kf = 25 (above about ``2 m / (Kf T)``: the time at the limit).
- **1600 and 2400 N/m against the force sensor's bandwidth (CL).** CL's band follows the mass line
  ``m / (1 + Kf)`` above the thesis's 4.5 Hz; a slower sensor lowers it only when it also lowers
  the CL onset of chapter 6's linear protocol below the thesis's 800 N/m (the onset column).

Each sweep's first value is the chapter-7 session's (read from the configuration); the cells
show the bandwidth, coherence, the rendering's magnitude at the first bin and up to 5 Hz, and the
time at the force limit, so the report shows the mechanism rather than a constant fitted to the
table.
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import Executor
from dataclasses import dataclass, field

import numpy as np

from haptic_dob.analysis.transparency import transparency
from haptic_sim.experiments import spread, thesis
from haptic_sim.experiments.tables import fmt
from haptic_sim.hand import reference_for_force
from haptic_sim.slide.session import SessionConfig, run_session
from haptic_sim.slide.stability import law_for
from haptic_sim.slide.stability import sweep as stability_sweep

SETTLE_S = 2.0  # the hand's ramp-in, left out as the sessions' summaries leave it out
SEED = 0  # the hand's seed: chapter 7's default
DURATION_S = 40.0  # each session, as chapter 7's
Controller = tuple[str, float]


def _grip(cfg: SessionConfig, mode: str, kf: float, damping: float) -> SessionConfig:
    """The chapter-7 law, the hand's grip damping (N s/m) at ``damping``."""
    law = law_for(mode, kf, cfg.law.max_force_n)
    return cfg.replace(law=law, hand__damping_n_s_per_m=damping)


def _force_limit(cfg: SessionConfig, mode: str, kf: float, limit: float) -> SessionConfig:
    """The law's and the actuator's force limit (N) at ``limit``."""
    return cfg.replace(law=law_for(mode, kf, limit), device__max_force_n=limit)


def _observer_gain(cfg: SessionConfig, mode: str, kf: float, gain: float) -> SessionConfig:
    """The chapter-7 law, the observer gain (N s/m) at ``gain``."""
    return cfg.replace(law=law_for(mode, kf, cfg.law.max_force_n), observer__gain=gain)


def _sensor(cfg: SessionConfig, mode: str, kf: float, bandwidth: float) -> SessionConfig:
    """The chapter-7 law, the force sensor's bandwidth (Hz) at ``bandwidth``."""
    law = law_for(mode, kf, cfg.law.max_force_n)
    return cfg.replace(law=law, sensor__bandwidth_hz=bandwidth)


def _hand_damping(b: SessionConfig) -> float:
    return b.hand.damping_n_s_per_m


def _max_force(b: SessionConfig) -> float:
    return b.device.max_force_n


def _gain(b: SessionConfig) -> float:
    return b.observer.gain


def _sensor_bandwidth(b: SessionConfig) -> float:
    return b.sensor.bandwidth_hz


@dataclass(frozen=True)
class Sweep:
    """One parameter swept at some walls for some controllers of Table 7.1."""

    name: str
    walls: tuple[float, ...]  # N/m
    parameter: str  # with its unit
    current: Callable[[SessionConfig], float]  # the chapter-7 session's value, swept first
    values: tuple[float, ...]  # the others
    apply: Callable[[SessionConfig, str, float, float], SessionConfig]  # (cfg, mode, Kf, value)
    controllers: tuple[Controller, ...] = tuple(thesis.BANDWIDTH_HZ)
    onset_walls: tuple[float, ...] = ()  # chapter 6's linear onset over these walls, if any
    # (once per value: the onset does not depend on chapter 7's wall)

    def values_for(self, base: SessionConfig) -> tuple[float, ...]:
        """The chapter-7 value first, then the others."""
        now = self.current(base)
        return (now, *(v for v in self.values if v != now))

    def config(
        self, base: SessionConfig, mode: str, kf: float, wall: float, value: float
    ) -> SessionConfig:
        """The chapter-7 session at ``wall`` (N/m) with the parameter at ``value``."""
        offset, amplitude = reference_for_force(wall, base.hand.stiffness_n_per_m)
        at_wall = base.replace(
            wall__stiffness_n_per_m=wall,
            hand__offset_m=offset,
            hand__amplitude_m=amplitude,
            loop__seed=SEED,
            loop__duration_s=DURATION_S,
        )
        return self.apply(at_wall, mode, kf, value)


GRIP = Sweep(
    "grip",
    (2400.0,),
    "grip damping (N s/m)",
    _hand_damping,
    (5.0, 2.0),
    _grip,
)
FORCE_LIMIT = Sweep(
    "force_limit",
    (80.0,),
    "force limit (N)",
    _max_force,
    (8.0, 16.0),
    _force_limit,
    (("CL", 2.0), ("DOB", 25.0)),
)
OBSERVER = Sweep(
    "observer",
    tuple(thesis.WALLS),
    "observer gain (N s/m)",
    _gain,
    (10.0, 41.6),
    _observer_gain,
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
SWEEPS = (GRIP, FORCE_LIMIT, OBSERVER, SENSOR)


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
    table_bw = res.summary(SETTLE_S).bandwidth_hz
    try:
        tr = transparency(
            res.q[k0:], res.force_measured[k0:], cfg.loop.rate_hz, cfg.wall.stiffness_n_per_m
        )
    except ValueError:  # no motion to measure
        return _Measured(None, None, None, None, None, saturated, onset, table_bw)
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
        for v in s.values_for(base)
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
        cells, [c.with_bandwidth(by_config[c.config].table_bandwidth_hz) for c in seeds]
    )


def label(mode: str, kf: float) -> str:
    """``OL``, ``CL Kf=2``..."""
    return mode if mode == "OL" else f"{mode} Kf={kf:g}"


def _cell_text(c: SweepCell) -> str:
    onset = "" if c.onset_n_per_m is None else f"; onset {c.onset_n_per_m:.0f}"
    return (
        f"{fmt(c.bandwidth_hz)} ({fmt(c.coherence_in_band)}); "
        f"{fmt(c.first_bin_db, '+.1f')} / {fmt(c.mean_db_to_5hz, '+.1f')}; "
        f"{c.saturated_pct:.0f} %{onset}"
    )


def sweep_table(r: SweepStudy, sweep: Sweep) -> str:
    """One sweep's table: a row per controller and wall, a column per value (in the order run),
    the thesis's cell last; chapter 6's linear onset per value where the sweep measures it."""
    values = list(dict.fromkeys(c.value for c in r.cells if c.sweep == sweep.name))
    if not values:
        return ""
    walls = ", ".join(f"{w:g}" for w in sweep.walls)
    lines = [
        f"**{walls} N/m against the {sweep.parameter}** (the first column is chapter 7's): "
        "bandwidth in Hz (coherence in the band); |Z_hat / Z_d| at the first bin / its mean up "
        "to 5 Hz (dB); time at the force limit"
        + ("; chapter 6's linear onset (N/m)" if sweep.onset_walls else "")
        + ":",
        "",
        "| | " + " | ".join(f"{v:g}" for v in values) + " | thesis (Hz) |",
        "|---|" + "---|" * (len(values) + 1),
    ]
    for mode, kf in sweep.controllers:
        for wall in sweep.walls:
            by_value = {c.value: c for c in r.of(sweep.name, mode, kf, wall)}
            if not by_value:
                continue
            cols = [_cell_text(by_value[v]) if v in by_value else "-" for v in values]
            ref = thesis.cell(mode, kf, wall)[0]
            name = label(mode, kf) + ("" if len(sweep.walls) == 1 else f", {wall:g} N/m")
            lines.append(f"| {name} | " + " | ".join(cols) + f" | {fmt(ref, 'g')} |")
    return "\n".join(lines) + "\n"
