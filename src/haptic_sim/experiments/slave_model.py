"""The teleoperation slave's model identified through the node graph (the reproduction's part).

One lockstep run of the teleoperation config's slave alone: its device (the hidden truth,
``config/urdf/arm7_truth.urdf``), its controller playing the excitation
(``slave.trajectory_path``: ``config/excitation/arm7_slave.yaml``), the table taken away, and a
recorder. ``haptic-identify --inertial``'s core reads the bag's joint states with the CAD URDF
and writes the identified URDF beside the bag; then an observer on each model (CAD, this
identification, the configuration's ``arm7_identified.urdf``) meets the slave in batch
(``haptic_sim.teleop.slave_model.check_model``): free motion, a held 5 N, rest in 20 postures.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from haptic_dob.bag.joints import read_joints
from haptic_dob.identification.arm_model import Record
from haptic_dob.identification.filters import IdentificationError
from haptic_dob.runtime.configs import config_dir
from haptic_sim.experiments.figures import pyplot, save_figure
from haptic_sim.experiments.graph_runs import GraphRun
from haptic_sim.experiments.records import Cell, Check, RunAnalysis
from haptic_sim.slide.session import SessionConfig
from haptic_sim.teleop.config import TeleopConfig
from haptic_sim.teleop.slave_model import (
    ModelCheck,
    cad_urdf,
    check_model,
    control_model,
    excitation_path,
    identify_slave,
    slave_bench,
)

#: the excitation's length (s) and the quick run's
SECONDS = 60.0
QUICK_SECONDS = 20.0
RUN = "slave_excitation"
#: the acceptance bounds (issue 32)
RESIDUAL_PCT = 3.0
FREE_N = 0.2
HELD_PCT = 3.0


def teleop_config() -> TeleopConfig:
    """The installed teleoperation config (``teleop_sim.yaml``)."""
    return TeleopConfig.from_yaml(config_dir() / "teleop_sim.yaml")


def slave_runs(_base_config: Path, seed: int = 0, quick: bool = False) -> list[GraphRun]:
    """The one run: the slave playing its excitation, recorded."""
    cfg = teleop_config()
    device = cfg.values("slave", "device_node")
    device.update(
        clock_mode="lockstep",
        duration_s=QUICK_SECONDS if quick else SECONDS,
        wait_for=["slave_controller_node"],
        command_source="slave_controller_node",  # the slave's law commands it, as in teleop
        start_with=[],
        **{"contact.stiffness_n_per_m": 0.0},
    )
    controller = cfg.values("slave", "slave_controller_node")
    controller["slave.trajectory_path"] = str(excitation_path(config_dir()))
    params: dict[str, dict[str, Any]] = {
        "device_node": device,
        "slave_controller_node": controller,
        "recorder_node": {"topics": ["joint_states", "/parameter_events"]},
    }
    cell = Cell("slave", "impedance", 0.0, 0.0)
    return [GraphRun(RUN, params, cell, "the teleoperation slave playing its excitation")]


@dataclass(frozen=True)
class ModelRow:
    """What an observer on one model made of the slave (``ModelCheck``, JSON-ready)."""

    model: str
    free_max_n: float
    free_rms_n: float
    held_error_pct: float
    rest_n: list[float]

    @classmethod
    def of(cls, model: str, check: ModelCheck) -> ModelRow:
        """From a check."""
        return cls(
            model, check.free_max_n, check.free_rms_n, check.held_error_pct, list(check.rest_n)
        )


@dataclass(frozen=True)
class SlaveModelResult:
    """The identification (per joint: residuals, friction, armature beside the truth; per link:
    mass beside CAD and the truth), the models' checks, and the acceptance checks."""

    seconds: float
    samples: int
    condition_number: float
    urdf: str  # where the identified URDF was written
    joints: list[str]
    residual_pct: list[float]
    residual_cad_pct: list[float]
    armature: list[float]
    viscous: list[float]
    coulomb: list[float]
    truth_armature: list[float]
    truth_viscous: list[float]
    truth_coulomb: list[float]
    links: list[str]
    mass: list[float]
    cad_mass: list[float]
    unidentifiable: list[str]
    models: list[ModelRow]
    checks: list[Check]
    failures: list[str]


def slave_result(rows: list[RunAnalysis], _base: SessionConfig) -> SlaveModelResult:
    """Identify from the run's bag, check each model, judge against the issue's bounds."""
    cfg = teleop_config()
    bag = Path(rows[0].bag)
    control = control_model(cfg)
    js = read_joints(bag, "joint_states", control.joint_names)
    record = Record(js.stamps_ns, js.position, js.effort, js.names)
    seconds = len(js.stamps_ns) / cfg.slave_loop.rate_hz
    try:
        fit = identify_slave(cfg, record)
    except IdentificationError as exc:
        return _failed(seconds, str(exc))
    out = bag.parent / "identified.urdf"
    out.write_text(fit.urdf(cad_urdf(cfg), f"identified from {bag.name} (reproduction)"))
    configured = cfg.values("slave", "observer_node")["urdf_path"]
    models = [
        ModelRow.of("CAD (arm7.urdf)", check_model(cfg, cad_urdf(cfg))),
        ModelRow.of("identified from this bag", check_model(cfg, str(out))),
        ModelRow.of("the configuration's (arm7_identified.urdf)", check_model(cfg, configured)),
    ]
    truth = slave_bench(cfg).truth
    ident = models[1]
    checks = [
        Check(
            f"held-out torque residual {fit.residual_pct:.2f} % of the worst joint's span "
            f"< {RESIDUAL_PCT:g} % (CAD {fit.residual_cad_pct:.1f} %)",
            fit.residual_pct < RESIDUAL_PCT,
        ),
        Check(
            f"free motion: the estimate peaks at {ident.free_max_n:.3f} N < {FREE_N:g} N "
            f"(CAD {models[0].free_max_n:.2f} N)",
            ident.free_max_n < FREE_N,
        ),
        Check(
            f"a held 5 N estimated within {ident.held_error_pct:.2f} % < {HELD_PCT:g} % "
            f"(CAD {models[0].held_error_pct:.1f} %)",
            ident.held_error_pct < HELD_PCT,
        ),
        Check(
            "every link physically consistent (positive mass, centre of mass in its box, "
            "pseudo-inertia positive definite: the identification refuses otherwise)",
            all(lf.pseudo_inertia_min > 0.0 and lf.mass > 0.0 for lf in fit.links),
        ),
        Check(
            f"the configuration's model does as well: peak {models[2].free_max_n:.3f} N, "
            f"held {models[2].held_error_pct:.2f} %",
            models[2].free_max_n < FREE_N and models[2].held_error_pct < HELD_PCT,
        ),
    ]
    return SlaveModelResult(
        seconds=seconds,
        samples=fit.samples,
        condition_number=fit.condition_number,
        urdf=str(out),
        joints=[j.joint for j in fit.joints],
        residual_pct=[100 * j.heldout_rms / j.torque_span for j in fit.joints],
        residual_cad_pct=[100 * j.heldout_rms_cad / j.torque_span for j in fit.joints],
        armature=[j.armature for j in fit.joints],
        viscous=[j.viscous for j in fit.joints],
        coulomb=[j.coulomb for j in fit.joints],
        truth_armature=[float(v) for v in truth.armature],
        truth_viscous=[float(v) for v in truth.viscous],
        truth_coulomb=[float(v) for v in truth.coulomb],
        links=[lf.link for lf in fit.links],
        mass=[lf.mass for lf in fit.links],
        cad_mass=[lf.cad_mass for lf in fit.links],
        unidentifiable=list(fit.unidentifiable),
        models=models,
        checks=checks,
        failures=[],
    )


def _failed(seconds: float, why: str) -> SlaveModelResult:
    check = Check(f"the identification failed: {why}", False)
    return SlaveModelResult(
        seconds,
        0,
        float("nan"),
        "",
        [],
        [],
        [],
        [],
        [],
        [],
        [],
        [],
        [],
        [],
        [],
        [],
        [],
        [],
        [check],
        [why],
    )


def slave_tables(r: SlaveModelResult) -> str:
    """The models' checks, then per joint the residuals, friction and armature."""
    lines = [
        f"**The observer on each model** ({len(r.models[0].rest_n) if r.models else 0} postures at "
        "rest; free motion: the tool sweeping a 16 x 30 x 12 cm box for 4 s; a steady 5 N pushing "
        "the held tool down):",
        "",
        "| model | free motion: peak / RMS (N) | held 5 N: error | at rest: mean / largest (N) |",
        "|---|---|---|---|",
    ]
    for m in r.models:
        lines.append(
            f"| {m.model} | {m.free_max_n:.3f} / {m.free_rms_n:.3f} | {m.held_error_pct:.2f} % | "
            f"{np.mean(m.rest_n):.3f} / {np.max(m.rest_n):.3f} |"
        )
    lines += [
        "",
        f"**The identification** ({r.seconds:.0f} s, {r.samples} samples fitted, condition number "
        f"{r.condition_number:.3g}; held-out residual, % of each joint's torque span):",
        "",
        "| joint | residual: CAD -> identified | identified / truth: armature (kg m^2) | viscous "
        "(N m s/rad) | Coulomb (N m) |",
        "|---|---|---|---|---|",
    ]
    for i, j in enumerate(r.joints):
        lines.append(
            f"| {j} | {r.residual_cad_pct[i]:.2f} % -> {r.residual_pct[i]:.2f} % | "
            f"{r.armature[i]:.4f} / {r.truth_armature[i]:.4f} | {r.viscous[i]:.3f} / "
            f"{r.truth_viscous[i]:.3f} | {r.coulomb[i]:.3f} / {r.truth_coulomb[i]:.3f} |"
        )
    lines += [
        "",
        "Masses (kg), CAD -> identified: "
        + ", ".join(
            f"{n} {c:.2f} -> {m:.2f}" for n, c, m in zip(r.links, r.cad_mass, r.mass, strict=True)
        )
        + ". A link's own mass is seen only in combinations (a mass with the links beyond it, a "
        "joint's armature with the inertia about its axis): the parameters outside the base set "
        f"are held toward CAD ({', '.join(r.unidentifiable)}).",
        "",
    ]
    return "\n".join(lines)


def slave_console(r: SlaveModelResult) -> list[str]:
    """The part's terminal lines."""
    if not r.models:
        return [f"slave model: {r.failures[0]}"]
    cad, ident = r.models[0], r.models[1]
    return [
        f"slave model: residual {max(r.residual_cad_pct):.1f} % -> {max(r.residual_pct):.2f} %, "
        f"free motion {cad.free_max_n:.2f} -> {ident.free_max_n:.3f} N, held 5 N "
        f"{cad.held_error_pct:.1f} -> {ident.held_error_pct:.2f} %, at rest "
        f"{np.mean(cad.rest_n):.2f} -> {np.mean(ident.rest_n):.3f} N"
    ]


def plot_rest(r: SlaveModelResult, path: Path, _base: SessionConfig) -> None:
    """The estimate at rest in each posture, per model."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8, 3.5))
    width = 0.8 / max(1, len(r.models))
    n = len(r.models[0].rest_n) if r.models else 0
    for i, m in enumerate(r.models):
        ax.bar(np.arange(n) + i * width, m.rest_n, width, label=m.model)
    ax.set_xticks(np.arange(n) + 0.4 - width / 2, [str(k + 1) for k in range(n)])
    ax.set_yscale("log")
    ax.set_xlabel("posture (held still, nothing in contact)")
    ax.set_ylabel("estimate's size (N)")
    ax.legend(fontsize=8, loc="lower center", bbox_to_anchor=(0.5, 1.0), ncol=3, frameon=False)
    save_figure(fig, path)
