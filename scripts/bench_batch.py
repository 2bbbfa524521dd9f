"""In-process benchmarks of the loop's maths with no transport: batch sessions, one observer update.

``batch_cycle_us`` is also the batch floor ``benchmarks.py margin`` compares the graph with.
"""

from __future__ import annotations

import statistics
import time
import timeit

from haptic_dob.core.models import SlideModel
from haptic_dob.core.observers.disturbance import DisturbanceObserver
from haptic_sim.slide.session import SessionConfig, run_session
from haptic_sim.slide.stability import law_for


def bench_batch_session(repeat: int) -> str:
    """A 40 s slide session at 1 kHz (default config, OL and DOB): real-time factor, cycle."""
    out = []
    for mode, kf in (("OL", 0.0), ("DOB", 1.0)):
        cfg = SessionConfig().replace(law=law_for(mode, kf))
        times = []
        for _ in range(repeat):
            t0 = time.perf_counter()
            run_session(cfg)
            times.append(time.perf_counter() - t0)
        med = statistics.median(times)
        out.append(
            f"{mode}: median {med:.3f} s for 40 s simulated -> {40.0 / med:.1f}x real time, "
            f"{med / 40.0 * 1e3:.1f} us a cycle"
        )
    return "; ".join(out)


def bench_observer_update(repeat: int) -> str:
    """One slide observer update (validation, implicit update, clip): microseconds."""
    obs = DisturbanceObserver(SlideModel(), 41.6, 1e-3, 4.0)
    q, qd, tau = (0.001,), (0.01,), (0.5,)
    obs.update(q, qd, tau)
    n = 100_000
    runs = [
        timeit.timeit(lambda: obs.update(q, qd, tau), number=n) / n * 1e6 for _ in range(repeat)
    ]
    return f"median {statistics.median(runs):.2f} us per update (min {min(runs):.2f})"


def batch_cycle_us(mode: str = "DOB", kf: float = 1.0, seconds: float = 10.0) -> float:
    """One batch slide session's time per cycle (µs): the maths of the loop with no transport."""
    cfg = SessionConfig().replace(law=law_for(mode, kf), loop__duration_s=seconds)
    t0 = time.perf_counter()
    run_session(cfg)
    return (time.perf_counter() - t0) / (seconds * 1e3) * 1e6
