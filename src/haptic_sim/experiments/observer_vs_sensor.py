"""Thesis section 5.3 through the node graph: the observer's estimate against the force sensor.

Two recorded sessions with the observer running beside an OL loop (its model the assumed one,
its output clipped to the actuator's 4 N as the thesis clipped it): the semi-random hand moving
the slide in free space (no wall), and pushing into an 800 N/m wall as in chapter 7. The report
sets the estimate (``wrench_estimate``) against the handle's force sensor (``wrench_measured``)
and the simulation's true hand force (``sim/hand_wrench``), with RMS differences after the
hand's ramp-in.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from haptic_dob.bag.reader import Selection, read_bag
from haptic_msgs_py.topics import EE_POSE, HAND_WRENCH, WRENCH_ESTIMATE, WRENCH_MEASURED
from haptic_sim.experiments.graph_runs import GraphRun, session_params
from haptic_sim.experiments.records import Cell, RunAnalysis
from haptic_sim.slide.session import SessionConfig

WALLS = (0.0, 800.0)  # N/m: free space, the thesis's wall
DURATION_S = 10.0
SETTLE_S = 2.0  # the hand's ramp-in, left out of the figures
FREE_AMPLITUDE_M = 0.002  # the hand's swing in free space: forces within the 4 N clip
RECORDED = [WRENCH_ESTIMATE, WRENCH_MEASURED, HAND_WRENCH, EE_POSE, "ee_twist", "/parameter_events"]
TRACE_HZ = 200.0


@dataclass(frozen=True)
class ObserverRun:
    """One session: RMS differences (N) after the ramp-in, the estimate's clipping, the traces."""

    run: str
    wall_n_per_m: float
    rms_estimate_vs_sensor_n: float
    rms_estimate_vs_true_n: float
    rms_sensor_vs_true_n: float
    clipped_pct: float  # samples where the estimate sits at its 4 N limit
    estimate_n: list[float]  # at TRACE_HZ, from SETTLE_S on
    sensor_n: list[float]
    true_n: list[float]


@dataclass(frozen=True)
class Ch5Result:
    """Free space and the 800 N/m wall."""

    runs: list[ObserverRun]


def run_name(wall: float) -> str:
    """``ch5_free`` or ``ch5_wall800``."""
    return "ch5_free" if wall == 0.0 else f"ch5_wall{wall:g}"


def chapter5_runs(base_config: Path, seed: int = 0, _quick: bool = False) -> list[GraphRun]:
    """The free-space session and the wall session (OL, the observer beside the loop)."""
    runs = []
    for wall in WALLS:
        hand = {"hand.offset_m": 0.0, "hand.amplitude_m": FREE_AMPLITUDE_M} if wall == 0.0 else {}
        params = session_params(
            base_config,
            {
                "controller_node": {"mode": "OL", "kf": 0.0, "warm_inputs": False},
                "device_node": {
                    "wait_for": ["environment_node", "observer_node", "controller_node"],
                    "duration_s": DURATION_S,
                    "seed": seed,
                    **hand,
                },
                "environment_node": {"stiffness_n_per_m": wall},
                "recorder_node": {"topics": RECORDED},
            },
        )
        text = "ch5 observer vs sensor, " + ("free space" if wall == 0.0 else f"{wall:g} N/m")
        runs.append(GraphRun(run_name(wall), params, Cell("ch5", "OL", 0.0, wall), text))
    return runs


def _forces(bag: str, topic: str) -> tuple[np.ndarray, np.ndarray]:
    """Stamps (ns) and the force along the slide's x of one wrench topic."""
    series = read_bag(bag, Selection(force_topic=topic)).force
    return series.stamps_ns, np.asarray(series.values, dtype=np.float64)


def _rms(x: np.ndarray) -> float:
    return math.sqrt(float(np.mean(x * x)))


def ch5_result(rows: list[RunAnalysis], base: SessionConfig) -> Ch5Result:
    """The three forces of each bag on their common stamps after the ramp-in."""
    limit = base.observer.output_limit or math.inf
    out = []
    for row in rows:
        series = [_forces(row.bag, t) for t in (WRENCH_ESTIMATE, WRENCH_MEASURED, HAND_WRENCH)]
        common = series[0][0]
        for stamps, _ in series[1:]:
            common = np.intersect1d(common, stamps)
        common = common[common >= SETTLE_S * 1e9]
        est, sen, tru = (v[np.searchsorted(s, common)] for s, v in series)
        step = max(1, round(base.loop.rate_hz / TRACE_HZ))
        out.append(
            ObserverRun(
                row.name,
                row.wall,
                _rms(est - sen),
                _rms(est - tru),
                _rms(sen - tru),
                float(np.mean(np.abs(est) >= limit * (1 - 1e-9)) * 100.0),
                [round(float(v), 4) for v in est[::step]],
                [round(float(v), 4) for v in sen[::step]],
                [round(float(v), 4) for v in tru[::step]],
            )
        )
    return Ch5Result(out)
