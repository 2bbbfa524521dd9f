"""What the reproduction runs: the thesis's chapter 7 and chapter 6 sessions as node-graph runs.

Chapter 7 (transparency): OL, CL with Kf = 2, DOB with Kf = 1 and Kf = 25 on walls of 80, 800,
1600 and 2400 N/m, 40 s of semi-random hand motion each (the same seed for every cell, so every
controller meets the same hand). The hand's push and swing follow the wall
(``reference_for_force``). OL and CL runs leave the observer out (they do not use it) and the
controller subscribes only to its own mode's input; the recorder records what the analysis reads.

Chapter 6 (vibration onset, through the graph): the push-and-hold protocol of ``haptic-stability``
(Coulomb friction off, a light 20 N/m grip, a 0.5 N x 5 ms pulse), for OL, CL with Kf = 2 and DOB
with Kf = 100 over the thesis's walls (800 to 3200 N/m) plus points that bracket the OL and CL
bounds, 4 s each.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from haptic_sim.experiments.graph_runs import GraphRun, session_params
from haptic_sim.hand import reference_for_force
from haptic_sim.stability import StabilityProtocol

CH7_CONTROLLERS: list[tuple[str, float]] = [("OL", 0.0), ("CL", 2.0), ("DOB", 1.0), ("DOB", 25.0)]
CH7_WALLS: list[float] = [80.0, 800.0, 1600.0, 2400.0]
CH6_CONTROLLERS: list[tuple[str, float]] = [("OL", 0.0), ("CL", 2.0), ("DOB", 100.0)]
#: the thesis's walls (800-3200 N/m) and points around the OL and CL bounds (2544, 848 N/m)
CH6_WALLS: dict[str, list[float]] = {
    "OL": [800.0, 1600.0, 2000.0, 2400.0, 2800.0, 3200.0],
    "CL": [600.0, 800.0, 900.0, 1000.0, 1200.0, 1600.0, 2400.0, 3200.0],
    "DOB": [800.0, 1600.0, 2400.0, 3200.0],
}
RECORDED = ["ee_pose", "ee_twist", "wrench_measured", "/parameter_events"]

#: thesis Table 7.1 (bandwidth, Hz) and 7.2 (impedance error, %), walls 80, 800, 1600, 2400 N/m
THESIS_BANDWIDTH: dict[tuple[str, float], list[float]] = {
    ("OL", 0.0): [1.3, 3.8, 5.3, 0.6],
    ("CL", 2.0): [1.7, 5.5, 6.6, 4.5],
    ("DOB", 1.0): [1.6, 5.1, 6.0, 5.3],
    ("DOB", 25.0): [1.8, 2.9, 3.9, 3.4],
}
THESIS_ERROR: dict[tuple[str, float], list[float]] = {
    ("OL", 0.0): [26.8, 30.5, 27.0, 29.0],
    ("CL", 2.0): [25.4, 30.4, 22.8, 16.5],
    ("DOB", 1.0): [23.9, 34.0, 30.9, 26.6],
    ("DOB", 25.0): [40.3, 32.0, 26.0, 22.7],
}
#: thesis chapter 6: the lowest wall that vibrated (N/m)
THESIS_ONSET: dict[str, float] = {"OL": 2400.0, "CL": 800.0, "DOB": 3200.0}


def label(mode: str, kf: float) -> str:
    """``OL``, ``CL Kf=2``..."""
    return mode if mode == "OL" else f"{mode} Kf={kf:g}"


def _loop_nodes(mode: str) -> list[str]:
    nodes = ["environment_node", "controller_node"]
    return [*nodes, "observer_node"] if mode == "DOB" else nodes


def _base(base_config: Path, mode: str, kf: float, extra: dict[str, dict[str, Any]]) -> dict:
    overrides = {
        "controller_node": {"mode": mode, "kf": kf, "warm_inputs": False},
        "device_node": {"wait_for": _loop_nodes(mode), **extra.pop("device_node", {})},
        "recorder_node": {"topics": RECORDED},
        **extra,
    }
    params = session_params(base_config, overrides)
    if mode != "DOB":
        params.pop("observer_node", None)
    return params


def chapter7_runs(
    base_config: Path,
    seed: int = 0,
    duration_s: float = 40.0,
    controllers: list[tuple[str, float]] | None = None,
    walls: list[float] | None = None,
) -> list[GraphRun]:
    """The transparency cells as graph runs."""
    k_h = float(session_params(base_config, {})["device_node"]["hand.stiffness_n_per_m"])
    runs = []
    for mode, kf in controllers or CH7_CONTROLLERS:
        for wall in walls or CH7_WALLS:
            offset, amplitude = reference_for_force(wall, k_h)
            extra = {
                "device_node": {
                    "duration_s": duration_s,
                    "seed": seed,
                    "hand.offset_m": offset,
                    "hand.amplitude_m": amplitude,
                },
                "environment_node": {"stiffness_n_per_m": wall},
            }
            name = f"ch7_{mode}_kf{kf:g}_k{wall:g}".replace(".", "p")
            runs.append(
                GraphRun(
                    name,
                    _base(base_config, mode, kf, extra),
                    f"ch7 {label(mode, kf)}, {wall:g} N/m",
                    {"part": "ch7", "mode": mode, "kf": kf, "wall": wall},
                )
            )
    return runs


def chapter6_runs(
    base_config: Path,
    controllers: list[tuple[str, float]] | None = None,
    walls: dict[str, list[float]] | None = None,
) -> list[GraphRun]:
    """The onset protocol's sessions as graph runs."""
    p = StabilityProtocol()
    runs = []
    for mode, kf in controllers or CH6_CONTROLLERS:
        for wall in (walls or CH6_WALLS)[mode]:
            extra: dict[str, dict[str, Any]] = {
                "/**": {"slide.coulomb_n": p.coulomb_n},
                "device_node": {
                    "duration_s": p.pulse_at_s + p.observe_s,
                    "hand.behaviour": "push_hold",
                    "hand.mass_kg": 0.0,
                    "hand.stiffness_n_per_m": p.grip_n_per_m,
                    "hand.damping_n_s_per_m": 0.0,
                    "hand.offset_m": p.push_n * (1.0 / wall + 1.0 / p.grip_n_per_m),
                    "hand.amplitude_m": 0.0,
                    "hand.ramp_s": p.ramp_s,
                    "hand.perturbation_n": p.pulse_n,
                    "hand.perturbation_at_s": p.pulse_at_s,
                    "hand.perturbation_s": p.pulse_s,
                },
                "environment_node": {"stiffness_n_per_m": wall},
            }
            name = f"ch6_{mode}_kf{kf:g}_k{wall:g}".replace(".", "p")
            runs.append(
                GraphRun(
                    name,
                    _base(base_config, mode, kf, extra),
                    f"ch6 {label(mode, kf)}, {wall:g} N/m",
                    {"part": "ch6", "mode": mode, "kf": kf, "wall": wall},
                )
            )
    return runs
