"""Section 5.3's part of the report: the table, the figure and the terminal lines."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from haptic_sim.experiments.figures import pyplot, save_figure
from haptic_sim.experiments.observer_vs_sensor import SETTLE_S, TRACE_HZ, Ch5Result
from haptic_sim.slide.session import SessionConfig


def _where(wall: float) -> str:
    return "free space" if wall == 0.0 else f"{wall:g} N/m wall"


def ch5_table(r: Ch5Result, _base: SessionConfig) -> str:
    """RMS differences between the estimate, the sensor and the true hand force."""
    lines = [
        f"RMS differences after the first {SETTLE_S:g} s (N):",
        "",
        "| session | estimate - sensor | estimate - true force | sensor - true force "
        "| estimate at its limit |",
        "|---|---|---|---|---|",
    ]
    for run in r.runs:
        lines.append(
            f"| {_where(run.wall_n_per_m)} | {run.rms_estimate_vs_sensor_n:.3f} | "
            f"{run.rms_estimate_vs_true_n:.3f} | {run.rms_sensor_vs_true_n:.3f} | "
            f"{run.clipped_pct:.1f} % |"
        )
    return "\n".join(lines) + "\n"


def plot_ch5(r: Ch5Result, path: Path, _base: SessionConfig) -> None:
    """The estimate over the sensor's reading and the true force, one panel per session."""
    plt = pyplot()
    fig, axes = plt.subplots(1, len(r.runs), figsize=(12, 3.8), squeeze=False)
    for ax, run in zip(axes[0], r.runs, strict=True):
        t = SETTLE_S + np.arange(len(run.estimate_n)) / TRACE_HZ
        ax.plot(t, run.true_n, color="0.6", lw=2.0, label="true hand force")
        ax.plot(t, run.sensor_n, "k", lw=0.8, label="force sensor")
        ax.plot(t, run.estimate_n, "C3--", lw=0.9, label="observer (clipped at 4 N)")
        ax.set_title(
            f"{_where(run.wall_n_per_m)}: RMS est - sensor {run.rms_estimate_vs_sensor_n:.3f} N"
        )
        ax.set_xlabel("time (s)")
        ax.set_ylabel("hand force (N)")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    save_figure(fig, path)


def ch5_console(r: Ch5Result) -> list[str]:
    """One line per session."""
    return [
        f"observer vs sensor, {_where(run.wall_n_per_m)}: RMS {run.rms_estimate_vs_sensor_n:.3f} N"
        f" (vs the true force {run.rms_estimate_vs_true_n:.3f} N)"
        for run in r.runs
    ]
