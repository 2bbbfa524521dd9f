"""Chapter 4 through the node graph: identify the slide (4.2) and verify the model (4.3).

As the thesis did on its device, and as a lab does: the graph holds the simulated slide in an
80 N/m two-sided virtual spring (OL, no hand) and the environment adds a known force (the
identification's 2.4 N step; the verification's 1.6 N and 3.2 N steps and 0.6 N, 2 Hz sine),
each run recorded as a bag. ``haptic-identify``'s core finds the model in the 2.4 N bag's joint
states by least squares, by the step method and by the thesis's step formulas; each identified
model then predicts every run (a batch simulation of the model alone, under the same spring and
input) and the prediction is set against the recorded positions. The plant's truth
(``plant.*``, with stiction and an amplifier lag the model leaves out) is shown beside what was
identified. The configuration's observer model (the ``/**`` ``slide.*`` block) is the least-squares
model of the 2.4 N bag to ``MODEL_DIGITS`` significant digits; a check says whether it still is.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from haptic_dob.bag.joints import read_joint
from haptic_dob.core.control import ControlMode, ImpedanceLaw
from haptic_dob.core.environment import VirtualWall
from haptic_dob.core.excitation import Excitation
from haptic_dob.core.models.slide import SlideParams
from haptic_dob.identification.one_dof import IdentificationError, JointRecord, SlideFit, identify
from haptic_dob.runtime.params import values_of
from haptic_sim.experiments.graph_runs import GraphRun, session_params
from haptic_sim.experiments.records import Cell, Check, RunAnalysis
from haptic_sim.hand import HandParams
from haptic_sim.slide.plant import SlideDeviceParams
from haptic_sim.slide.session import SessionConfig, run_session

SPRING_N_PER_M = 80.0
START_S = 1.5  # the input starts here (after the analysis's settle time; the slide rests before)
DURATION_S = 5.0
IDENTIFY = Excitation("step", 2.4, START_S)
VERIFY = (
    Excitation("step", 1.6, START_S),
    Excitation("step", 3.2, START_S),
    Excitation("sine", 0.6, START_S, 2.0),
)
RECORDED = ["joint_states", "ee_pose", "ee_twist", "wrench_measured", "/parameter_events"]
METHODS = ("least_squares", "step", "thesis_step")
TRACE_HZ = 200.0  # the traces kept in results.json for the figures
#: significant digits of the identified model as the configuration states it
MODEL_DIGITS = 4


@dataclass(frozen=True)
class Prediction:
    """One identified model against one run: RMS and final position errors (mm), the traces."""

    run: str
    excitation: str
    method: str
    rms_error_mm: float
    final_error_mm: float  # mean over the last 0.5 s, predicted - measured
    predicted_mm: list[float]  # at TRACE_HZ


@dataclass(frozen=True)
class Ch4Result:
    """The models identified from the 2.4 N bag, their predictions, the measured traces, and
    what could not be identified or predicted (one line each)."""

    fits: list[SlideFit]
    predictions: list[Prediction]
    measured_mm: dict[str, list[float]]  # run name -> positions at TRACE_HZ
    checks: list[Check]
    failures: list[str]


def run_name(e: Excitation) -> str:
    """``ch4_step_2p4``, ``ch4_sine_0p6``..."""
    return f"ch4_{e.kind}_{e.amplitude_n:g}".replace(".", "p")


def chapter4_runs(base_config: Path, _seed: int = 0, _quick: bool = False) -> list[GraphRun]:
    """The identification run and the three verification runs (OL, no hand, the spring)."""
    runs = []
    for e in (IDENTIFY, *VERIFY):
        params = session_params(
            base_config,
            {
                "controller_node": {"mode": "OL", "kf": 0.0, "warm_inputs": False},
                "device_node": {
                    "wait_for": ["environment_node", "controller_node"],
                    "duration_s": DURATION_S,
                    "hand.behaviour": "none",
                },
                "environment_node": {
                    "stiffness_n_per_m": SPRING_N_PER_M,
                    "damping_n_s_per_m": 0.0,
                    "two_sided": True,
                    **values_of(e, "excitation."),
                },
                "recorder_node": {"topics": RECORDED},
            },
        )
        params.pop("observer_node", None)
        cell = Cell("ch4", "OL", 0.0, SPRING_N_PER_M)
        runs.append(GraphRun(run_name(e), params, cell, f"ch4 {e.label()} under the spring"))
    return runs


def rounded(x: float, digits: int = MODEL_DIGITS) -> float:
    """``x`` to ``digits`` significant digits."""
    return float(f"{x:.{digits}g}")


def stated_model(fit: SlideFit) -> tuple[float, float, float]:
    """(m, c, Fc) of a fit as the configuration states them (``MODEL_DIGITS`` digits)."""
    return rounded(fit.mass_kg), rounded(fit.viscous_n_s_per_m), rounded(fit.coulomb_n or 0.0)


def identification_record(base_config: Path) -> JointRecord:
    """The 2.4 N run's joint states from its session in batch (the lockstep graph's bag holds the
    same samples, to the bit): encoder positions and the effort applied over [k-1, k)."""
    run = chapter4_runs(base_config)[0]
    cfg = SessionConfig.from_node_params(run.params)
    res = run_session(cfg)
    period_ns = round(1e9 / cfg.loop.rate_hz)
    stamps = np.arange(res.q.size, dtype=np.int64) * period_ns
    return JointRecord(stamps, res.q, res.effort, "slide")


def model_check(fits: list[SlideFit], model: SlideParams) -> Check:
    """Whether the configuration's observer model is the least-squares model of the 2.4 N bag."""
    ls = next((f for f in fits if f.method == "least_squares"), None)
    stated = (model.mass_kg, model.viscous_n_s_per_m, model.coulomb_n)
    got = stated_model(ls) if ls is not None else None
    return Check(
        f"the configuration's observer model (m {stated[0]:g} kg, c {stated[1]:g} N s/m, Fc "
        f"{stated[2]:g} N) is least squares on the 2.4 N bag to {MODEL_DIGITS} significant "
        "digits" + ("" if got is None or got == stated else f" (found {got})"),
        got == stated,
    )


def predicted_positions(fit: SlideFit, e: Excitation, base: SessionConfig) -> np.ndarray:
    """The identified model alone (its mass, viscous and Coulomb friction) under the spring and
    ``e``: positions (m) of every sample, as the graph's run has them (``ValueError`` for a
    model that cannot be, e.g. a negative friction)."""
    model = SlideParams(fit.mass_kg, fit.viscous_n_s_per_m, fit.coulomb_n or 0.0)
    d = base.device
    plant = SlideDeviceParams.matching(
        model,
        max_force_n=d.max_force_n,
        encoder_resolution_m=d.encoder_resolution_m,
        initial_position_m=d.initial_position_m,
    )
    cfg = SessionConfig(
        loop=base.loop,
        model=model,
        device=plant,
        hand=HandParams(behaviour="none"),
        wall=VirtualWall(SPRING_N_PER_M, two_sided=True),
        excitation=e,
        law=ImpedanceLaw(ControlMode.OL),
    ).replace(loop__duration_s=DURATION_S)
    return run_session(cfg).q


def _decimate(x: np.ndarray, rate_hz: float) -> list[float]:
    step = max(1, round(rate_hz / TRACE_HZ))
    return [round(float(v) * 1e3, 4) for v in x[::step]]


def ch4_result(rows: list[RunAnalysis], base: SessionConfig) -> Ch4Result:
    """Identify from the first run's bag, predict every run with each model, check the fits."""
    records = {r.name: read_joint(r.bag) for r in rows}
    ident = records[run_name(IDENTIFY)]
    fits, failures = [], []
    for method in METHODS:
        try:
            fits.append(identify(ident, method))
        except IdentificationError as exc:
            failures.append(f"{method}: {exc}")
    rate = base.loop.rate_hz
    excitations = {run_name(e): e for e in (IDENTIFY, *VERIFY)}
    measured = {name: _decimate(rec.position, rate) for name, rec in records.items()}
    predictions = []
    tail = slice(-round(0.5 * rate), None)
    for fit in fits:
        try:
            for name, rec in records.items():
                x, xp = rec.position, predicted_positions(fit, excitations[name], base)
                n = min(len(xp), len(x))
                err = xp[:n] - x[:n]
                predictions.append(
                    Prediction(
                        name,
                        excitations[name].label(),
                        fit.method,
                        float(np.sqrt(np.mean(err * err))) * 1e3,
                        float(np.mean(xp[:n][tail]) - np.mean(x[:n][tail])) * 1e3,
                        _decimate(xp, rate),
                    )
                )
        except ValueError as exc:  # the fitted model is no model (a negative friction...)
            failures.append(f"{fit.method}: its model predicts nothing: {exc}")
    checks = [*ch4_checks(fits, base.device), model_check(fits, base.model)]
    checks += [Check(f, False) for f in failures]
    return Ch4Result(fits, predictions, measured, checks, failures)


def _off(got: float | None, want: float) -> float:
    """Relative error (absolute where ``want`` is 0)."""
    g = got if got is not None else math.nan
    return abs(g - want) / want if want else abs(g)


def ch4_checks(fits: list[SlideFit], truth: SlideDeviceParams) -> list[Check]:
    """Least squares within 5 % (m, c) and 25 % (Fc) of the plant's truth, the step method
    within 15 % (m, c) and 25 % (Fc); the thesis's formulas: m within 15 % (their c takes the
    Coulomb friction in: reported)."""
    out = []
    for fit in fits:
        m = _off(fit.mass_kg, truth.mass_kg)
        c = _off(fit.viscous_n_s_per_m, truth.viscous_n_s_per_m)
        if fit.method == "thesis_step":
            ok = m <= 0.15
            text = (
                f"the thesis's step formulas on the 2.4 N bag: m {100 * m:.1f} % of the plant's "
                f"truth (within 15 %); their c, {100 * c:.0f} % off, takes the Coulomb friction in"
            )
            out.append(Check(text, ok))
            continue
        fc = _off(fit.coulomb_n, truth.coulomb_n)
        within = 0.05 if fit.method == "least_squares" else 0.15
        ok = m <= within and c <= within and fc <= 0.25
        name = "least squares" if fit.method == "least_squares" else "step method"
        text = (
            f"{name} on the 2.4 N bag: m {100 * m:.1f} %, c {100 * c:.1f} % (within "
            f"{100 * within:.0f} %) and Fc {100 * fc:.1f} % (within 25 %) of the plant's truth"
        )
        out.append(Check(text, ok))
    return out
