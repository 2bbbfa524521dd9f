"""The slave arm alone, its joint impedance tracking a given path: free motion across the
workspace (how large the estimate is with nothing in contact). Its model is identified from the
excitation ``haptic_sim.teleop.slave_model`` plays.

The slave device, its observer and its controller are the teleoperation config's; no master and
no channel: the point to track comes from ``path`` (m, at the sample's time in s).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from haptic_dob.core.cycle import estimate
from haptic_dob.teleop.slave import SlaveController
from haptic_sim.teleop.config import TeleopConfig

Path = Callable[[float], tuple[float, float, float]]


@dataclass
class SlaveRun:
    """Per-cycle arrays of a slave-only run: joints (N, dof), points and forces (N, 3)."""

    t: np.ndarray
    stamps_ns: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    effort: np.ndarray
    target: np.ndarray
    point: np.ndarray
    contact: np.ndarray
    estimate: np.ndarray


#: (controller, q, q', t) -> (the efforts, the point tracked)
Step = Callable[[SlaveController, np.ndarray, np.ndarray, float], tuple[list[float], Any]]


def _run(config: TeleopConfig, duration_s: float, step: Step) -> SlaveRun:
    """The slave under ``step`` for ``duration_s`` (its observer running alongside)."""
    slave = config.slave_device()
    dt = slave.dt
    n = max(1, round(duration_s / dt))
    obs = config.slave_observer.build(config.model("slave", "observer_node"), dt)
    ctl = SlaveController(config.model("slave", "slave_controller_node"), config.slave, dt)
    dof = slave.dof
    joints = {k: np.empty((n, dof)) for k in ("q", "qd", "effort")}
    cart = {k: np.empty((n, 3)) for k in ("target", "point", "contact", "estimate")}
    for k in range(n):
        s = slave.sample()
        f = estimate(obs, s.q, s.qd, s.effort)
        tau, target = step(ctl, np.asarray(s.q), np.asarray(s.qd), k * dt)
        joints["q"][k], joints["qd"][k], joints["effort"][k] = s.q, s.qd, s.effort
        cart["target"][k] = target
        cart["point"][k] = slave.model._forward_kinematics(slave.q)
        cart["contact"][k] = slave.contact_force_true
        cart["estimate"][k] = f
        slave.apply(tau)
    stamps = np.arange(n, dtype=np.int64) * slave.period_ns
    return SlaveRun(stamps * 1e-9, stamps, **joints, **cart)


def run_slave_path(config: TeleopConfig, path: Path, duration_s: float) -> SlaveRun:
    """The slave's joint impedance tracking the point ``path(t)`` (m) for ``duration_s``."""

    def step(
        ctl: SlaveController, q: np.ndarray, qd: np.ndarray, t: float
    ) -> tuple[list[float], Any]:
        target = path(t)
        return ctl.command(q, qd, target), target

    return _run(config, duration_s, step)


def sweep(
    start: tuple[float, float, float],
    reach_m: tuple[float, float, float],
    periods_s: tuple[float, float, float],
    ramp_s: float = 0.5,
) -> Path:
    """``start + ramp(t) * reach_i sin(2 pi t / period_i)`` per axis: the tool moves across the
    workspace (a Lissajous figure of the three periods), starting smoothly from rest."""

    def at(t: float) -> tuple[float, float, float]:
        r = 1.0 if t >= ramp_s else 0.5 - 0.5 * math.cos(math.pi * t / ramp_s)
        return (
            start[0] + r * reach_m[0] * math.sin(2.0 * math.pi * t / periods_s[0]),
            start[1] + r * reach_m[1] * math.sin(2.0 * math.pi * t / periods_s[1]),
            start[2] + r * reach_m[2] * math.sin(2.0 * math.pi * t / periods_s[2]),
        )

    return at
