"""What the reproduction runs: the thesis's chapter 7 and chapter 6 sessions as node-graph runs.

Chapter 7 (transparency): OL, CL with Kf = 2, DOB with Kf = 1 and Kf = 25 on walls of 80, 800,
1600 and 2400 N/m, 40 s of semi-random hand motion each (the same seed for every cell, so every
controller meets the same hand). The hand's push and swing follow the wall
(``reference_for_force``). OL and CL runs leave the observer out (they do not use it) and the
controller subscribes only to its own mode's input; the recorder records what the analysis reads.
The quick variant (the demo) runs OL, CL Kf = 2 and DOB Kf = 1 at 800 N/m for 20 s.

Chapter 6 (vibration onset, through the graph): the push-and-hold protocol of ``haptic-stability``
(Coulomb friction off, a light 20 N/m grip, a 0.5 N x 5 ms pulse), for OL, CL with Kf = 2 and DOB
with Kf = 100 over the thesis's walls (800 to 3200 N/m) plus points that bracket the OL and CL
bounds, 4 s each.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from haptic_sim.experiments import thesis
from haptic_sim.experiments.graph_runs import GraphRun, session_params
from haptic_sim.experiments.records import Cell, label
from haptic_sim.hand import reference_for_force
from haptic_sim.stability import StabilityProtocol

CH7_CONTROLLERS: list[tuple[str, float]] = [("OL", 0.0), ("CL", 2.0), ("DOB", 1.0), ("DOB", 25.0)]
CH7_WALLS: list[float] = list(thesis.WALLS)
QUICK_CONTROLLERS: list[tuple[str, float]] = [("OL", 0.0), ("CL", 2.0), ("DOB", 1.0)]
QUICK_WALLS: list[float] = [800.0]
QUICK_DURATION_S = 20.0
CH6_CONTROLLERS: list[tuple[str, float]] = [("OL", 0.0), ("CL", 2.0), ("DOB", 100.0)]
#: the thesis's walls (800-3200 N/m) and points around the OL and CL bounds (2544, 848 N/m)
CH6_WALLS: dict[str, list[float]] = {
    "OL": [800.0, 1600.0, 2000.0, 2400.0, 2800.0, 3200.0],
    "CL": [600.0, 800.0, 900.0, 1000.0, 1200.0, 1600.0, 2400.0, 3200.0],
    "DOB": [800.0, 1600.0, 2400.0, 3200.0],
}
RECORDED = ["ee_pose", "ee_twist", "wrench_measured", "/parameter_events"]


def _loop_nodes(mode: str) -> list[str]:
    nodes = ["environment_node", "controller_node"]
    return [*nodes, "observer_node"] if mode == "DOB" else nodes


def _run(base_config: Path, cell: Cell, extra: dict[str, dict[str, Any]]) -> GraphRun:
    """The graph run of one cell: the base config, the controller, ``extra`` over them."""
    overrides = {
        "controller_node": {"mode": cell.mode, "kf": cell.kf, "warm_inputs": False},
        "device_node": {"wait_for": _loop_nodes(cell.mode), **extra.pop("device_node", {})},
        "recorder_node": {"topics": RECORDED},
        **extra,
    }
    params = session_params(base_config, overrides)
    if cell.mode != "DOB":
        params.pop("observer_node", None)
    name = f"{cell.part}_{cell.mode}_kf{cell.kf:g}_k{cell.wall:g}".replace(".", "p")
    text = f"{cell.part} {label(cell.mode, cell.kf)}, {cell.wall:g} N/m"
    return GraphRun(name, params, cell, text)


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
            runs.append(_run(base_config, Cell("ch7", mode, kf, wall), extra))
    return runs


def chapter7_plan(base_config: Path, seed: int, quick: bool) -> list[GraphRun]:
    """Chapter 7's runs: every cell, or the quick variant's."""
    if quick:
        return chapter7_runs(base_config, seed, QUICK_DURATION_S, QUICK_CONTROLLERS, QUICK_WALLS)
    return chapter7_runs(base_config, seed)


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
                "/**": {"slide.coulomb_n": p.coulomb_n},  # the assumed model's
                "device_node": {
                    "plant.coulomb_n": p.coulomb_n,  # and the plant's
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
            runs.append(_run(base_config, Cell("ch6", mode, kf, wall), extra))
    return runs


def chapter6_plan(base_config: Path, _seed: int, _quick: bool) -> list[GraphRun]:
    """Chapter 6's runs (the hand holds still: no seed; no quick variant)."""
    return chapter6_runs(base_config)
