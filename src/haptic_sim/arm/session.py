"""The multi-DOF batch runner: one simulated arm session in-process, node-graph cycle timing.

Per cycle k, as ``session.py`` does for the slide: the device reports sample k
(``SimulatedArm.sample``), the cycle of ``haptic_dob.core.cycle`` (wall force, estimate, command k)
answers it, and the device holds command k over [k, k+1) and steps to k+1.

``exact_force=True`` replaces the observer's wrench at the controller's DOB input by the exact
one (thesis section 5.2.2's comparison): the disturbance the observer would see without lag,
``d = J^T F_tip + h_obs(q, q') - h_plant(q, q')`` at the sample's true state (``h`` = Coriolis,
gravity and friction of the observer's and of the true model; the inertias are assumed equal),
mapped to the tip with the observer's own damped least squares. With an observer model that
leaves gravity out this is the true tip force plus gravity's equivalent tip force.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from haptic_dob.core.control import ImpedanceController, ImpedanceLaw
from haptic_dob.core.cycle import LoopCycle
from haptic_dob.core.environment import VirtualWall
from haptic_dob.core.models.base import DeviceModel
from haptic_dob.core.models.factory import build_model
from haptic_dob.core.models.phantom import PhantomModel
from haptic_dob.core.observers.factory import ObserverSettings
from haptic_dob.core.tip_force import dls_transpose_solve
from haptic_dob.runtime.configs import urdf_beside
from haptic_dob.runtime.params import build, load_node_params, node_view, replace_groups
from haptic_sim.arm.device import ArmDeviceParams, SimulatedArm
from haptic_sim.hand import HandParams
from haptic_sim.sensor import ForceSensorParams
from haptic_sim.slide.session import LoopSettings


@dataclass(frozen=True)
class ArmSessionConfig:
    """Everything a simulated arm session needs.

    ``plant`` is the true physics; ``observer_model`` the observer's (and controller's) model,
    default the plant itself (a perfect model). ``wall`` with zero stiffness renders nothing.
    """

    loop: LoopSettings = field(default_factory=lambda: LoopSettings(duration_s=2.0))
    plant: DeviceModel = field(default_factory=PhantomModel)
    device: ArmDeviceParams = field(default_factory=ArmDeviceParams)
    sensor: ForceSensorParams = field(default_factory=ForceSensorParams)
    hand: HandParams = field(default_factory=lambda: HandParams(behaviour="none"))
    wall: VirtualWall = field(default_factory=lambda: VirtualWall(stiffness_n_per_m=0.0))
    law: ImpedanceLaw = field(default_factory=lambda: ImpedanceLaw(max_force_n=8.5))
    observer: ObserverSettings = field(
        default_factory=lambda: ObserverSettings(gain=2.0, output_limit=0.0)
    )
    observer_model: DeviceModel | None = None
    exact_force: bool = False
    hold_s: float = 0.0

    def replace(self, **groups: Any) -> ArmSessionConfig:
        """A copy with whole groups replaced, or single fields as ``group__field=value``."""
        out: ArmSessionConfig = replace_groups(self, **groups)
        return out

    @classmethod
    def from_node_params(cls, nodes: Mapping[str, Mapping[str, Any]]) -> ArmSessionConfig:
        """Build from per-node parameter dicts (``device_node``, ``observer_node``...; ``/**``)."""
        dev, env, obs, ctl = (
            node_view(nodes, n)
            for n in ("device_node", "environment_node", "observer_node", "controller_node")
        )
        if dev.get("model", "slide") == "slide":
            raise ValueError("an arm session needs model phantom or urdf, got slide")
        return cls(
            loop=build(LoopSettings, dev),
            plant=build_model(dev),
            device=build(ArmDeviceParams, dev, "arm."),
            sensor=build(ForceSensorParams, dev, "sensor."),
            hand=build(HandParams, dev, "hand."),
            wall=build(VirtualWall, env),
            law=build(ImpedanceLaw, ctl),
            observer=build(ObserverSettings, obs),
            observer_model=build_model(obs),
        )

    @classmethod
    def from_yaml(cls, path: str | Path) -> ArmSessionConfig:
        """Load a ``ros__parameters`` YAML file (the one the node graph is launched with; a
        relative ``urdf_path`` beside it, as the launcher takes it)."""
        nodes = load_node_params(path)
        urdf_beside(nodes, path)
        return cls.from_node_params(nodes)


@dataclass(frozen=True)
class ArmSessionSummary:
    """An arm session's headline figures."""

    model: str  # the plant's model class
    controller: str
    kf: float
    stiffness_n_per_m: float
    observer_gain: float  # N m s/rad
    duration_s: float
    seed: int
    estimate_rms_error_n: float  # RMS of the 3-D tip-force estimate's error
    max_penetration_m: float
    in_contact_pct: float


@dataclass
class ArmSessionResult:
    """Per-cycle arrays of an arm session (SI units), one row per cycle k.

    Joint arrays are (N, dof), Cartesian ones (N, 3): ``q_true``/``ee_true`` the true state at
    sample k, ``q``/``qd``/``ee`` what the device reported, ``effort`` the effort applied over
    [k-1, k), ``command`` command k, ``tip_force`` the true external force on the end effector
    (hand + external), ``d_hat`` the observer's joint estimate and ``d_exact`` the exact
    disturbance of the observer's model, ``force_estimated`` the observer's wrench and
    ``force_used`` what the controller's DOB input got.
    """

    config: ArmSessionConfig
    t: np.ndarray
    q_true: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    effort: np.ndarray
    command: np.ndarray
    ee_true: np.ndarray
    ee: np.ndarray
    wall_force: np.ndarray
    tip_force: np.ndarray
    force_measured: np.ndarray
    force_estimated: np.ndarray
    force_used: np.ndarray
    d_hat: np.ndarray
    d_exact: np.ndarray

    def summary(self, settle_s: float = 0.0) -> ArmSessionSummary:
        """Headline figures after ``settle_s`` seconds (at most a quarter of the session)."""
        cfg = self.config
        s = slice(min(round(settle_s * cfg.loop.rate_hz), self.t.size // 4), None)
        err = np.linalg.norm(self.force_estimated[s] - self.tip_force[s], axis=1)
        depth = (self.ee_true[s] - np.asarray(cfg.wall.position)) @ np.asarray(cfg.wall.normal)
        return ArmSessionSummary(
            model=type(cfg.plant).__name__,
            controller=cfg.law.mode.value,
            kf=cfg.law.kf,
            stiffness_n_per_m=cfg.wall.stiffness_n_per_m,
            observer_gain=cfg.observer.gain,
            duration_s=self.t.size / cfg.loop.rate_hz,
            seed=cfg.loop.seed,
            estimate_rms_error_n=float(np.sqrt(np.mean(err * err))),
            max_penetration_m=float(max(depth.max(), 0.0)),
            in_contact_pct=float(np.mean(depth > 0.0) * 100.0),
        )

    def save(self, path: str | Path) -> None:
        """Write the arrays to an ``.npz`` file."""
        arrays = {
            f.name: getattr(self, f.name) for f in dataclasses.fields(self) if f.name != "config"
        }
        np.savez(path, **arrays)


def exact_disturbance(device: SimulatedArm, observer_model: DeviceModel) -> np.ndarray:
    """The joint disturbance the observer's model sees at the device's true state (see top)."""
    q, v = device.q, device.v
    plant = device.model
    d = observer_model._bias_effort(q, v) - plant._bias_effort(q, v)
    if np.any(device.tip_force_true != 0.0):
        d = d + plant._jacobian(q).T @ device.tip_force_true
    return d


def run_arm_session(config: ArmSessionConfig, cycles: int | None = None) -> ArmSessionResult:
    """Run ``config`` in-process for ``cycles`` cycles (default: duration_s * rate_hz)."""
    loop = config.loop
    device = SimulatedArm(
        config.plant, config.device, config.sensor, config.hand, *loop.device_args()
    )
    n = loop.batch_cycles(cycles)
    obs_model = config.observer_model or config.plant
    if obs_model.dof != device.dof:
        raise ValueError(f"observer model has {obs_model.dof} joints, the plant {device.dof}")
    observer = config.observer.build(obs_model, device.dt)
    cycle = LoopCycle(
        config.wall, observer, ImpedanceController(obs_model, config.law), device.period_ns
    )
    dof = device.dof
    # warm-up: the device held at rest (its actuators balance the true gravity) while the
    # observer converges; the record starts at the release
    for _ in range(round(config.hold_s * loop.rate_hz)):
        s = device.sample()
        observer.update(s.q, s.qd, s.effort)
        device.apply(config.plant._gravity(device.q).tolist())
    joint = {k: np.empty((n, dof)) for k in ("q_true", "q", "qd", "effort", "command")}
    joint |= {k: np.empty((n, dof)) for k in ("d_hat", "d_exact")}
    cart = {
        k: np.empty((n, 3))
        for k in (
            "ee_true",
            "ee",
            "wall_force",
            "tip_force",
            "force_measured",
            "force_estimated",
            "force_used",
        )
    }
    for k in range(n):
        s = device.sample()
        joint["q_true"][k] = device.q
        cart["ee_true"][k] = obs_model._forward_kinematics(device.q)
        d_exact = exact_disturbance(device, obs_model)
        f_used: tuple[float, float, float] | None = None
        if config.exact_force:
            fx = dls_transpose_solve(
                obs_model._jacobian(device.q),
                d_exact,
                observer.dls_threshold_m,
                observer.dls_damping_m,
            )
            f_used = (float(fx[0]), float(fx[1]), float(fx[2]))
        f_wall, f_est, tau = cycle.step(
            s.stamp_ns,
            s.q,
            s.qd,
            s.effort,
            s.ee_position,
            s.ee_velocity,
            s.wrench_measured,
            estimate_override=f_used,
        )
        d_hat = observer.estimate
        device.apply(tau)
        joint["q"][k] = s.q
        joint["qd"][k] = s.qd
        joint["effort"][k] = s.effort
        joint["command"][k] = tau
        joint["d_hat"][k] = d_hat
        joint["d_exact"][k] = d_exact
        cart["ee"][k] = s.ee_position
        cart["wall_force"][k] = f_wall
        cart["tip_force"][k] = s.hand_force
        cart["force_measured"][k] = s.wrench_measured
        cart["force_estimated"][k] = f_est
        cart["force_used"][k] = f_used or f_est
    t = np.arange(n) * device.dt
    return ArmSessionResult(config=config, t=t, **joint, **cart)
