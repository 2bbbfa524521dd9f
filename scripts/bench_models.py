"""Benchmarks of the multi-DOF models (not timed tests): medians over repeated runs.

Usage: ``.venv/bin/python scripts/bench_models.py [NAME ...] [--repeat N]``; without names, all
run. Measured like ``scripts/benchmarks.py observer`` measures the slide: ``timeit`` of the call
the loop makes with a sample of tuples of floats (validation, dynamics, implicit update, clip).

- ``phantom``: one PHANToM 1.5 observer update (``update``), and ``update`` + ``wrench``.
- ``arm7``: the same for the 7-DOF URDF arm ``config/urdf/arm7.urdf``.
- ``phantom_sim``: one control cycle of the simulated PHANToM (10 RK4 sub-steps), no hand and with
  the semi-random hand.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import timeit
from collections.abc import Callable
from pathlib import Path

import numpy as np

from haptic_dob.core.models.base import DeviceModel

sys.path.insert(0, str(Path(__file__).resolve().parent))
from benchmarks import machine
from haptic_dob.core.models import PhantomModel, UrdfModel
from haptic_dob.core.observers.disturbance import DisturbanceObserver
from haptic_sim.arm.device import SimulatedArm
from haptic_sim.hand import HandParams

ROOT = Path(__file__).resolve().parents[1]


def _median_us(fn: Callable[[], object], repeat: int, number: int) -> tuple[float, float]:
    runs = [timeit.timeit(fn, number=number) / number * 1e6 for _ in range(repeat)]
    return statistics.median(runs), min(runs)


def _observer(model: DeviceModel, q: tuple, qd: tuple, tau: tuple, repeat: int) -> str:
    obs = DisturbanceObserver(model, 2.0, 1e-3, 50.0)
    obs.update(q, qd, tau)
    n = 20_000
    upd, upd_min = _median_us(lambda: obs.update(q, qd, tau), repeat, n)

    def both() -> None:
        obs.update(q, qd, tau)
        obs.wrench(q)

    full, full_min = _median_us(both, repeat, n)
    return (
        f"update median {upd:.1f} us (min {upd_min:.1f}); "
        f"update + wrench median {full:.1f} us (min {full_min:.1f})"
    )


def bench_phantom(repeat: int) -> str:
    """PHANToM 1.5 (appendix B) observer update, dynamics by pinocchio on the open tree."""
    return _observer(PhantomModel(), (0.1, 0.2, 1.4), (0.01, 0.02, -0.03), (0.1, 0.2, 0.3), repeat)


def bench_arm7(repeat: int) -> str:
    """7-DOF URDF arm observer update."""
    model = UrdfModel(ROOT / "config" / "urdf" / "arm7.urdf", "tool")
    q = tuple(np.linspace(0.1, 0.7, 7).tolist())
    qd = tuple(np.linspace(-0.2, 0.2, 7).tolist())
    tau = tuple(np.linspace(1.0, 3.0, 7).tolist())
    return _observer(model, q, qd, tau, repeat)


def bench_phantom_sim(repeat: int) -> str:
    """One 1 kHz cycle of the simulated PHANToM (10 RK4 sub-steps), without and with a hand."""
    out = []
    for behaviour in ("none", "semi_random"):
        dev = SimulatedArm(PhantomModel(), hand=HandParams(behaviour=behaviour))
        med, low = _median_us(lambda dev=dev: dev.apply([0.0, 0.0, 0.0]), repeat, 500)
        out.append(f"hand {behaviour}: median {med:.0f} us per cycle (min {low:.0f})")
    return "; ".join(out)


BENCHMARKS: dict[str, Callable[[int], str]] = {
    "phantom": bench_phantom,
    "arm7": bench_arm7,
    "phantom_sim": bench_phantom_sim,
}


def main(argv: list[str] | None = None) -> int:
    """Run the named benchmarks (default: all) and print one line each."""
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("names", nargs="*", help=f"benchmarks to run: {', '.join(BENCHMARKS)}")
    p.add_argument("--repeat", type=int, default=7, help="repetitions (median reported)")
    a = p.parse_args(argv)
    unknown = [n for n in a.names if n not in BENCHMARKS]
    if unknown:
        p.error(f"unknown benchmark(s) {', '.join(unknown)}; choose from {', '.join(BENCHMARKS)}")
    print(f"machine: {machine()}")
    for name in a.names or list(BENCHMARKS):
        print(f"{name}: {BENCHMARKS[name](a.repeat)}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
