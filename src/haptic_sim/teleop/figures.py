"""The teleoperation figures (matplotlib, Agg backend, PNG at 120 dpi): force tracking of one
session, and the loop's stability against the channel's delay with and without passivity
control."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from haptic_sim.experiments.figures import pyplot, save_figure
from haptic_sim.teleop.result import TeleopResult
from haptic_sim.teleop.stability import DelayPoint


def plot_force_tracking(result: TeleopResult, path: Path) -> None:
    """Along the table's normal (into it): the true contact force, the observer's estimate, the
    force the master renders (scaled back to the slave) and the wrist sensor; the points of
    master (mapped), target and slave; the channel's net energy."""
    plt = pyplot()
    cfg = result.config
    u = np.asarray(cfg.contact.normal)  # from free space into the table
    t = result.t
    fig, (ax_f, ax_x, ax_e) = plt.subplots(3, 1, figsize=(8.0, 8.0), sharex=True)
    ax_f.plot(t, -result.contact @ u, "k", lw=1.4, label="true contact")
    ax_f.plot(t, -result.estimate @ u, "C0", lw=1.0, label="observer estimate")
    ax_f.plot(t, -result.rendered @ u, "C3", lw=1.0, ls="--", label="rendered on the master")
    ax_f.plot(t, -result.sensor @ u, "C2", lw=0.6, alpha=0.6, label="wrist sensor")
    ax_f.set_ylabel("force into the table (N)")
    ax_f.legend(loc="upper right", fontsize=8)
    arch = cfg.teleop.architecture.replace("_", "-")
    ax_f.set_title(
        f"{arch}, {cfg.channel.round_trip_delay_ms:g} ms round trip, "
        f"passivity control {'on' if cfg.channel.passivity else 'off'}"
    )
    p0 = result.slave_point[0]
    for name, x, style in (
        ("master (mapped)", result.master_point, "C1"),
        ("target", result.target, "C4--"),
        ("slave", result.slave_point, "k"),
    ):
        ax_x.plot(t, ((x - p0) @ u) * 1e3, style, lw=1.0, label=name)
    surface = float((np.asarray(cfg.contact.position) - p0) @ u)
    ax_x.axhline(surface * 1e3, color="0.5", lw=0.8, ls=":", label="table")
    ax_x.set_ylabel("toward the table (mm)")
    ax_x.legend(loc="upper right", fontsize=8)
    ax_e.plot(t, result.channel_energy, "k", lw=1.0)
    ax_e.axhline(0.0, color="0.5", lw=0.8)
    ax_e.set_ylabel("channel net energy in (J)")
    ax_e.set_xlabel("time (s)")
    save_figure(fig, path)


def plot_delay_sweep(points: list[DelayPoint], threshold_mm: float, path: Path) -> None:
    """Oscillation and the channel's lowest net energy against the round-trip delay."""
    plt = pyplot()
    fig, (ax_o, ax_e) = plt.subplots(2, 1, figsize=(7.0, 6.0), sharex=True)
    for passivity, style, label in ((False, "C3o-", "plain channel"), (True, "C0s-", "TDPA")):
        pts = sorted(
            (p for p in points if p.passivity == passivity), key=lambda p: p.round_trip_delay_ms
        )
        if not pts:
            continue
        d = [p.round_trip_delay_ms for p in pts]
        ax_o.plot(d, [max(p.oscillation_mm, 1e-5) for p in pts], style, label=label)
        ax_e.plot(d, [p.channel_energy_min_j for p in pts], style, label=label)
    ax_o.axhline(threshold_mm, color="0.5", lw=0.8, ls=":", label="stability threshold")
    ax_o.set_yscale("log")
    ax_o.set_ylabel("master oscillation (mm)")
    ax_o.legend(fontsize=8)
    ax_o.set_title("push, hold and a pulse: the loop against the channel's delay")
    ax_e.axhline(0.0, color="0.5", lw=0.8)
    ax_e.set_ylabel("lowest net energy into the channel (J)")
    ax_e.set_xlabel("round-trip delay (ms)")
    save_figure(fig, path)
