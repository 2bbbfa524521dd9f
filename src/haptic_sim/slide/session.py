"""The batch runner: one simulated session in-process, with the node graph's exact cycle timing.

Per cycle k: the device reports sample k (``SimulatedSlide.sample``), the cycle of
``haptic_dob.core.cycle`` (wall force, estimate, command k, the stages the node graph runs) answers
it, and the device holds command k over [k, k+1) and steps to k+1.

Deterministic for a given seed; the node graph in lockstep reproduces it to the bit.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from haptic_dob.analysis.energy import passivity_observer
from haptic_dob.analysis.transparency import transparency
from haptic_dob.core.control import ImpedanceController, ImpedanceLaw
from haptic_dob.core.cycle import LoopCycle
from haptic_dob.core.environment import VirtualWall
from haptic_dob.core.excitation import Excitation
from haptic_dob.core.models.slide import SlideParams
from haptic_dob.core.observers.factory import ObserverSettings
from haptic_dob.core.validation import nonnegative, positive
from haptic_dob.runtime.params import build, load_node_params, node_view, param, replace_groups
from haptic_sim.hand import HandParams
from haptic_sim.sensor import ForceSensorParams
from haptic_sim.slide.device import SimulatedSlide
from haptic_sim.slide.plant import SlideDeviceParams


@dataclass(frozen=True)
class LoopSettings:
    """Rate, physics sub-steps, length and seed of a simulated session."""

    rate_hz: float = field(
        default=1000.0,
        metadata=param(description="control rate", unit="Hz", bounds=(1.0, 1e5), read_only=True),
    )
    substeps: int = field(
        default=10,
        metadata=param(
            description="physics steps per control period", bounds=(1, 1000), read_only=True
        ),
    )
    duration_s: float = field(
        default=40.0,
        metadata=param(
            description="session length; 0 = until stopped", unit="s", bounds=(0.0, 1e7)
        ),
    )
    seed: int = field(
        default=0,
        metadata=param(
            description="seed of the hand motion and sensor noise",
            bounds=(0, 2**31 - 1),
            read_only=True,
        ),
    )

    def __post_init__(self) -> None:
        positive("rate_hz", self.rate_hz)
        nonnegative("duration_s", self.duration_s)
        if self.substeps < 1:
            raise ValueError(f"substeps must be >= 1, got {self.substeps}")

    def batch_cycles(self, cycles: int | None = None) -> int:
        """The cycles a batch run takes: ``cycles``, or ``duration_s * rate_hz`` (at least 1)."""
        n = round(self.duration_s * self.rate_hz) if cycles is None else int(cycles)
        if n <= 0:
            raise ValueError(f"a batch session needs at least one cycle, got {n}")
        return n

    def device_args(self) -> tuple[float, int, int]:
        """(rate_hz, substeps, seed): the loop's part of a simulated device's arguments."""
        return self.rate_hz, self.substeps, self.seed


@dataclass(frozen=True)
class SessionConfig:
    """Everything a simulated slide session needs (each part is a parameter group of a node).

    ``device`` is the simulated slide, its true physics included (the device node's ``plant.*``);
    ``model`` is what the observer and the controller assume (their ``slide.*``: the identified
    model, never the plant's truth unless a config makes it so); the slide's axis is the model's.
    """

    loop: LoopSettings = field(default_factory=LoopSettings)
    model: SlideParams = field(default_factory=SlideParams)
    device: SlideDeviceParams = field(default_factory=SlideDeviceParams)
    sensor: ForceSensorParams = field(default_factory=ForceSensorParams)
    hand: HandParams = field(default_factory=HandParams)
    wall: VirtualWall = field(default_factory=VirtualWall)
    excitation: Excitation = field(default_factory=Excitation)
    law: ImpedanceLaw = field(default_factory=ImpedanceLaw)
    # the thesis clipped the slide's estimate to the actuator's 4 N
    observer: ObserverSettings = field(default_factory=lambda: ObserverSettings(output_limit=4.0))

    def replace(self, **groups: Any) -> SessionConfig:
        """A copy with whole groups replaced, or single fields as ``group__field=value``."""
        out: SessionConfig = replace_groups(self, **groups)
        return out

    @classmethod
    def from_node_params(cls, nodes: Mapping[str, Mapping[str, Any]]) -> SessionConfig:
        """Build from per-node parameter dicts (``device_node``, ``environment_node``, ...).

        Keys follow the nodes' parameter names (``plant.mass_kg``, ``slide.mass_kg``,
        ``hand.offset_m``, ``stiffness_n_per_m``, ``mode``, ``gain``...); ``/**`` applies to every
        node. The assumed model is the observer's (the controller's must be the same).
        """
        dev, env, obs, ctl = (
            node_view(nodes, n)
            for n in ("device_node", "environment_node", "observer_node", "controller_node")
        )
        model = build(SlideParams, obs, "slide.")
        if build(SlideParams, ctl, "slide.") != model:
            raise ValueError(
                "the observer and the controller assume different slide models (slide.*): "
                "a batch session runs one"
            )
        if build(SlideParams, dev, "slide.").axis != model.axis:
            raise ValueError(
                "the device's slide.axis differs from the one the observer assumes: a batch "
                "session runs one axis"
            )
        return cls(
            loop=build(LoopSettings, dev),
            model=model,
            device=build(SlideDeviceParams, dev, "plant."),
            sensor=build(ForceSensorParams, dev, "sensor."),
            hand=build(HandParams, dev, "hand."),
            wall=build(VirtualWall, env),
            excitation=build(Excitation, env, "excitation."),
            law=build(ImpedanceLaw, ctl),
            observer=build(ObserverSettings, obs),
        )

    @classmethod
    def from_yaml(cls, path: str | Path) -> SessionConfig:
        """Load a ``ros__parameters`` YAML file (the one the node graph is launched with)."""
        return cls.from_node_params(load_node_params(path))


@dataclass(frozen=True)
class SessionSummary:
    """A session's headline figures. Transparency figures are None when the record is too short
    or does not move (or the wall has no stiffness)."""

    controller: str
    kf: float
    stiffness_n_per_m: float
    observer_gain: float  # N s/m
    duration_s: float
    seed: int
    estimate_rms_error_n: float  # observer's estimate against the true hand force
    saturated_pct: float  # samples with the actuator at its limit
    in_contact_pct: float  # samples inside the wall
    max_active_energy_j: float  # the passivity observer's largest generated energy
    bandwidth_hz: float | None
    impedance_error_pct: float | None
    coherence_in_band: float | None
    band_below_first_bin: bool = False  # the band ends below the first bin (a floor, not a value)


@dataclass
class SessionResult:
    """Per-cycle arrays of a session (SI units), all of length N (one row per cycle k).

    Positions, velocities and forces are along the slide's axis (scalars); ``command`` is the
    effort command k, ``effort`` the effort the actuator applied over [k-1, k).
    """

    config: SessionConfig
    t: np.ndarray
    x_true: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    effort: np.ndarray
    command: np.ndarray
    wall_force: np.ndarray
    hand_force: np.ndarray
    force_measured: np.ndarray
    force_estimated: np.ndarray

    @property
    def dt(self) -> float:
        """Control period (s)."""
        return 1.0 / self.config.loop.rate_hz

    def summary(self, settle_s: float = 2.0) -> SessionSummary:
        """Headline figures, leaving out the first ``settle_s`` seconds (the hand's ramp-in; at
        most a quarter of the session)."""
        cfg = self.config
        fs = cfg.loop.rate_hz
        s = slice(min(round(settle_s * fs), self.t.size // 4), None)
        err = self.force_estimated[s] - self.hand_force[s]
        depth = self.q[s] - float(np.dot(cfg.wall.position, cfg.wall.normal))
        tr = None
        if cfg.wall.stiffness_n_per_m > 0.0:
            try:
                tr = transparency(
                    self.q[s],
                    self.force_measured[s],
                    fs,
                    cfg.wall.stiffness_n_per_m,
                    cfg.wall.damping_n_s_per_m,
                )
            except ValueError:  # too short for the spectral settings, or no motion
                tr = None
        return SessionSummary(
            controller=cfg.law.mode.value,
            kf=cfg.law.kf,
            stiffness_n_per_m=cfg.wall.stiffness_n_per_m,
            observer_gain=cfg.observer.gain,
            duration_s=self.t.size / fs,
            seed=cfg.loop.seed,
            estimate_rms_error_n=float(np.sqrt(np.mean(err * err))),
            saturated_pct=float(
                np.mean(np.abs(self.effort[s]) >= cfg.device.max_force_n * (1 - 1e-9)) * 100.0
            ),
            in_contact_pct=float(np.mean(depth > 0.0) * 100.0),
            max_active_energy_j=passivity_observer(
                self.force_measured[s], self.qd[s], self.dt
            ).max_active_j,
            bandwidth_hz=None if tr is None else tr.bandwidth_hz,
            impedance_error_pct=None if tr is None else tr.impedance_error_pct,
            coherence_in_band=None if tr is None else tr.mean_coherence_in_band,
            band_below_first_bin=False if tr is None else tr.band_below_first_bin,
        )

    def save(self, path: str | Path) -> None:
        """Write the arrays to an ``.npz`` file."""
        arrays = {
            f.name: getattr(self, f.name) for f in dataclasses.fields(self) if f.name != "config"
        }
        np.savez(path, **arrays)


def run_session(config: SessionConfig, cycles: int | None = None) -> SessionResult:
    """Run ``config`` in-process for ``cycles`` cycles (default: duration_s * rate_hz)."""
    loop = config.loop
    device = SimulatedSlide(
        config.device, config.sensor, config.hand, *loop.device_args(), axis=config.model.axis
    )
    n = loop.batch_cycles(cycles)
    model = config.model.model()
    observer = config.observer.build(model, device.dt)
    cycle = LoopCycle(
        config.wall,
        observer,
        ImpedanceController(model, config.law),
        device.period_ns,
        config.excitation,
    )
    axis = device.model.axis
    ax0, ax1, ax2 = (float(a) for a in axis)

    x_true, q, qd, effort, command = (np.empty(n) for _ in range(5))
    wall_force, hand_force, force_measured, force_estimated = (np.empty(n) for _ in range(4))
    for k in range(n):
        s = device.sample()
        x_true[k] = device.x
        f_wall, f_est, tau = cycle.step(
            s.stamp_ns, s.q, s.qd, s.effort, s.ee_position, s.ee_velocity, s.wrench_measured
        )
        device.apply(tau)
        fm, fh = s.wrench_measured, s.hand_force
        q[k], qd[k], effort[k], command[k] = s.q[0], s.qd[0], s.effort[0], tau[0]
        wall_force[k] = f_wall[0] * ax0 + f_wall[1] * ax1 + f_wall[2] * ax2
        hand_force[k] = fh[0] * ax0 + fh[1] * ax1 + fh[2] * ax2
        force_measured[k] = fm[0] * ax0 + fm[1] * ax1 + fm[2] * ax2
        force_estimated[k] = f_est[0] * ax0 + f_est[1] * ax1 + f_est[2] * ax2
    return SessionResult(
        config=config,
        t=np.arange(n) * device.dt,
        x_true=x_true,
        q=q,
        qd=qd,
        effort=effort,
        command=command,
        wall_force=wall_force,
        hand_force=hand_force,
        force_measured=force_measured,
        force_estimated=force_estimated,
    )
