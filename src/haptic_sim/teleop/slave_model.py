"""The teleoperation slave's model, identified from its own joint states (batch).

The slave's device is its hidden truth (``/slave/device_node``'s URDF: masses, centres of mass,
friction and armature its CAD URDF lacks, ``haptic_sim.arm.truth``); its controller keeps the CAD
URDF (``/slave/slave_controller_node``'s). ``slave_bench`` is that arm alone, the table taken
away, moved by its controller; ``identify_slave`` plays the excitation file (``EXCITATION``,
beside the config) and identifies the model from the record as ``haptic-identify --inertial``
does from a bag; ``check_model`` says what an observer on a given URDF makes of free motion, a
held 5 N and rest (``haptic_sim.arm.model_bench``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from haptic_dob.core.models import UrdfModel
from haptic_dob.core.models._pinocchio_urdf import read_urdf
from haptic_dob.identification.arm_excitation import FourierExcitation
from haptic_dob.identification.arm_model import Record, identify_arm_model
from haptic_dob.identification.arm_model_report import ArmModelFit
from haptic_dob.runtime.params import build
from haptic_sim.arm.device import ArmDeviceParams
from haptic_sim.arm.model_bench import (
    ArmBench,
    bias_at_rest,
    free_motion,
    held_force,
    play,
    rest_poses,
)
from haptic_sim.teleop.config import TeleopConfig

Arr = NDArray[np.float64]
#: the slave's excitation (``haptic-excite``), beside ``config/urdf``
EXCITATION = "excitation/arm7_slave.yaml"
#: the low-pass (Hz) through which the slave's Coulomb turns are searched: its encoders resolve
#: 1 urad a sample, speeds far below the 1 mrad/s its heaviest joint's friction turns over
SLAVE_TURN_CUTOFF_HZ = 50.0
#: the steady force the held tool is pushed with (N, base frame: down)
HELD_FORCE_N = (0.0, 0.0, -5.0)
#: postures the bias at rest is measured in
REST_POSES = 20


def slave_bench(config: TeleopConfig) -> ArmBench:
    """The slave arm alone (its truth, device settings, impedance and observer settings)."""
    values = config.values("slave", "device_node")
    truth = config.model("slave", "device_node")
    if not isinstance(truth, UrdfModel):
        raise ValueError("the slave's model is identified on a URDF arm")
    return ArmBench(
        truth=truth,
        device=build(ArmDeviceParams, values, "arm."),
        substeps=config.slave_loop.substeps,
        rate_hz=config.slave_loop.rate_hz,
        impedance=config.slave,
        observer=config.slave_observer,
    )


def cad_urdf(config: TeleopConfig) -> str:
    """The slave's CAD URDF (its controller's) as XML text."""
    values = config.values("slave", "slave_controller_node")
    return read_urdf(values.get("robot_description") or values["urdf_path"])


def control_model(config: TeleopConfig) -> UrdfModel:
    """The slave controller's model (CAD)."""
    model = config.model("slave", "slave_controller_node")
    if not isinstance(model, UrdfModel):
        raise ValueError("the slave's model is identified on a URDF arm")
    return model


def excitation_path(config_dir: Path) -> Path:
    """The slave's excitation file in a config directory."""
    return config_dir / EXCITATION


def play_excitation(config: TeleopConfig, excitation: FourierExcitation, seconds: float) -> Record:
    """The slave playing ``excitation`` for ``seconds``: the record a bag of it holds."""
    return play(slave_bench(config), control_model(config), excitation, seconds)


def identify_slave(config: TeleopConfig, record: Record, holdout: float = 0.3) -> ArmModelFit:
    """The slave's model from ``record`` (``haptic-identify --inertial --turn-cutoff-hz 50``)."""
    tip = control_model(config).tip_frame
    return identify_arm_model(
        cad_urdf(config), tip, record, holdout=holdout, turn_cutoff_hz=SLAVE_TURN_CUTOFF_HZ
    )


@dataclass(frozen=True)
class ModelCheck:
    """What an observer on one model makes of the slave: free motion (the estimate's peak and
    RMS, N), a held 5 N (the estimate's error, % of 5 N) and rest (the estimate's size in each
    posture, N)."""

    free_max_n: float
    free_rms_n: float
    held_error_pct: float
    rest_n: tuple[float, ...]

    @property
    def rest_mean_n(self) -> float:
        """The bias at rest, mean over the postures (N)."""
        return float(np.mean(self.rest_n))

    @property
    def rest_max_n(self) -> float:
        """The bias at rest, largest over the postures (N)."""
        return float(np.max(self.rest_n))


def check_model(config: TeleopConfig, observer_urdf: str) -> ModelCheck:
    """An observer on ``observer_urdf`` (XML or a path) on the slave (see the module)."""
    bench, control = slave_bench(config), control_model(config)
    observer = UrdfModel(observer_urdf, control.tip_frame, list(control.joint_names))
    free = free_motion(bench, control, observer)
    held = held_force(bench, control, observer, HELD_FORCE_N)
    error = float(np.linalg.norm(held - np.array(HELD_FORCE_N)) / np.linalg.norm(HELD_FORCE_N))
    rest = bias_at_rest(bench, control, observer, rest_poses(bench, REST_POSES))
    return ModelCheck(
        free_max_n=float(np.max(free)),
        free_rms_n=float(np.sqrt(np.mean(free * free))),
        held_error_pct=100.0 * error,
        rest_n=tuple(float(v) for v in rest),
    )
