"""The stability map: vibration-onset stiffness against Kf and wall damping, from batch sweeps.

Each point is a ``haptic_sim.stability`` sweep (the push-and-hold protocol of the README) run
coarse-to-fine: a geometric grid locates the first stiffness that vibrates, a second, linear grid
between its neighbours gives the onset to a few percent. The Z-width (Colgate & Brown 1994) is,
per controller, the largest stiffness rendered without vibration against the wall damping B,
beside the passivity bound ``K T / 2 + |B| < b / (1 + Kf)`` (figures in ``figures``).
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import Executor
from dataclasses import dataclass

import numpy as np

from haptic_dob.environment import VirtualWall
from haptic_dob.observer import ObserverSettings
from haptic_sim.session import SessionConfig
from haptic_sim.stability import StabilityProtocol, law_for, onset, sweep

K_MIN, K_MAX = 5.0, 20000.0
#: the onset against Kf (B = 0): CL and DOB at these Kf, and OL
MAP_KFS = [0.5, 1.0, 2.0, 5.0, 10.0, 25.0, 100.0]
#: the Z-width: these controllers against these wall dampings (N s/m)
ZWIDTH_CONTROLLERS = [("OL", 0.0), ("CL", 2.0), ("DOB", 1.0)]
ZWIDTH_DAMPINGS = [0.0, 0.25, 0.5, 1.0]


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


@dataclass(frozen=True)
class StabilityMap:
    """The map part's result: the onset against Kf (B = 0), then the Z-width's other dampings."""

    points: list[MapPoint]


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
    progress: Callable[[MapPoint], None] | None = None,
) -> list[MapPoint]:
    """Onsets for every (controller, Kf) and wall damping (``executor``: a shared process pool)."""
    base = base or SessionConfig()
    if observer_gain is not None:
        base = base.replace(observer=ObserverSettings(observer_gain, base.observer.output_limit))
    protocol = StabilityProtocol()
    out = []
    T = 1.0 / base.loop.rate_hz
    b = base.device.viscous_n_s_per_m
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


def map_study(base: SessionConfig, executor: Executor | None = None) -> StabilityMap:
    """The onset against Kf for OL, CL and DOB (B = 0) and the Z-width's rows (B > 0)."""
    controllers = [("OL", 0.0)] + [(m, kf) for m in ("CL", "DOB") for kf in MAP_KFS]
    points = stability_map(controllers, [0.0], base, executor=executor)
    damped = [d for d in ZWIDTH_DAMPINGS if d != 0.0]
    return StabilityMap(points + stability_map(ZWIDTH_CONTROLLERS, damped, base, executor=executor))
