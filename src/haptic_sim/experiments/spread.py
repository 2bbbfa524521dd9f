"""Table 7.1 for several seeds of the hand (batch): how far one 40 s session pins a cell down.

The thesis measured each cell once, with one user's 40 s of motion; chapter 7 here runs one
seed of the simulated hand. Running the same cells for other seeds (batch, the graph's cycle
timing: seed 0 is chapter 7's own table to the bit) shows how much of a cell's distance from the
thesis is the hand's draw, how many cells fall within 15 % for each seed, and how many the
median of the seeds puts within 15 %. A band that ends below the first frequency bin is a
resolution floor, not a measured edge: it never counts as within 15 %.
"""

from __future__ import annotations

import statistics
from concurrent.futures import Executor
from dataclasses import dataclass

from haptic_sim.experiments import thesis
from haptic_sim.experiments.observer_gain import gain_at
from haptic_sim.experiments.plan import CH7_CONTROLLERS, CH7_WALLS
from haptic_sim.experiments.tables import fmt
from haptic_sim.slide.session import SessionConfig, run_session
from haptic_sim.slide.stability import law_for

SEEDS = (0, 1, 2)
DURATION_S = 40.0  # chapter 7's sessions
within = thesis.within


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

    @property
    def matches(self) -> bool:
        """Within 15 % of the thesis's bandwidth (never for a band below the first bin)."""
        bw = None if self.below_first_bin else self.bandwidth_hz
        return within(self.mode, self.kf, self.wall, bw)


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


def shown(c: SeedCell) -> str:
    """A cell's bandwidth as the tables show it: ``< 0.25`` below the first bin."""
    return ("< " if c.below_first_bin else "") + fmt(c.bandwidth_hz)


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


def spread_table(cells: list[SeedCell]) -> str:
    """Each cell's bandwidth per seed and their median beside the thesis's, and the counts
    within 15 % per seed and for the median."""
    if not cells:
        return ""
    seeds = sorted({c.seed for c in cells})
    by = {(c.mode, c.kf, c.wall, c.seed): c for c in cells}
    med = medians(cells)
    lines = [
        f"**Table 7.1 for {len(seeds)} seeds of the hand** (batch; seed 0 is chapter 7's "
        "table): bandwidth (Hz) per seed and their median, `*` within 15 % of the thesis, "
        "`<` a band that ends below the first frequency bin:",
        "",
        "| cell | " + " | ".join(f"seed {s}" for s in seeds) + " | median | thesis |",
        "|---|" + "---|" * (len(seeds) + 2),
    ]
    for mode, kf in CH7_CONTROLLERS:
        for wall in CH7_WALLS:
            row = [by.get((mode, kf, wall, s)) for s in seeds]
            cols = ["-" if c is None else shown(c) + ("*" if c.matches else "") for c in row]
            m = med.get((mode, kf, wall))
            below = [c for c in row if c is not None and c.below_first_bin]
            floor = "< " + fmt(below[0].bandwidth_hz) if below else "-"
            cols.append(floor if m is None else fmt(m) + ("*" if within(mode, kf, wall, m) else ""))
            name = mode if mode == "OL" else f"{mode} Kf={kf:g}"
            ref = thesis.cell(mode, kf, wall)[0]
            lines.append(f"| {name}, {wall:g} N/m | " + " | ".join(cols) + f" | {fmt(ref, 'g')} |")
    n = counts(cells)
    total = sum(1 for c in cells if c.seed == seeds[0])
    lines.append(
        "| within 15 % | "
        + " | ".join(f"{n[s]} of {total}" for s in seeds)
        + f" | {median_count(cells)} of {total} | |"
    )
    return "\n".join(lines) + "\n"


def counts(cells: list[SeedCell]) -> dict[int, int]:
    """Cells within 15 % of the thesis per seed."""
    return {
        s: sum(c.matches for c in cells if c.seed == s) for s in sorted({c.seed for c in cells})
    }


def median_count(cells: list[SeedCell]) -> int:
    """Cells whose median over the seeds is within 15 % of the thesis."""
    return sum(within(*k, m) for k, m in medians(cells).items())
