"""The stability map: vibration-onset stiffness against Kf and wall damping, from batch sweeps.

Each point is a ``haptic_sim.slide.stability`` sweep (the push-and-hold protocol of the README) run
coarse-to-fine: a geometric grid locates the first stiffness that vibrates, a second, linear grid
between its neighbours gives the onset to a few percent. The Z-width (Colgate & Brown 1994) is,
per controller, the largest stiffness rendered without vibration against the wall damping B,
beside the passivity bound ``K T / 2 + |B| < b / (1 + Kf)`` (figures in ``figures``).
"""

from __future__ import annotations

from concurrent.futures import Executor
from dataclasses import dataclass

import numpy as np

from haptic_dob.core.environment import VirtualWall
from haptic_dob.core.observers.factory import ObserverSettings
from haptic_sim.slide.session import SessionConfig
from haptic_sim.slide.stability import StabilityPoint, StabilityProtocol, growth_at, law_for, onset

K_MIN, K_MAX = 5.0, 20000.0
#: the onset against Kf (B = 0): CL and DOB at these Kf, and OL
MAP_KFS = [0.5, 1.0, 2.0, 5.0, 10.0, 25.0, 100.0]
#: the Z-width: these controllers against these wall dampings (N s/m)
ZWIDTH_CONTROLLERS = [("OL", 0.0), ("CL", 2.0), ("DOB", 1.0)]
ZWIDTH_DAMPINGS = [0.0, 0.25, 0.5, 1.0]
#: points a pool worker takes at a time (one point is a 4 s session: a fraction of a second)
CHUNK = 4


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


def _growth(
    jobs: list[tuple[SessionConfig, float]],
    protocol: StabilityProtocol,
    executor: Executor | None,
) -> list[StabilityPoint]:
    """The protocol at every (configuration, stiffness) of ``jobs``, in order, in one batch."""
    args = ([protocol] * len(jobs), [c for c, _ in jobs], [k for _, k in jobs])
    if executor is None:
        return list(map(growth_at, *args))
    return list(executor.map(growth_at, *args, chunksize=CHUNK))


def find_onsets(
    cfgs: list[SessionConfig],
    protocol: StabilityProtocol,
    executor: Executor | None,
    coarse: int = 16,
    fine: int = 8,
) -> list[tuple[float | None, bool]]:
    """Per configuration (onset N/m or None, vibrated already at ``K_MIN``): a coarse geometric
    sweep, then a fine linear one around the first vibrating stiffness. Every configuration's
    coarse points go to the pool as one batch, then every fine point: no worker waits for the
    slowest point of one sweep before the next sweep starts."""
    grid = [float(k) for k in np.geomspace(K_MIN, K_MAX, coarse)]
    first = _growth([(c, k) for c in cfgs for k in grid], protocol, executor)
    out: list[tuple[float | None, bool] | None] = []
    refine: list[tuple[int, list[float]]] = []  # (configuration, its fine grid)
    for i in range(len(cfgs)):
        vib = [p.vibrates for p in first[i * coarse : (i + 1) * coarse]]
        if not any(vib):
            out.append((None, False))
        elif vib[0]:
            out.append((grid[0], True))
        else:
            j = vib.index(True)
            out.append(None)
            refine.append((i, [float(k) for k in np.linspace(grid[j - 1], grid[j], fine)]))
    second = _growth([(cfgs[i], k) for i, ks in refine for k in ks], protocol, executor)
    for n, (i, _ks) in enumerate(refine):
        k_on = onset(second[n * fine : (n + 1) * fine])
        out[i] = (None if k_on is None else float(k_on)), False
    return [o for o in out if o is not None]


def stability_map(
    controllers: list[tuple[str, float]],
    dampings: list[float],
    base: SessionConfig | None = None,
    observer_gain: float | None = None,
    executor: Executor | None = None,
) -> list[MapPoint]:
    """Onsets for every (controller, Kf) and wall damping (``executor``: a shared process pool)."""
    base = base or SessionConfig()
    if observer_gain is not None:
        base = base.replace(observer=ObserverSettings(observer_gain, base.observer.output_limit))
    T = 1.0 / base.loop.rate_hz
    b = base.device.viscous_n_s_per_m
    w = base.wall
    cases = [(mode, kf, damping) for mode, kf in controllers for damping in dampings]
    cfgs = [
        base.replace(
            law=law_for(mode, kf, base.law.max_force_n),
            wall=VirtualWall(w.stiffness_n_per_m, damping, w.position, w.normal),
        )
        for mode, kf, damping in cases
    ]
    out = []
    for (mode, kf, damping), (k_on, below) in zip(
        cases, find_onsets(cfgs, StabilityProtocol(), executor), strict=True
    ):
        kf_eff = kf if mode != "OL" else 0.0
        out.append(
            MapPoint(
                mode,
                kf_eff,
                damping,
                base.observer.gain,
                k_on,
                below,
                passivity_bound(b, T, kf_eff, damping),
            )
        )
    return out


def map_study(base: SessionConfig, executor: Executor | None = None) -> StabilityMap:
    """The onset against Kf for OL, CL and DOB (B = 0) and the Z-width's rows (B > 0)."""
    controllers = [("OL", 0.0)] + [(m, kf) for m in ("CL", "DOB") for kf in MAP_KFS]
    points = stability_map(controllers, [0.0], base, executor=executor)
    damped = [d for d in ZWIDTH_DAMPINGS if d != 0.0]
    return StabilityMap(points + stability_map(ZWIDTH_CONTROLLERS, damped, base, executor=executor))
