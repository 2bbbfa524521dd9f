"""Benchmarks of the suite (not timed tests): each prints medians over repeated runs.

Usage: ``.venv/bin/python scripts/benchmarks.py [NAME ...] [--repeat N]``; without names, all
in-process benchmarks run. BENCHMARKS.md records the figures with the exact command and machine.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import time
from collections.abc import Callable


def machine() -> str:
    """CPU model, core count and Python version of this machine."""
    model = platform.processor() or "unknown CPU"
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as fh:
            for line in fh:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return f"{model}, {os.cpu_count()} cores, Python {platform.python_version()}"


def bench_batch_session(repeat: int) -> str:
    """A 40 s slide session at 1 kHz (default config, OL and DOB): real-time factor."""
    from haptic_sim.session import SessionConfig, run_session
    from haptic_sim.stability import law_for

    out = []
    for mode, kf in (("OL", 0.0), ("DOB", 1.0)):
        cfg = SessionConfig().replace(law=law_for(mode, kf))
        times = []
        for _ in range(repeat):
            t0 = time.perf_counter()
            run_session(cfg)
            times.append(time.perf_counter() - t0)
        med = statistics.median(times)
        out.append(f"{mode}: median {med:.3f} s for 40 s simulated -> {40.0 / med:.1f}x real time")
    return "; ".join(out)


def bench_observer_update(repeat: int) -> str:
    """One slide observer update (validation, implicit update, clip): microseconds."""
    import timeit

    from haptic_dob.models import SlideModel
    from haptic_dob.observer import DisturbanceObserver

    obs = DisturbanceObserver(SlideModel(), 41.6, 1e-3, 4.0)
    q, qd, tau = (0.001,), (0.01,), (0.5,)
    obs.update(q, qd, tau)
    n = 100_000
    runs = [
        timeit.timeit(lambda: obs.update(q, qd, tau), number=n) / n * 1e6 for _ in range(repeat)
    ]
    return f"median {statistics.median(runs):.2f} us per update (min {min(runs):.2f})"


BENCHMARKS: dict[str, Callable[[int], str]] = {
    "batch": bench_batch_session,
    "observer": bench_observer_update,
}


def main(argv: list[str] | None = None) -> int:
    """Run the named benchmarks (default: all) and print one line each."""
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("names", nargs="*", choices=[*BENCHMARKS, []], help="benchmarks to run")
    p.add_argument("--repeat", type=int, default=5, help="repetitions (median reported)")
    a = p.parse_args(argv)
    print(f"machine: {machine()}")
    for name in a.names or list(BENCHMARKS):
        print(f"{name}: {BENCHMARKS[name](a.repeat)}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
