"""What the reproduction runs: the thesis's chapter 7 and chapter 6 sessions as node-graph runs.

Chapter 7 (transparency): OL, CL with Kf = 2, DOB with Kf = 1 and Kf = 25 on walls of 80, 800,
1600 and 2400 N/m (thesis 7.1), 40 s of semi-random hand motion each, the same seed and depth
(``haptic_sim.hand.depth_reference``) for every cell; DOB takes its Kf's observer gain
(``observer_gain.gain_at``). OL and CL runs leave the observer out, the controller subscribes
only to its mode's input, and the recorder records what the analysis reads. The quick variant
(the demo): OL, CL Kf = 2 and DOB Kf = 1 at 800 N/m, 40 s each (the 4 s segments need it).

Chapter 6 (vibration onset; docs/reproduction.md): a light 20 N/m grip pushing 1 N into the
wall, 4-4.5 s per wall, in ``haptic_sim.slide.stability``'s two protocols. The linear one (a
0.5 N x 5 ms pulse, Coulomb friction off in plant and model) for OL and CL Kf = 2 over the
thesis's walls and points that bracket their bounds, and DOB Kf = 100 at two walls; the tap
(``TAP``, friction kept) for OL and CL at their thesis walls, DOB at the thesis's and between.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from haptic_sim.experiments.graph_runs import GraphRun, session_params
from haptic_sim.experiments.observer_gain import gain_at
from haptic_sim.experiments.records import Cell, label
from haptic_sim.slide.session import SessionConfig
from haptic_sim.slide.stability import TAP, StabilityProtocol

#: chapter 7's controllers and walls (N/m), as thesis 7.1's text names them
CH7_CONTROLLERS: list[tuple[str, float]] = [("OL", 0.0), ("CL", 2.0), ("DOB", 1.0), ("DOB", 25.0)]
CH7_WALLS: list[float] = [80.0, 800.0, 1600.0, 2400.0]
QUICK_CONTROLLERS: list[tuple[str, float]] = [("OL", 0.0), ("CL", 2.0), ("DOB", 1.0)]
QUICK_WALLS: list[float] = [800.0]
QUICK_DURATION_S = 40.0
CH6_CONTROLLERS: list[tuple[str, float]] = [("OL", 0.0), ("CL", 2.0), ("DOB", 100.0)]
#: the linear protocol: the thesis's walls (800-3200 N/m) and points around the OL and CL bounds
#: (2544, 848 N/m); DOB at two (unstable at every wall)
CH6_WALLS: dict[str, list[float]] = {
    "OL": [800.0, 1600.0, 2000.0, 2400.0, 2800.0, 3200.0],
    "CL": [600.0, 800.0, 900.0, 1000.0, 1200.0, 1600.0, 2400.0, 3200.0],
    "DOB": [800.0, 3200.0],
}
#: the tap with the configuration's friction: OL and CL at their thesis walls and the last one,
#: DOB at the thesis's walls (its onset 3200 N/m) and between
CH6_TAP_WALLS: dict[str, list[float]] = {
    "OL": [2400.0, 3200.0],
    "CL": [800.0, 3200.0],
    "DOB": [800.0, 1600.0, 2000.0, 2400.0, 2800.0, 3200.0, 3600.0],
}
#: the parts of the two protocols' cells (the tap's runs and rows are told apart by it)
CH6_PARTS = {"linear": "ch6", "tap": "ch6tap"}
RECORDED = ["ee_pose", "ee_twist", "wrench_measured", "/parameter_events"]


def _loop_nodes(mode: str) -> list[str]:
    nodes = ["environment_node", "controller_node"]
    return [*nodes, "observer_node"] if mode == "DOB" else nodes


def _run(base_config: Path, cell: Cell, extra: dict[str, dict[str, Any]]) -> GraphRun:
    """The graph run of one cell: the base config, the controller (DOB: the observer gain of
    its Kf), ``extra`` over them."""
    overrides = {
        "controller_node": {"mode": cell.mode, "kf": cell.kf, "warm_inputs": False},
        "device_node": {"wait_for": _loop_nodes(cell.mode), **extra.pop("device_node", {})},
        "recorder_node": {"topics": RECORDED},
        **extra,
    }
    if cell.mode == "DOB":
        base = SessionConfig.from_node_params(session_params(base_config, {}))
        overrides["observer_node"] = {"gain": gain_at(cell.kf, base)}
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
    """The transparency cells as graph runs (the configuration's hand at every wall)."""
    runs = []
    for mode, kf in controllers or CH7_CONTROLLERS:
        for wall in walls or CH7_WALLS:
            extra = {
                "device_node": {"duration_s": duration_s, "seed": seed},
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
    protocol: StabilityProtocol | None = None,
    part: str = CH6_PARTS["linear"],
) -> list[GraphRun]:
    """One protocol's sessions as graph runs (the linear one by default)."""
    p = protocol or StabilityProtocol()
    friction: dict[str, dict[str, Any]] = {}
    if p.coulomb_n is not None:  # the assumed model's and the plant's
        friction = {"/**": {"slide.coulomb_n": p.coulomb_n}}
    runs = []
    for mode, kf in controllers or CH6_CONTROLLERS:
        for wall in (walls or CH6_WALLS)[mode]:
            device: dict[str, Any] = {
                "duration_s": p.duration_s,
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
            }
            if p.coulomb_n is not None:
                device["plant.coulomb_n"] = p.coulomb_n
            extra: dict[str, dict[str, Any]] = {
                **friction,
                "device_node": device,
                "environment_node": {"stiffness_n_per_m": wall},
            }
            runs.append(_run(base_config, Cell(part, mode, kf, wall), extra))
    return runs


def chapter6_plan(base_config: Path, _seed: int, _quick: bool) -> list[GraphRun]:
    """Chapter 6's runs, both protocols (the hand holds still: no seed; no quick variant)."""
    tap = chapter6_runs(base_config, walls=CH6_TAP_WALLS, protocol=TAP, part=CH6_PARTS["tap"])
    return chapter6_runs(base_config) + tap
