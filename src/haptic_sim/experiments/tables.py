"""The report's Markdown tables, and the terminal's summary lines, from the typed results."""

from __future__ import annotations

import math
from collections.abc import Callable

from haptic_sim.experiments import thesis
from haptic_sim.experiments.dob_mechanism import (
    GRIPS,
    WALLS,
    DobStudy,
    GripPoint,
    KickPoint,
    first_vibrating_with,
)
from haptic_sim.experiments.plan import CH7_CONTROLLERS
from haptic_sim.experiments.records import (
    GraphOnset,
    RunAnalysis,
    TapSweep,
    label,
)
from haptic_sim.experiments.results import bound, ch7_grid
from haptic_sim.experiments.stability_map import MapPoint
from haptic_sim.slide.stability import THRESHOLD_PLATEAU_M


def fmt(v: float | None, spec: str = ".2f", none: str = "–") -> str:
    """``v`` formatted with ``spec``; ``none`` when it is None or not finite."""
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return none
    return format(v, spec)


# --- chapters 7 and 6 through the graph ---------------------------------------------------------
#: the chapter-7 tables: title, the row's value, its column in ``thesis.cell``, number format
CH7_TABLES: tuple[tuple[str, Callable[[RunAnalysis], float | None], int, str], ...] = (
    (
        "Transparency bandwidth (Hz): simulation / thesis Table 7.1",
        lambda r: r.bandwidth_hz,
        0,
        ".2f",
    ),
    (
        "Average impedance error in the band (%): simulation / thesis Table 7.2",
        lambda r: r.impedance_error_pct,
        1,
        ".1f",
    ),
)


def ch7_tables(rows: list[RunAnalysis]) -> str:
    """Tables 7.1 and 7.2 with the simulation beside the thesis (``sim / thesis``)."""
    ctls, walls, cells = ch7_grid(rows)
    out = []
    for title, value, idx, spec in CH7_TABLES:
        out.append(f"**{title}**\n")
        out.append("| controller | " + " | ".join(f"{w:g} N/m" for w in walls) + " |")
        out.append("|---|" + "---|" * len(walls))
        for mode, kf in ctls:
            cols = []
            for w in walls:
                r = cells.get((mode, kf, w))
                ref = thesis.cell(mode, kf, w)[idx]
                floor = "< " if idx == 0 and r is not None and r.band_below_first_bin else ""
                got = fmt(None if r is None else value(r), spec)
                cols.append(f"{floor}{got} / {fmt(ref, 'g')}")
            out.append(f"| {label(mode, kf)} | " + " | ".join(cols) + " |")
        out.append("")
    return "\n".join(out)


def ch6_table(onsets: list[GraphOnset], b: float, rate_hz: float) -> str:
    """The onset table (graph) and the per-wall growth rates."""
    lines = [
        "| controller | onset, graph (N/m) | bound 2b/(T(1+Kf)) (N/m) | thesis: first wall "
        "that vibrated (N/m) |",
        "|---|---|---|---|",
    ]
    for e in onsets:
        k_on = e.onset_n_per_m
        bnd = bound(e.mode, e.kf, b, rate_hz)
        shown = fmt(k_on, ".0f", "none up to the last wall")
        if e.first_point_vibrates and k_on is not None:
            shown = f"<= {k_on:.0f} (the lowest wall vibrates)"
        ref = thesis.ONSET_N_PER_M.get(e.mode)
        lines.append(f"| {e.controller} | {shown} | {bnd:.0f} | {fmt(ref, 'g')} |")
    lines += [
        "",
        "Pulse-response growth rate per wall (1/s; > 0 grows, `vib` = sustained before the pulse):",
        "",
    ]
    for e in onsets:
        pts = ", ".join(f"{p.wall:g}: {fmt(p.growth_per_s, '+.2f', 'vib')}" for p in e.points)
        lines.append(f"- {e.controller}: {pts}")
    return "\n".join(lines) + "\n"


def ch6_tap_table(taps: list[TapSweep]) -> str:
    """The tap protocol: each wall's residual motion and the first wall that keeps vibrating."""
    lines = [
        "**With the plant's friction, tapped** (3 N for 20 ms; motion 2-3 s after the tap, um RMS "
        "about its trend, at its dominant frequency; vibrating where the hand feels it: its peak "
        f"above the detection threshold at that frequency, {THRESHOLD_PLATEAU_M * 1e6:g} um up to "
        '40 Hz, after Bolanowski, Gescheider, Verrillo and Checkosky 1988, "Four channels '
        'mediate the mechanical aspects of touch"):',
        "",
        "| controller | residual motion per wall (N/m: um) | first wall that keeps vibrating "
        "(N/m) | thesis (N/m) |",
        "|---|---|---|---|",
    ]
    for t in taps:
        cells = ", ".join(
            f"{p.wall:g}: {p.residual_rms_m * 1e6:.1f}"
            + (f" @ {p.frequency_hz:.0f} Hz" if p.vibrates else "")
            for p in t.points
        )
        ref = thesis.ONSET_N_PER_M.get(t.mode)
        first = fmt(t.first_vibrating_n_per_m, "g", "none")
        lines.append(f"| {t.controller} | {cells} | {first} | {fmt(ref, 'g')} |")
    return "\n".join(lines) + "\n"


def ch7_console(rows: list[RunAnalysis]) -> list[str]:
    """The chapter-7 cells for the terminal, by wall, beside the thesis's."""

    def order(r: RunAnalysis) -> tuple[float, int]:
        c = (r.mode, r.kf)
        return r.wall, CH7_CONTROLLERS.index(c) if c in CH7_CONTROLLERS else 9

    out = [f"{'controller':<12}{'wall':>9}{'bandwidth':>11}{'imp. error':>12}   thesis"]
    for r in sorted(rows, key=order):
        bw, err = thesis.cell(r.mode, r.kf, r.wall)
        got = ("<" if r.band_below_first_bin else "") + fmt(r.bandwidth_hz)
        out.append(
            f"{r.controller_label:<12}{r.wall:>5g} N/m{got:>8} Hz"
            f"{fmt(r.impedance_error_pct, '.1f'):>10} %   {fmt(bw, 'g')} Hz, {fmt(err, 'g')} %"
        )
    return out


def ch6_console(onsets: list[GraphOnset], taps: list[TapSweep]) -> list[str]:
    """The chapter-6 onsets and the tap's first vibrating walls for the terminal."""
    out = [f"onset {e.controller}: {fmt(e.onset_n_per_m, '.0f')} N/m" for e in onsets]
    return out + [
        f"tapped with friction, {t.controller}: first vibrating wall "
        f"{fmt(t.first_vibrating_n_per_m, 'g', 'none')} N/m"
        for t in taps
    ]


# --- the stability map --------------------------------------------------------------------------
def map_table(points: list[MapPoint]) -> str:
    """Onset against Kf (B = 0) and the Z-width rows."""
    lines = [
        "| controller | Kf | wall damping (N s/m) | onset (N/m) | passivity bound (N/m) |",
        "|---|---|---|---|---|",
    ]
    for p in sorted(points, key=lambda p: (p.controller, p.damping_n_s_per_m, p.kf)):
        shown = (
            "vibrates at any K"
            if p.below_range
            else fmt(p.onset_n_per_m, ".0f", "none up to 20000")
        )
        lines.append(
            f"| {p.controller} | {p.kf:g} | {p.damping_n_s_per_m:g} | {shown} | "
            f"{p.bound_n_per_m:.0f} |"
        )
    return "\n".join(lines) + "\n"


# --- the DOB question ---------------------------------------------------------------------------
def _kick_cell(p: KickPoint) -> str:
    rms = f"{p.residual_rms_m * 1e6:.1f}"
    return f"{rms} @ {p.frequency_hz:.0f} Hz" if p.vibrates else rms


def _grip_cell(p: GripPoint) -> str:
    rms = f"{p.residual_rms_m * 1e6:.1f}"
    return f"{rms} @ {p.frequency_hz:.0f} Hz" if p.vibrates else rms


def dob_tables(d: DobStudy) -> str:
    """Tables of the mechanism study."""
    lines = [
        "**Linear loop model** (no saturation, no Coulomb friction; hand a pure force "
        "source): lowest unstable wall (N/m); 0 = unstable at any stiffness.",
        "",
        "| Kf | c (N s/m) | DOB | CL, ideal sensor |",
        "|---|---|---|---|",
    ]
    for r in d.linear:
        lines.append(
            f"| {r.kf:g} | {r.gain:g} | {fmt(r.dob_onset_n_per_m, '.0f', 'stable')}"
            f" | {fmt(r.cl_onset_n_per_m, '.0f', 'stable')} |"
        )
    lines += [
        "",
        "**The gain above which DOB chatters at the sample rate** (the linear model's mode near "
        "-Kf c T / (2 m): the command alternating its sign every period), N s/m:",
        "",
        "| Kf | with the amplifier lag | without (about 2 m / (Kf T)) |",
        "|---|---|---|",
    ]
    for g in d.chatter:
        lag, no_lag = fmt(g.gain, ".1f", "none"), fmt(g.gain_without_lag, ".1f", "none")
        lines.append(f"| {g.kf:g} | {lag} | {no_lag} |")
    lines += [
        "",
        f"**Tap grid** (DOB Kf = 100, chapter 6's tap in batch; residual motion 2-3 s after the "
        "tap, um RMS; vibrating where the hand feels it: its peak above the detection threshold "
        f"at its frequency, {THRESHOLD_PLATEAU_M * 1e6:g} um up to 40 Hz):",
        "",
        "| c (N s/m) | Coulomb (N) | "
        + " | ".join(f"{w:g}" for w in WALLS)
        + " | first wall that vibrates |",
        "|---|---|" + "---|" * (len(WALLS) + 1),
    ]
    for fv in d.first_vibrating:
        row = {
            p.stiffness_n_per_m: p
            for p in d.kick
            if p.gain == fv.gain and p.coulomb_n == fv.coulomb_n
        }
        cols = [_kick_cell(row[w]) for w in WALLS if w in row]
        lines.append(
            f"| {fv.gain:g} | {fv.coulomb_n:g} | "
            + " | ".join(cols)
            + f" | {fmt(fv.wall, 'g', 'none')} |"
        )
    if d.grips:
        lines += [
            "",
            "**The tap with another hand** (DOB Kf = 100, the configuration's gain and friction; "
            "residual motion 2-3 s after the tap, um RMS):",
            "",
            "| hand | " + " | ".join(f"{w:g}" for w in WALLS) + " | first wall that vibrates |",
            "|---|" + "---|" * (len(WALLS) + 1),
        ]
        for grip in GRIPS:
            by_wall = {p.stiffness_n_per_m: p for p in d.grips if p.grip == grip.name}
            if not by_wall:
                continue
            taps = [_grip_cell(by_wall[w]) for w in WALLS if w in by_wall]
            first = fmt(first_vibrating_with(d.grips, grip.name), "g", "none")
            hand = (
                f"{grip.name}: {grip.mass_kg:g} kg, {grip.stiffness_n_per_m:g} N/m, "
                f"{grip.damping_n_s_per_m:g} N s/m"
            )
            lines.append(f"| {hand} | " + " | ".join(taps) + f" | {first} |")
    if d.model_mismatch:
        lines += [
            "",
            "**DOB with an observer model that leaves Coulomb friction out** (batch, the "
            "chapter-7 hand; bandwidth Hz / impedance error %):",
            "",
            "| wall (N/m) | Kf | the assumed model | no Coulomb in the model |",
            "|---|---|---|---|",
        ]
        cells = {(c.wall, c.kf, c.observer_model): c for c in d.model_mismatch}
        for wall, kf in sorted({(c.wall, c.kf) for c in d.model_mismatch}):
            cols = [
                f"{fmt(c.bandwidth_hz)} / {fmt(c.impedance_error_pct, '.1f')}"
                for c in (cells[(wall, kf, "assumed")], cells[(wall, kf, "no Coulomb")])
            ]
            lines.append(f"| {wall:g} | {kf:g} | " + " | ".join(cols) + " |")
    return "\n".join(lines) + "\n"
