"""Table 7.1 for several seeds of the hand beside the thesis's: the table and the counts within
15 % per seed and for the median (``spread`` runs the cells)."""

from __future__ import annotations

from haptic_sim.experiments import thesis
from haptic_sim.experiments.plan import CH7_CONTROLLERS, CH7_WALLS
from haptic_sim.experiments.spread import SeedCell, medians
from haptic_sim.experiments.tables import fmt

within = thesis.within


def matches(c: SeedCell) -> bool:
    """Within 15 % of the thesis's bandwidth (never for a band below the first bin)."""
    return within(c.mode, c.kf, c.wall, None if c.below_first_bin else c.bandwidth_hz)


def shown(c: SeedCell) -> str:
    """A cell's bandwidth as the tables show it: ``< 0.25`` below the first bin."""
    return ("< " if c.below_first_bin else "") + fmt(c.bandwidth_hz)


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
            cols = ["-" if c is None else shown(c) + ("*" if matches(c) else "") for c in row]
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
        s: sum(matches(c) for c in cells if c.seed == s) for s in sorted({c.seed for c in cells})
    }


def median_count(cells: list[SeedCell]) -> int:
    """Cells whose median over the seeds is within 15 % of the thesis."""
    return sum(within(*k, m) for k, m in medians(cells).items())
