"""Table 7.1 for several seeds of the hand (batch): how far one 40 s session pins a cell down.

The thesis measured each cell once, with one user's 40 s of motion; chapter 7 here runs one
seed of the simulated hand. Running the same cells for other seeds (batch, the graph's cycle
timing: seed 0 is chapter 7's own table to the bit) shows how much of a cell's distance from the
thesis is the hand's draw. This module runs them and takes their median; ``spread_report`` sets
them beside the thesis (this one never reads it). A band that ends below the first frequency
bin is a resolution floor, not a measured edge: its median is no value.
"""

from __future__ import annotations

import statistics
from concurrent.futures import Executor
from dataclasses import dataclass

from haptic_sim.experiments.observer_gain import gain_at
from haptic_sim.experiments.plan import CH7_CONTROLLERS, CH7_WALLS
from haptic_sim.slide.session import SessionConfig, run_session
from haptic_sim.slide.stability import law_for

SEEDS = (0, 1, 2)
DURATION_S = 40.0  # chapter 7's sessions


@dataclass(frozen=True)
class SeedCell:
    """One Table 7.1 cell for one seed of the hand: its bandwidth (Hz; None if none) and whether
    the band ended below the first frequency bin (then the bandwidth is that bin's)."""

    seed: int
    mode: str
    kf: float
    wall: float
    bandwidth_hz: float | None
    below_first_bin: bool = False


def chapter7_session(
    base: SessionConfig, mode: str, kf: float, wall: float, seed: int
) -> SessionConfig:
    """A chapter-7 cell in batch: the law (DOB: the observer gain of its Kf), the wall, the
    configuration's hand, the seed."""
    cfg = base.replace(
        law=law_for(mode, kf, base.law.max_force_n),
        wall__stiffness_n_per_m=wall,
        loop__seed=seed,
        loop__duration_s=DURATION_S,
    )
    return cfg.replace(observer__gain=gain_at(kf, base)) if mode == "DOB" else cfg


@dataclass(frozen=True)
class PlannedCell:
    """A Table 7.1 cell for one seed, before it runs: which, and its batch session."""

    seed: int
    mode: str
    kf: float
    wall: float
    config: SessionConfig

    def with_bandwidth(self, bandwidth_hz: float | None, below_first_bin: bool) -> SeedCell:
        """The cell with its session's bandwidth (Hz; None if none)."""
        return SeedCell(self.seed, self.mode, self.kf, self.wall, bandwidth_hz, below_first_bin)


def cells(base: SessionConfig) -> list[PlannedCell]:
    """Every chapter-7 cell for every seed of ``SEEDS``, not yet run."""
    return [
        PlannedCell(seed, mode, kf, wall, chapter7_session(base, mode, kf, wall, seed))
        for seed in SEEDS
        for (mode, kf) in CH7_CONTROLLERS
        for wall in CH7_WALLS
    ]


def _run(cell: PlannedCell) -> SeedCell:
    s = run_session(cell.config).summary()
    return cell.with_bandwidth(s.bandwidth_hz, s.band_below_first_bin)


def seed_cells(base: SessionConfig, executor: Executor | None = None) -> list[SeedCell]:
    """Every Table 7.1 cell for every seed of ``SEEDS``, run."""
    planned = cells(base)
    return list(executor.map(_run, planned)) if executor else [_run(c) for c in planned]


def median_bandwidth(cells: list[SeedCell]) -> float | None:
    """The median over the seeds of one cell's bandwidth (Hz); None if a seed has none, or if
    the median falls on a band below the first bin (a floor, not a value)."""
    if not cells or any(c.bandwidth_hz is None for c in cells):
        return None
    ranked = sorted(cells, key=lambda c: c.bandwidth_hz or 0.0)
    mid = ranked[(len(ranked) - 1) // 2 : len(ranked) // 2 + 1]
    if all(c.below_first_bin for c in mid):
        return None
    return float(statistics.mean(c.bandwidth_hz or 0.0 for c in mid))


def medians(cells: list[SeedCell]) -> dict[tuple[str, float, float], float | None]:
    """Each cell's median over the seeds (Hz; None: see ``median_bandwidth``)."""
    keys = dict.fromkeys((c.mode, c.kf, c.wall) for c in cells)
    return {k: median_bandwidth([c for c in cells if (c.mode, c.kf, c.wall) == k]) for k in keys}
