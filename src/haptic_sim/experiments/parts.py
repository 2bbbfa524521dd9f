"""The one table of the reproduction's experiments: ``EXPERIMENTS``, one entry per part.

An entry says how its part runs (through the node graph or in batch), the type of its result, and
its section of the report: heading, introduction, tables and text, figures, notes, acceptance
checks, the paragraphs it adds to "where the simulation differs", and its lines in the terminal.
``haptic-experiment`` runs the parts from it and the report renders them from it, in its order;
``save_results`` and ``load_results`` write and read ``results.json`` through its result types.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path
from typing import Any

from haptic_sim.experiments import (
    discussion,
    dob_mechanism,
    figures,
    identification,
    identification_report,
    observer_vs_sensor,
    observer_vs_sensor_report,
    phantom,
    plan,
    results,
    slave_model,
    spread_report,
    stability_map,
    sweeps,
    sweeps_report,
    tables,
)
from haptic_sim.experiments.entry import BatchJob, Experiment, Figure, GraphJob
from haptic_sim.experiments.jsonio import from_json, to_json
from haptic_sim.experiments.records import Ch6Result, Ch7Result, ExperimentResults
from haptic_sim.slide.session import SessionConfig


def _b_rate(base: SessionConfig) -> tuple[float, float]:
    """The simulated plant's viscous friction (N s/m) and the loop rate (Hz): the bound's inputs."""
    return base.device.viscous_n_s_per_m, base.loop.rate_hz


def _kick_traces(base: SessionConfig, path: Path) -> None:
    """The stick-or-chatter traces: simulated and drawn while the dob part runs."""
    wall = dob_mechanism.TRACES_WALL
    figures.plot_kick_traces(dob_mechanism.traces(base, wall), wall, path)


CH4: Experiment[identification.Ch4Result] = Experiment(
    part="ch4",
    result_type=identification.Ch4Result,
    job=GraphJob(identification.chapter4_runs, identification.ch4_result, analyse=False),
    heading="Chapter 4: identification and model verification through the node graph",
    intro="The graph holds the simulated slide in an 80 N/m two-sided virtual spring (OL, no "
    "hand) while the environment adds a known force: the thesis's 2.4 N step to identify the "
    "model, 1.6 N and 3.2 N steps and a 0.6 N, 2 Hz sine to verify it. Each run is a bag; "
    "`haptic-identify`'s core reads the joint states of the 2.4 N bag.",
    body=lambda r, base: [identification_report.ch4_tables(r, base)],
    figures=(
        Figure(
            "ch4_identification.png", "thesis figure 4.2", identification_report.plot_identification
        ),
        Figure(
            "ch4_verification.png", "thesis figure 4.3", identification_report.plot_verification
        ),
    ),
    notes=lambda r: [identification_report.ch4_notes(r)],
    checks=lambda r: r.checks,
    console=identification_report.ch4_console,
)
CH5: Experiment[observer_vs_sensor.Ch5Result] = Experiment(
    part="ch5",
    result_type=observer_vs_sensor.Ch5Result,
    job=GraphJob(observer_vs_sensor.chapter5_runs, observer_vs_sensor.ch5_result, analyse=False),
    heading="Thesis section 5.3: the observer against the force sensor",
    intro="The observer runs beside an OL loop (the model it assumes, its output clipped to "
    "4 N as the thesis clipped it) while the semi-random hand moves the slide in free space, "
    "then pushes into an 800 N/m wall; each session is a bag.",
    body=lambda r, base: [observer_vs_sensor_report.ch5_table(r, base)],
    figures=(Figure("ch5_observer.png", "thesis section 5.3", observer_vs_sensor_report.plot_ch5),),
    console=observer_vs_sensor_report.ch5_console,
)
CH7: Experiment[Ch7Result] = Experiment(
    part="ch7",
    result_type=Ch7Result,
    job=GraphJob(plan.chapter7_plan, lambda rows, _base: results.ch7_result(rows)),
    heading="Chapter 7: transparency",
    body=lambda r, _base: [tables.ch7_tables(r.rows)],
    figures=(
        Figure(
            "ch7_transparency.png",
            "chapter 7",
            lambda r, path, _base: figures.plot_ch7(r.rows, path),
        ),
    ),
    quick=True,
    notes=lambda r: [discussion.ch7_notes(r.rows)],
    checks=lambda r: r.checks,
    differences=lambda r: discussion.ch7_differences(r.rows),
    console=lambda r: tables.ch7_console(r.rows),
)
CH6: Experiment[Ch6Result] = Experiment(
    part="ch6",
    result_type=Ch6Result,
    job=GraphJob(plan.chapter6_plan, results.ch6_result),
    heading="Chapter 6: vibration onset through the node graph",
    intro="The thesis's user tried to provoke vibration; here a light 20 N/m grip pushes 1 N "
    "into the wall, in two protocols run as node-graph sessions. The linear one (that of "
    "`haptic-stability`, README) leaves Coulomb friction out of the plant and the model, the "
    "premise of the passivity bounds the thesis compared its OL and CL onsets with, and pulses "
    "the handle with 0.5 N for 5 ms; the onset is the interpolated zero crossing of the pulse "
    "response's growth rate along the walls. The tap keeps the configuration's plant and model "
    "as they are and taps with 3 N for 20 ms.",
    body=lambda r, base: [
        tables.ch6_table(r.onsets, *_b_rate(base)),
        tables.ch6_tap_table(r.taps),
    ],
    figures=(
        Figure(
            "ch6_onsets.png",
            "chapter 6",
            lambda r, path, base: figures.plot_ch6(r.onsets, path, *_b_rate(base)),
        ),
    ),
    checks=lambda r: r.checks,
    differences=lambda _r: [
        discussion.ONSETS_FROM_A_PROTOCOL,
        discussion.OBSERVER_GAIN,
    ],
    console=lambda r: tables.ch6_console(r.onsets, r.taps),
)
MAP: Experiment[stability_map.StabilityMap] = Experiment(
    part="map",
    result_type=stability_map.StabilityMap,
    job=BatchJob(
        lambda base, pool, _figs: stability_map.map_study(base, pool),
        lambda r: f"stability map: {len(r.points)} onsets",
    ),
    heading="Stability map (batch)",
    intro="The same protocol swept coarse-to-fine in batch simulation for each Kf, and for "
    "three controllers against the wall damping (Z-width).",
    body=lambda r, _base: [tables.map_table(r.points)],
    figures=(
        Figure(
            "onset_vs_kf.png",
            "onset against Kf",
            lambda r, path, base: figures.plot_onset_vs_kf(
                r.points, path, base.device.viscous_n_s_per_m, 1.0 / base.loop.rate_hz
            ),
        ),
        Figure("zwidth.png", "Z-width", lambda r, path, _base: figures.plot_zwidth(r.points, path)),
    ),
)
DOB: Experiment[dob_mechanism.DobStudy] = Experiment(
    part="dob",
    result_type=dob_mechanism.DobStudy,
    job=BatchJob(
        lambda base, pool, _figs: dob_mechanism.study(base, pool),
        lambda _r: "DOB mechanism study: done",
    ),
    heading="The DOB question: quiet at Kf = 100 up to 2400 N/m",
    intro="Chapter 6's tap in batch (a light 20 N/m grip pushing 1 N into the wall, a 3 N "
    "tap for 20 ms) with DOB at Kf = 100, over the observer gain, with the plant's friction "
    "kept or off, and with a firmer hand; the residual motion 2-3 s after the tap says "
    "whether the wall keeps vibrating.",
    body=lambda r, base: [tables.dob_tables(r), discussion.dob_discussion(r, base.observer.gain)],
    figures=(
        Figure(
            "dob_kick_grid.png",
            "kick grid",
            lambda r, path, _base: figures.plot_kick_grid(r.kick, path),
        ),
        Figure("dob_kick_traces.png", "stick or chatter", simulate=_kick_traces),
    ),
    differences=lambda _r: [discussion.OBSERVER_GAIN],
)
SWEEPS: Experiment[sweeps.SweepStudy] = Experiment(
    part="sweeps",
    result_type=sweeps.SweepStudy,
    job=BatchJob(
        lambda base, pool, _figs: sweeps.study(base, pool),
        lambda r: f"Table 7.1's off cells swept: {len(r.cells) + len(r.seeds)} cells",
    ),
    heading="Table 7.1's cells that stay off, against the parameter responsible (batch)",
    intro="Controllers of Table 7.1 in the chapter-7 session (40 s, the hand's seed 0, "
    "as chapter 7's default), with one parameter swept from the chapter-7 value: "
    "the hand's grip damping at 2400 N/m (and, for OL with a loose grip, the friction), the "
    "hand's depth at 80 N/m, the observer gain and "
    "the plant's low-speed friction at every wall (DOB), the force sensor's bandwidth at 1600 "
    "and 2400 N/m (CL): each cell that stays off has its sweep. Then the whole table for three "
    "seeds of the hand and their median.",
    body=lambda r, _base: [
        sweeps_report.sweep_table(r, sweeps.GRIP),
        sweeps_report.grip_text(r),
        sweeps_report.sweep_table(r, sweeps.VIBRATING),
        sweeps_report.vibrating_text(r),
        sweeps_report.sweep_table(r, sweeps.DEPTH),
        sweeps_report.depth_text(r),
        sweeps_report.sweep_table(r, sweeps.OBSERVER),
        sweeps_report.observer_text(r),
        sweeps_report.sweep_table(r, sweeps.FRICTION),
        sweeps_report.friction_text(r),
        sweeps_report.sweep_table(r, sweeps.SENSOR),
        sweeps_report.sensor_text(r),
        spread_report.spread_table(r.seeds),
    ],
    figures=(),
    checks=sweeps_report.checks,
    differences=sweeps_report.differences,
)
PHANTOM: Experiment[phantom.PhantomResult] = Experiment(
    part="phantom",
    result_type=phantom.PhantomResult,
    job=BatchJob(
        lambda _base, _pool, figs: phantom.reproduce(figs),
        lambda _r: "PHANToM section 5.2: done",
    ),
    heading="Thesis section 5.2: the PHANToM 1.5 (batch)",
    body=lambda r, _base: [discussion.phantom_text(r)],
    figures=(Figure("thesis_5_2_1.png", "5.2.1"), Figure("thesis_5_2_2.png", "5.2.2")),
)
SLAVE: Experiment[slave_model.SlaveModelResult] = Experiment(
    part="slave",
    result_type=slave_model.SlaveModelResult,
    job=GraphJob(slave_model.slave_runs, slave_model.slave_result, analyse=False),
    heading="Teleoperation: the slave's model identified from its own bag",
    intro="The teleoperation slave's simulated arm has its own truth (link masses 10-20 % off "
    "its URDF, centres of mass 1-2 cm away, joint friction and armature the URDF lacks). The "
    "graph runs the slave alone, the table taken away, its controller playing the excitation "
    "`haptic-excite` designed, recorded; `haptic-identify --inertial`'s core finds the model "
    "in the bag's joint states; an observer on each model then meets the slave in batch.",
    body=lambda r, _base: [slave_model.slave_tables(r)],
    figures=(Figure("slave_rest.png", "the estimate at rest", slave_model.plot_rest),),
    checks=lambda r: r.checks,
    console=slave_model.slave_console,
)
#: the parts in the report's order
EXPERIMENTS: tuple[Experiment[Any], ...] = (CH4, CH5, CH7, CH6, MAP, DOB, SWEEPS, PHANTOM, SLAVE)
PARTS: tuple[str, ...] = tuple(e.part for e in EXPERIMENTS)
QUICK_PARTS: list[str] = [e.part for e in EXPERIMENTS if e.quick]


def present(res: ExperimentResults) -> list[tuple[Experiment[Any], Any]]:
    """The parts run in ``res`` with their results, in the table's order."""
    found = [(e, e.result_in(res)) for e in EXPERIMENTS]
    return [(e, r) for e, r in found if r is not None]


def save_results(path: Path, res: ExperimentResults) -> None:
    """Write ``results.json`` (indented JSON; the parts in the table's order)."""
    ordered = replace(res, results={e.part: r for e, r in present(res)})
    path.write_text(json.dumps(to_json(ordered), indent=1) + "\n", encoding="utf-8")


def load_results(path: Path) -> ExperimentResults:
    """Read ``results.json`` back into typed results; ``ValueError`` if it is not one."""
    res = from_json(ExperimentResults, json.loads(path.read_text(encoding="utf-8")))
    types = {e.part: e.result_type for e in EXPERIMENTS}
    unknown = set(res.results) - set(types)
    if unknown:
        raise ValueError(f"{path}: unknown part(s) {', '.join(sorted(unknown))}")
    typed = {p: from_json(types[p], v) for p, v in res.results.items()}
    return replace(res, results=typed)
