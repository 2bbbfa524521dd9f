"""The stability map: vibration-onset stiffness against Kf and wall damping, from batch sweeps.

Each point is a ``haptic_sim.stability`` sweep (the push-and-hold protocol of the README) run
coarse-to-fine: a geometric grid locates the first stiffness that vibrates, a second, linear grid
between its neighbours gives the onset to a few percent. A Z-width plot (Colgate & Brown 1994)
shows, per controller, the largest stiffness rendered without vibration against the wall
damping B, beside the passivity bound ``K T / 2 + |B| < b / (1 + Kf)``.
"""

from __future__ import annotations

import math
from concurrent.futures import Executor
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from haptic_dob.environment import VirtualWall
from haptic_dob.observer import ObserverSettings
from haptic_sim.session import SessionConfig
from haptic_sim.stability import StabilityProtocol, law_for, onset, sweep

K_MIN, K_MAX = 5.0, 20000.0


@dataclass(frozen=True)
class MapPoint:
    """One controller at one wall damping: the measured onset and the passivity bound (N/m)."""

    controller: str
    kf: float
    damping_n_s_per_m: float
    observer_gain: float
    onset_n_per_m: float | None  # None: nothing vibrated up to K_MAX
    below_range: bool  # vibrated already at K_MIN
    bound_n_per_m: float

    def as_dict(self) -> dict:
        """JSON-ready."""
        return asdict(self)


def passivity_bound(b: float, T: float, kf: float, damping: float) -> float:
    """Largest K with ``K T / 2 + |B| < b / (1 + Kf)`` (Colgate; thesis 6.3 with Kf); 0 if none."""
    return max(0.0, 2.0 * (b / (1.0 + kf) - abs(damping)) / T)


def find_onset(
    base: SessionConfig,
    protocol: StabilityProtocol,
    executor: Executor | None,
    coarse: int = 16,
    fine: int = 8,
) -> tuple[float | None, bool]:
    """Coarse geometric sweep, then a fine linear one around the first vibrating stiffness."""
    grid = np.geomspace(K_MIN, K_MAX, coarse)
    first = sweep(grid, base, protocol, executor=executor)
    vib = [p.vibrates for p in first.points]
    if not any(vib):
        return None, False
    i = vib.index(True)
    if i == 0:
        return float(grid[0]), True
    lo, hi = grid[i - 1], grid[i]
    second = sweep(np.linspace(lo, hi, fine), base, protocol, executor=executor)
    k_on = onset(second.points)
    return (None if k_on is None else float(k_on)), False


def stability_map(
    controllers: list[tuple[str, float]],
    dampings: list[float],
    base: SessionConfig | None = None,
    observer_gain: float | None = None,
    executor: Executor | None = None,
    progress=None,
) -> list[MapPoint]:
    """Onsets for every (controller, Kf) and wall damping (``executor``: a shared process pool)."""
    base = base or SessionConfig()
    if observer_gain is not None:
        base = base.replace(observer=ObserverSettings(observer_gain, base.observer.output_limit))
    protocol = StabilityProtocol()
    out = []
    T = 1.0 / base.loop.rate_hz
    b = base.model.viscous_n_s_per_m
    for mode, kf in controllers:
        for damping in dampings:
            w = base.wall
            cfg = base.replace(
                law=law_for(mode, kf, base.law.max_force_n),
                wall=VirtualWall(w.stiffness_n_per_m, damping, w.position, w.normal),
            )
            k_on, below = find_onset(cfg, protocol, executor)
            kf_eff = kf if mode != "OL" else 0.0
            point = MapPoint(
                mode,
                kf_eff,
                damping,
                base.observer.gain,
                k_on,
                below,
                passivity_bound(b, T, kf_eff, damping),
            )
            out.append(point)
            if progress:
                progress(point)
    return out


def plot_onset_vs_kf(points: list[MapPoint], path: Path, b: float, T: float) -> None:
    """Onset stiffness against Kf per controller at B = 0, with the passivity bound."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

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
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_zwidth(points: list[MapPoint], path: Path, b: float, T: float) -> None:
    """Z-width: largest vibration-free stiffness against wall damping, per controller."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    groups: dict[tuple[str, float], list[MapPoint]] = {}
    for p in points:
        groups.setdefault((p.controller, p.kf), []).append(p)
    for (mode, kf), pts in sorted(groups.items()):
        pts.sort(key=lambda p: p.damping_n_s_per_m)
        d = [p.damping_n_s_per_m for p in pts]
        k = [p.onset_n_per_m if p.onset_n_per_m is not None else math.nan for p in pts]
        label = mode if mode == "OL" else f"{mode} Kf={kf:g}"
        (line,) = ax.plot(d, k, marker="o", label=label)
        bounds = [p.bound_n_per_m if p.bound_n_per_m > 0 else math.nan for p in pts]
        ax.plot(d, bounds, ls=":", color=line.get_color())
    ax.set_yscale("log")
    ax.set_xlabel("wall damping B (N s/m)")
    ax.set_ylabel("largest stiffness without vibration (N/m)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, title="measured (solid), passivity bound (dotted)", title_fontsize=7)
    ax.set_title("Z-width of the slide (batch simulation)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
