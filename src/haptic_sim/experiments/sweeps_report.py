"""The sweeps part's prose: what each sweep shows, and where the simulation differs, with the
cells' own numbers (``sweeps``)."""

from __future__ import annotations

from haptic_sim.experiments import spread, thesis
from haptic_sim.experiments.sweeps import (
    FORCE_LIMIT,
    GRIP,
    OBSERVER,
    SENSOR,
    SweepCell,
    SweepStudy,
    label,
)
from haptic_sim.experiments.tables import fmt


def _first_and_collapsed(cells: list[SweepCell]) -> tuple[SweepCell, SweepCell | None]:
    """The chapter-7 value's cell, and the first other whose band is under half of it."""
    first = cells[0]
    half = 0.5 * (first.bandwidth_hz or 0.0)
    return first, next((c for c in cells[1:] if (c.bandwidth_hz or 0.0) < half), None)


def grip_text(r: SweepStudy) -> str:
    """What the grip sweep shows, with its own numbers ("" when OL was not run)."""
    ol = r.of(GRIP.name, "OL", 0.0)
    if not ol:
        return ""
    first, loose = _first_and_collapsed(ol)
    text = (
        f"With the chapter-7 grip ({first.value:g} N s/m) OL keeps a {fmt(first.bandwidth_hz)} Hz "
        "band at 2400 N/m, where the thesis measured 0.6 Hz; but it renders the wall "
        f"{fmt(first.mean_db_to_5hz, '+.1f')} dB on average up to 5 Hz "
        f"({fmt(first.first_bin_db, '+.1f')} dB at the first bin), close to the -3 dB that ends "
        "the band everywhere, so the band's edge is ill-conditioned. "
    )
    if loose is not None:
        text += (
            f"With a looser grip ({loose.value:g} N s/m) the first bin reaches "
            f"{fmt(loose.first_bin_db, '+.1f')} dB (coherence {fmt(loose.coherence_in_band)}) "
            f"and the band ends there, at {fmt(loose.bandwidth_hz)} Hz, though the mean up to "
            f"5 Hz moves only to {fmt(loose.mean_db_to_5hz, '+.1f')} dB. The thesis's 0.6 Hz "
            "fits the same edge falling to its lowest bins more than a different rendering. "
        )
    else:
        text += "No grip of the sweep moved the edge to the first bin. "
    return text + (
        "The controllers with force feedback render the stiff wall closer to the desired "
        "impedance, so their edges stay wide; the thesis did not measure its hand.\n"
    )


def limit_text(r: SweepStudy) -> str:
    """What the force-limit sweep shows, with its own numbers."""
    parts = []
    for mode, kf in (("CL", 2.0), ("DOB", 25.0)):
        cells = r.of(FORCE_LIMIT.name, mode, kf)
        if len(cells) < 2:
            continue
        first, widest = cells[0], max(cells[1:], key=lambda c: c.coherence_in_band or 0.0)
        ref = thesis.cell(mode, kf, FORCE_LIMIT.walls[0])[0]
        parts.append(
            f"{label(mode, kf)} spends {first.saturated_pct:.0f} % of the session at the "
            f"{first.value:g} N limit (coherence {fmt(first.coherence_in_band)}, band "
            f"{fmt(first.bandwidth_hz)} Hz); with {widest.value:g} N, {widest.saturated_pct:.0f} % "
            f"(coherence {fmt(widest.coherence_in_band)}, band {fmt(widest.bandwidth_hz)} Hz; "
            f"thesis {fmt(ref, 'g')} Hz)"
        )
    if not parts:
        return ""
    return (
        "At 80 N/m the hand's swing moves the handle centimetres and force feedback asks for "
        "1 + Kf times the force error: "
        + "; ".join(parts)
        + ". The collapse of these cells (the coherence near zero, the band at the first bin) is "
        "the actuator saturating under this hand, not the loop's linear behaviour; with the "
        "limit raised, each cell's band is what the later columns show. The thesis does not "
        "report its hand's swing at the soft wall.\n"
    )


def _saturation(c: SweepCell) -> float:
    return c.saturated_pct


def _matching(cells: list[SweepCell], ref: float | None) -> str:
    """The swept values whose band is within 15 % of the thesis's ``ref`` (Hz)."""
    good = [
        f"{c.value:g}"
        for c in cells
        if ref is not None
        and c.bandwidth_hz is not None
        and abs(c.bandwidth_hz - ref) <= 0.15 * ref
    ]
    return ", ".join(good) or "none of the sweep's values"


def observer_text(r: SweepStudy) -> str:
    """What the observer-gain sweep shows, with its own numbers ("" when not run)."""
    parts = []
    for mode, kf in OBSERVER.controllers:
        walls = []
        for wall in OBSERVER.walls:
            cells = r.of(OBSERVER.name, mode, kf, wall)
            if cells:
                ref = thesis.cell(mode, kf, wall)[0]
                walls.append(f"c = {_matching(cells, ref)} at {wall:g} N/m")
        if walls:
            parts.append(f"{label(mode, kf)}: " + ", ".join(walls))
    if not parts:
        return ""
    # the chatter's example where the force limit alone does not saturate (not at 80 N/m)
    swept = [c for c in r.cells if c.sweep == OBSERVER.name]
    chatter = max([c for c in swept if c.wall >= 800.0] or swept, key=_saturation)
    return (
        "The gains whose band is within 15 % of the thesis's, per wall: "
        + "; ".join(parts)
        + ". For a large Kf the rendered impedance rises past +3 dB near the observer's corner "
        "c / (2 pi m), so the high-gain band follows the gain; the low-gain DOB reaches its mass "
        "line m / 2 only with a faster observer, and a gain that fast chatters at the sample rate "
        f"at Kf = 25 ({label(chatter.mode, chatter.kf)} at {chatter.wall:g} N/m with c = "
        f"{chatter.value:g}: the command at the force limit {chatter.saturated_pct:.0f} % of the "
        "time) and at the thesis's Kf = 100 (the DOB section), where the chapter-7 gain (the first "
        "column) is set below it.\n"
    )


def sensor_text(r: SweepStudy) -> str:
    """What the sensor sweep shows, with its own numbers ("" when not run)."""
    wall = SENSOR.walls[-1]
    cells = r.of(SENSOR.name, "CL", 2.0, wall)
    onsets = [c for c in r.of(SENSOR.name, "CL", 2.0) if c.onset_n_per_m is not None]
    if len(cells) < 2 or len(onsets) < 2:
        return ""
    first, last = cells[0], cells[-1]
    ref = thesis.cell("CL", 2.0, wall)[0]
    return (
        f"CL Kf=2 at {wall:g} N/m keeps a {fmt(first.bandwidth_hz)} Hz band with the chapter-7 "
        f"sensor ({first.value:g} Hz); a {last.value:g} Hz sensor gives "
        f"{fmt(last.bandwidth_hz)} Hz (thesis {fmt(ref, 'g')} Hz) and moves chapter 6's linear CL "
        f"onset from {fmt(onsets[0].onset_n_per_m, '.0f')} to "
        f"{fmt(onsets[-1].onset_n_per_m, '.0f')} N/m (thesis {thesis.ONSET_N_PER_M['CL']:g} N/m). "
        "The thesis's CL cells above 800 N/m lie below the mass line m / (1 + Kf) that the "
        "simulated CL follows, and the sensor's bandwidth is not what puts them there.\n"
    )


def differences(r: SweepStudy) -> list[str]:
    """The paragraphs for "where the simulation differs" (a sweep not run adds none)."""
    out = []
    ol = [c for c in r.of(GRIP.name, "OL", 0.0) if c.bandwidth_hz is not None]
    if len(ol) >= 2:
        widest = max(ol, key=lambda c: c.bandwidth_hz or 0.0)
        narrowest = min(ol, key=lambda c: c.bandwidth_hz or 0.0)
        out.append(
            "- **The OL cell at 2400 N/m hangs on the hand's grip.** OL renders that wall near "
            "the -3 dB criterion across the band, so its bandwidth goes from "
            f"{fmt(widest.bandwidth_hz)} Hz ({widest.value:g} N s/m grip) to "
            f"{fmt(narrowest.bandwidth_hz)} Hz ({narrowest.value:g} N s/m) (the sweeps "
            "section); the thesis's 0.6 Hz is one side of that edge."
        )
    firsts = [r.of(FORCE_LIMIT.name, m, kf)[:1] for m, kf in FORCE_LIMIT.controllers]
    worst = max((c[0] for c in firsts if c), key=lambda c: c.saturated_pct, default=None)
    if worst is not None and worst.saturated_pct > 0.0:
        out.append(
            "- **Force feedback at 80 N/m saturates the actuator.** Under the chapter-7 hand "
            f"{label(worst.mode, worst.kf)} is at the {worst.value:g} N limit "
            f"{worst.saturated_pct:.0f} % of the time, which is what empties its band (the "
            "sweeps section)."
        )
    if r.of(OBSERVER.name, "DOB", 1.0) and r.of(OBSERVER.name, "DOB", 25.0):
        out.append(
            "- **The DOB rows hang on the observer gain.** With the one gain of every chapter, "
            "DOB Kf = 25's band sits near the observer's corner and DOB Kf = 1's above the "
            "thesis's; a faster observer would move Kf = 1 toward the thesis and Kf = 25 away, "
            "and chatter at Kf = 25 and 100 (the sweeps section)."
        )
    if r.of(SENSOR.name, "CL", 2.0):
        out.append(
            "- **CL above 800 N/m follows its mass line.** The simulated CL band grows with the "
            "wall as m / (1 + Kf) predicts; the thesis's 6.6 and 4.5 Hz at 1600 and 2400 N/m lie "
            "below it, and neither the force sensor's bandwidth (the sweeps section) nor the "
            "observer explains that here."
        )
    if r.seeds:
        n = spread.counts(r.seeds)
        per_seed = sum(1 for c in r.seeds if c.seed == min(n))
        out.append(
            "- **One seed's Table 7.1 is one draw of the hand.** Cells within 15 % of the "
            "thesis, per seed: "
            + ", ".join(f"seed {s}: {k}" for s, k in n.items())
            + f" of {per_seed} (the sweeps section)."
        )
    return out
