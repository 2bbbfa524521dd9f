"""Table 7.1 for several seeds of the hand (batch): how far one 40 s session pins a cell down.

The thesis measured each cell once, with one user's 40 s of motion; chapter 7 here runs one
seed of the simulated hand. Running the same cells for other seeds (batch, the graph's cycle
timing: seed 0 is chapter 7's own table to the bit) shows how much of a cell's distance from the
thesis is the hand's draw, and how many cells fall within 15 % for each seed.
"""

from __future__ import annotations

from concurrent.futures import Executor
from dataclasses import dataclass

from haptic_sim.experiments import thesis
from haptic_sim.experiments.tables import fmt
from haptic_sim.hand import reference_for_force
from haptic_sim.slide.session import SessionConfig, run_session
from haptic_sim.slide.stability import law_for

SEEDS = (0, 1)
DURATION_S = 40.0  # chapter 7's sessions
#: a cell matches when within this of the thesis's (relative)
WITHIN = 0.15


@dataclass(frozen=True)
class SeedCell:
    """One Table 7.1 cell for one seed of the hand: its bandwidth (Hz; None if none)."""

    seed: int
    mode: str
    kf: float
    wall: float
    bandwidth_hz: float | None

    @property
    def matches(self) -> bool:
        """Within ``WITHIN`` of the thesis's bandwidth."""
        ref = thesis.cell(self.mode, self.kf, self.wall)[0]
        got = self.bandwidth_hz
        return ref is not None and got is not None and abs(got - ref) <= WITHIN * ref


def chapter7_session(
    base: SessionConfig, mode: str, kf: float, wall: float, seed: int
) -> SessionConfig:
    """A chapter-7 cell in batch: the law, the wall, the hand's push and swing for it, the seed."""
    offset, amplitude = reference_for_force(wall, base.hand.stiffness_n_per_m)
    return base.replace(
        law=law_for(mode, kf, base.law.max_force_n),
        wall__stiffness_n_per_m=wall,
        hand__offset_m=offset,
        hand__amplitude_m=amplitude,
        loop__seed=seed,
        loop__duration_s=DURATION_S,
    )


@dataclass(frozen=True)
class PlannedCell:
    """A Table 7.1 cell for one seed, before it runs: which, and its batch session."""

    seed: int
    mode: str
    kf: float
    wall: float
    config: SessionConfig

    def with_bandwidth(self, bandwidth_hz: float | None) -> SeedCell:
        """The cell with its session's bandwidth (Hz; None if none)."""
        return SeedCell(self.seed, self.mode, self.kf, self.wall, bandwidth_hz)


def cells(base: SessionConfig) -> list[PlannedCell]:
    """Every Table 7.1 cell for every seed of ``SEEDS``, not yet run."""
    return [
        PlannedCell(seed, mode, kf, wall, chapter7_session(base, mode, kf, wall, seed))
        for seed in SEEDS
        for (mode, kf) in thesis.BANDWIDTH_HZ
        for wall in thesis.WALLS
    ]


def _run(cell: PlannedCell) -> SeedCell:
    return cell.with_bandwidth(run_session(cell.config).summary().bandwidth_hz)


def seed_cells(base: SessionConfig, executor: Executor | None = None) -> list[SeedCell]:
    """Every Table 7.1 cell for every seed of ``SEEDS``, run."""
    planned = cells(base)
    return list(executor.map(_run, planned)) if executor else [_run(c) for c in planned]


def spread_table(cells: list[SeedCell]) -> str:
    """Each cell's bandwidth per seed beside the thesis's, and the count within 15 % per seed."""
    if not cells:
        return ""
    seeds = sorted({c.seed for c in cells})
    by = {(c.mode, c.kf, c.wall, c.seed): c for c in cells}
    lines = [
        f"**Table 7.1 for {len(seeds)} seeds of the hand** (batch; seed 0 is chapter 7's "
        "table): bandwidth (Hz) per seed, `*` within 15 % of the thesis:",
        "",
        "| cell | " + " | ".join(f"seed {s}" for s in seeds) + " | thesis |",
        "|---|" + "---|" * (len(seeds) + 1),
    ]
    for mode, kf in thesis.BANDWIDTH_HZ:
        for wall in thesis.WALLS:
            row = [by.get((mode, kf, wall, s)) for s in seeds]
            cols = [
                "-" if c is None else fmt(c.bandwidth_hz) + ("*" if c.matches else "") for c in row
            ]
            name = mode if mode == "OL" else f"{mode} Kf={kf:g}"
            ref = thesis.cell(mode, kf, wall)[0]
            lines.append(f"| {name}, {wall:g} N/m | " + " | ".join(cols) + f" | {fmt(ref, 'g')} |")
    counts = [sum(c.matches for c in cells if c.seed == s) for s in seeds]
    total = sum(1 for c in cells if c.seed == seeds[0])
    lines.append("| within 15 % | " + " | ".join(f"{n} of {total}" for n in counts) + " | |")
    return "\n".join(lines) + "\n"


def counts(cells: list[SeedCell]) -> dict[int, int]:
    """Cells within 15 % of the thesis per seed."""
    return {
        s: sum(c.matches for c in cells if c.seed == s) for s in sorted({c.seed for c in cells})
    }
