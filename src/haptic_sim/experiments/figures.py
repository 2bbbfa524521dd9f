"""The report's figures, drawn from the typed results (matplotlib, Agg backend, PNG at 120 dpi)."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from haptic_sim.experiments import thesis
from haptic_sim.experiments.dob_mechanism import KickPoint
from haptic_sim.experiments.records import GraphOnset, RunAnalysis, label
from haptic_sim.experiments.results import bound, ch7_grid
from haptic_sim.experiments.stability_map import K_MAX, K_MIN, MapPoint
from haptic_sim.slide.session import SessionResult
from haptic_sim.slide.stability import detection_threshold_m


def pyplot() -> Any:
    """matplotlib.pyplot on the Agg backend."""
    # lazy: matplotlib only for a run that draws; Agg chosen before pyplot loads
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # lazy: after the backend is chosen

    return plt


def save_figure(fig: Any, path: Path) -> None:
    """Lay out, write as PNG at 120 dpi, close."""
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    pyplot().close(fig)


# --- chapters 7 and 6 through the graph ---------------------------------------------------------
def plot_ch7(rows: list[RunAnalysis], path: Path) -> None:
    """Bandwidth and impedance error against the wall, simulation (solid) and thesis (dashed)."""
    plt = pyplot()
    ctls, walls, cells = ch7_grid(rows)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    panels: tuple[tuple[Any, Callable[[RunAnalysis], float | None], dict[Any, Any]], ...] = (
        (ax1, lambda r: r.bandwidth_hz, thesis.BANDWIDTH_HZ),
        (ax2, lambda r: r.impedance_error_pct, thesis.ERROR_PCT),
    )
    for i, (mode, kf) in enumerate(ctls):
        color = f"C{i}"
        ws = [w for w in walls if (mode, kf, w) in cells]
        for ax, value, table in panels:
            ax.plot(
                ws,
                [value(cells[(mode, kf, w)]) for w in ws],
                "o-",
                color=color,
                label=label(mode, kf),
            )
            if (mode, kf) in table:
                ax.plot(thesis.WALLS, table[(mode, kf)], "x--", color=color, alpha=0.6)
    ax1.set_ylabel("transparency bandwidth (Hz)")
    ax2.set_ylabel("impedance error in the band (%)")
    for ax in (ax1, ax2):
        ax.set_xlabel("wall stiffness (N/m)")
        ax.grid(True, alpha=0.3)
    ax1.legend(fontsize=8, title="simulation (o), thesis (x, dashed)", title_fontsize=7)
    fig.suptitle("Chapter 7 through the node graph")
    save_figure(fig, path)


def plot_ch6(onsets: list[GraphOnset], path: Path, b: float, rate_hz: float) -> None:
    """Growth rate against the wall per controller, the zero line and the bounds."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for i, e in enumerate(onsets):
        grows = [(p.wall, p.growth_per_s) for p in e.points if p.growth_per_s is not None]
        ax.plot(
            [w for w, _ in grows], [g for _, g in grows], "o-", color=f"C{i}", label=e.controller
        )
        vib = [p.wall for p in e.points if p.growth_per_s is None]
        if vib:  # drawn just above zero, one row per controller so none hides another
            ax.plot(
                vib,
                [0.1 * (i + 1)] * len(vib),
                "v",
                color=f"C{i}",
                ms=9,
                label=f"{e.controller}: vibrating before the pulse",
            )
        ax.axvline(bound(e.mode, e.kf, b, rate_hz), color=f"C{i}", ls=":", lw=0.8)
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_xlabel("wall stiffness (N/m)")
    ax.set_ylabel("envelope growth after the pulse (1/s)")
    ax.set_title("Chapter 6 through the node graph (dotted: 2b/(T(1+Kf)))")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    save_figure(fig, path)


# --- the stability map --------------------------------------------------------------------------
def plot_onset_vs_kf(points: list[MapPoint], path: Path, b: float, T: float) -> None:
    """Onset stiffness against Kf per controller at B = 0, with the passivity bound."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    kfs = np.geomspace(0.1, 200, 200)
    ax.loglog(kfs, 2 * b / (T * (1 + kfs)), "k--", label="bound 2b/(T(1+Kf))")
    for mode, marker in (("CL", "s"), ("DOB", "o")):
        pts = sorted(
            (p for p in points if p.controller == mode and p.damping_n_s_per_m == 0.0),
            key=lambda p: p.kf,
        )
        if not pts:
            continue
        x = [p.kf for p in pts]
        y = [p.onset_n_per_m if p.onset_n_per_m is not None else K_MAX for p in pts]
        ax.loglog(
            x,
            y,
            marker=marker,
            label=f"{mode} (c = {pts[0].observer_gain:g} N s/m)" if mode == "DOB" else mode,
        )
        for p, yy in zip(pts, y, strict=True):
            if p.below_range:
                ax.annotate("vibrates at any K", (p.kf, yy), fontsize=7, rotation=45)
    ol = [p for p in points if p.controller == "OL" and p.damping_n_s_per_m == 0.0]
    if ol and ol[0].onset_n_per_m:
        ax.axhline(ol[0].onset_n_per_m, color="grey", lw=0.8, label="OL onset")
    ax.set_xlabel("force gain Kf")
    ax.set_ylabel("vibration-onset stiffness (N/m)")
    ax.set_ylim(K_MIN, K_MAX * 1.2)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Slide: onset against force gain (push-and-hold protocol)")
    save_figure(fig, path)


def plot_zwidth(points: list[MapPoint], path: Path) -> None:
    """Z-width: largest vibration-free stiffness against wall damping, per controller."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    groups: dict[tuple[str, float], list[MapPoint]] = {}
    for p in points:
        groups.setdefault((p.controller, p.kf), []).append(p)
    for (mode, kf), pts in sorted(groups.items()):
        pts.sort(key=lambda p: p.damping_n_s_per_m)
        d = [p.damping_n_s_per_m for p in pts]
        k = [p.onset_n_per_m if p.onset_n_per_m is not None else math.nan for p in pts]
        (line,) = ax.plot(d, k, marker="o", label=label(mode, kf))
        bounds = [p.bound_n_per_m if p.bound_n_per_m > 0 else math.nan for p in pts]
        ax.plot(d, bounds, ls=":", color=line.get_color())
    ax.set_yscale("log")
    ax.set_xlabel("wall damping B (N s/m)")
    ax.set_ylabel("largest stiffness without vibration (N/m)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, title="measured (solid), passivity bound (dotted)", title_fontsize=7)
    ax.set_title("Z-width of the slide (batch simulation)")
    save_figure(fig, path)


# --- the DOB question ---------------------------------------------------------------------------
def _over_threshold(p: KickPoint) -> float:
    """The residual's peak over the detection threshold at its frequency (floored for a log
    axis)."""
    peak = math.sqrt(2.0) * p.residual_rms_m
    return max(peak / detection_threshold_m(max(p.frequency_hz, 1e-3)), 1e-4)


def plot_kick_grid(points: list[KickPoint], path: Path) -> None:
    """The residual motion over the hand's detection threshold against wall stiffness, one line
    per (c, Coulomb)."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for c, fc in sorted({(p.gain, p.coulomb_n) for p in points}):
        row = sorted(
            (p for p in points if p.gain == c and p.coulomb_n == fc),
            key=lambda p: p.stiffness_n_per_m,
        )
        ax.semilogy(
            [p.stiffness_n_per_m for p in row],
            [_over_threshold(p) for p in row],
            marker="o",
            label=f"c = {c:g} N s/m, Coulomb {fc:g} N",
        )
    ax.axhline(1.0, color="k", ls=":", lw=0.8, label="detection threshold")
    ax.set_xlabel("wall stiffness (N/m)")
    ax.set_ylabel("residual peak 2-3 s after the tap / detection threshold")
    ax.set_title("DOB Kf = 100 on the slide: what stops the vibration")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    save_figure(fig, path)


def plot_kick_traces(runs: dict[str, SessionResult], stiffness: float, path: Path) -> None:
    """Depth and command around the tap, with and without Coulomb friction (runs by name)."""
    plt = pyplot()
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7.0, 5.0), sharex=True)
    for name, r in runs.items():
        ax1.plot(r.t, r.x_true * 1e3, lw=0.8, label=name)
        ax2.plot(r.t, r.effort, lw=0.6, label=name)
    ax1.set_ylabel("position (mm)")
    ax2.set_ylabel("applied effort (N)")
    ax2.set_xlabel("time (s)")
    ax1.set_title(f"DOB Kf = 100, {stiffness:g} N/m wall: the tap at 1.5 s")
    ax1.legend(fontsize=8)
    for ax in (ax1, ax2):
        ax.grid(True, alpha=0.3)
    ax2.set_xlim(1.3, 2.5)
    save_figure(fig, path)
