"""In-process benchmarks of the loop's maths with no transport: batch sessions, one observer update.

``batch_cycle_us`` is also the batch floor ``benchmarks.py margin`` compares the graph with.
"""

from __future__ import annotations

import math
import statistics
import time
import timeit

from haptic_dob.bridge.velocity import KalmanVelocity, WindowVelocity
from haptic_dob.core.models import PointMassModel, SlideModel
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
    """One slide observer update (validation, implicit update, clip), and one Force Dimension
    point mass's (three axes) with the next update's preparation: microseconds."""
    obs = DisturbanceObserver(SlideModel(), 41.6, 1e-3, 4.0)
    q, qd, tau = (0.001,), (0.01,), (0.5,)
    obs.update(q, qd, tau)
    n = 100_000
    runs = [
        timeit.timeit(lambda: obs.update(q, qd, tau), number=n) / n * 1e6 for _ in range(repeat)
    ]
    fd = DisturbanceObserver(PointMassModel([0.2, 0.21, 0.22], 1.0, 0.1), 30.0, 1e-3, 4.0)
    q3, qd3, tau3 = (0.001, 0.002, 0.003), (0.01, -0.02, 0.03), (0.5, -0.4, 0.3)

    def cycle() -> None:
        fd.update(q3, qd3, tau3)
        fd.prepare()

    cycle()
    n3 = 20_000
    runs3 = [timeit.timeit(cycle, number=n3) / n3 * 1e6 for _ in range(repeat)]
    return (
        f"slide: median {statistics.median(runs):.2f} us per update (min {min(runs):.2f}); "
        f"point mass: median {statistics.median(runs3):.2f} us per update and preparation "
        f"(min {min(runs3):.2f})"
    )


def bench_velocity(repeat: int) -> str:
    """The bridge's velocity from a Touch's three joints' counts (4e-4, 4e-4, 8e-4 rad, 500 Hz,
    the joints swinging 0.05 rad at 3, 5 and 7 rad/s): microseconds per state, the adaptive
    window and the Kalman filter (density 800)."""
    counts = [4e-4, 4e-4, 8e-4]
    n = 5000
    states = [
        tuple(
            c * round(0.05 * math.sin(k * 0.002 * w) / c)
            for c, w in zip(counts, (3, 5, 7), strict=True)
        )
        for k in range(n)
    ]
    out = []
    for name, make in (
        ("window (8 periods)", lambda: WindowVelocity(counts, 8, 0.01)),
        ("Kalman", lambda: KalmanVelocity(counts, [800.0] * 3, 0.002, 0.01)),
    ):
        runs = []
        for _ in range(repeat):
            est = make()
            t0 = time.perf_counter()
            for k, q in enumerate(states):
                est.update(k * 2_000_000, q)
            runs.append((time.perf_counter() - t0) / n * 1e6)
        out.append(f"{name} median {statistics.median(runs):.1f} us per state")
    return "; ".join(out)


def batch_cycle_us(mode: str = "DOB", kf: float = 1.0, seconds: float = 10.0) -> float:
    """One batch slide session's time per cycle (µs): the maths of the loop with no transport."""
    cfg = SessionConfig().replace(law=law_for(mode, kf), loop__duration_s=seconds)
    t0 = time.perf_counter()
    run_session(cfg)
    return (time.perf_counter() - t0) / (seconds * 1e3) * 1e6
