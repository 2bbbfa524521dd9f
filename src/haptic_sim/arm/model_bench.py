"""A simulated arm whose model is identified, and what its observer makes of a model.

``ArmBench``: the arm's hidden truth (``haptic_sim.arm.truth``), device settings, and the joint
impedance (``haptic_dob.teleop.slave``, on the controller's CAD model) that moves it from rest at
its start; the observer (on the model under test) runs alongside and changes nothing.
- ``play``: the controller plays an excitation; the record, to the bit a lockstep graph's bag of
  it (samples 0 to ``seconds``, timed by stamp as the slave controller node does);
- ``free_motion``: the tool sweeping a 16 x 30 x 12 cm box for 4 s; the estimate's size (N)
  after the first 0.5 s;
- ``held_force``: a steady force on the held tool from 1 s on; the estimate's mean, last second;
- ``bias_at_rest``: held still in postures drawn within 0.6 rad of the start (inside the limits);
  the estimate's size after 1 s (N).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from haptic_dob.core.cycle import estimate
from haptic_dob.core.models import UrdfModel
from haptic_dob.core.observers.factory import ObserverSettings
from haptic_dob.identification.arm_excitation import FourierExcitation
from haptic_dob.identification.arm_model import Record
from haptic_dob.teleop.slave import SlaveController, SlaveImpedance
from haptic_sim.arm.device import ArmDeviceParams, SimulatedArm
from haptic_sim.teleop.slave_motion import sweep

Arr = NDArray[np.float64]
#: the estimate is judged after this many samples (the observer's start, the sweep's ramp)
SETTLE = 500


@dataclass(frozen=True)
class ArmBench:
    """The simulated arm (see the module); ``device.initial_position`` is its start."""

    truth: UrdfModel
    device: ArmDeviceParams
    substeps: int = 2
    rate_hz: float = 1000.0
    impedance: SlaveImpedance = field(default_factory=lambda: SlaveImpedance(bandwidth_hz=20.0))
    observer: ObserverSettings = field(default_factory=lambda: ObserverSettings(gain=1000.0))

    def arm(self, device: ArmDeviceParams | None = None) -> SimulatedArm:
        """A fresh simulated arm (with other device settings, if given)."""
        return SimulatedArm(
            self.truth, device or self.device, rate_hz=self.rate_hz, substeps=self.substeps
        )


Law = Callable[[SlaveController, Arr, Arr, float], list[float]]


def _run(
    bench: ArmBench,
    models: tuple[UrdfModel, UrdfModel | None],
    seconds: float,
    law: Law,
    trajectory: FourierExcitation | None = None,
    device: ArmDeviceParams | None = None,
) -> tuple[Record, Arr]:
    """The arm under ``law`` for ``seconds`` (``models``: the controller's, the observer's):
    its record and the observer's estimates (N, 3)."""
    control, observer = models
    arm = bench.arm(device)
    ctl = SlaveController(control, bench.impedance, arm.dt, trajectory)
    obs = None if observer is None else bench.observer.build(observer, arm.dt)
    n = round(seconds * bench.rate_hz) + 1  # samples 0 to ``seconds``, as a device node's session
    stamps, q_, u_, f_ = (
        np.zeros(n, np.int64),
        np.zeros((n, arm.dof)),
        np.zeros((n, arm.dof)),
        np.zeros((n, 3)),
    )
    for k in range(n):
        s = arm.sample()
        q, qd = np.asarray(s.q), np.asarray(s.qd)
        stamps[k], q_[k], u_[k] = s.stamp_ns, q, s.effort
        if obs is not None:
            f_[k] = estimate(obs, s.q, s.qd, s.effort)
        arm.apply(law(ctl, q, qd, s.stamp_ns * 1e-9))  # as the node times it: bit for bit
    return Record(stamps, q_, u_, tuple(bench.truth.joint_names)), f_


def play(
    bench: ArmBench, control: UrdfModel, excitation: FourierExcitation, seconds: float
) -> Record:
    """The record of the arm playing ``excitation`` for ``seconds``."""

    def law(ctl: SlaveController, q: Arr, qd: Arr, t: float) -> list[float]:
        return ctl.play(q, qd, t)

    return _run(bench, (control, None), seconds, law, excitation)[0]


def free_motion(
    bench: ArmBench, control: UrdfModel, observer: UrdfModel, seconds: float = 4.0
) -> Arr:
    """The estimate's size (N) at each sample after ``SETTLE`` while the tool sweeps a box."""
    start = np.asarray(bench.device.initial_position, dtype=np.float64)
    path = sweep(tuple(control.forward_kinematics(start)), (0.08, 0.15, 0.06), (5.3, 6.1, 4.7))

    def law(ctl: SlaveController, q: Arr, qd: Arr, t: float) -> list[float]:
        return ctl.command(q, qd, path(t))

    _, f = _run(bench, (control, observer), seconds, law)
    out: Arr = np.linalg.norm(f[SETTLE:], axis=1)
    return out


def _hold(ctl: SlaveController, q: Arr, qd: Arr, _t: float) -> list[float]:
    if ctl.q_d is None:
        ctl.start(q)
    return ctl.joint_command(q, qd, ctl.q_0)


def held_force(
    bench: ArmBench,
    control: UrdfModel,
    observer: UrdfModel,
    force_n: Sequence[float] = (0.0, 0.0, -5.0),
) -> Arr:
    """The estimate's mean (N, (3,)) over the last second of 3 s, a steady ``force_n`` pushing
    the held tool from 1 s on."""
    _, f = _run(
        bench,
        (control, observer),
        3.0,
        _hold,
        device=replace(
            bench.device,
            external_force_n=(float(force_n[0]), float(force_n[1]), float(force_n[2])),
            external_force_at_s=1.0,
        ),
    )
    out: Arr = np.mean(f[-round(bench.rate_hz) :], axis=0)
    return out


def rest_poses(bench: ArmBench, poses: int = 20, seed: int = 0) -> Arr:
    """``poses`` postures around the start (each joint within 0.6 rad, inside its limits)."""
    start = np.asarray(bench.device.initial_position, dtype=np.float64)
    limits = np.array(bench.truth.position_limits)
    rng = np.random.default_rng(seed)
    out: Arr = np.clip(
        start + rng.uniform(-0.6, 0.6, (poses, start.size)),
        limits[:, 0] + 0.05,
        limits[:, 1] - 0.05,
    )
    return out


def bias_at_rest(bench: ArmBench, control: UrdfModel, observer: UrdfModel, poses: Arr) -> Arr:
    """The estimate's size (N) after 1 s held still at each of ``poses``, nothing in contact."""
    out = []
    for pose in poses:
        _, f = _run(
            bench,
            (control, observer),
            1.0,
            _hold,
            device=replace(bench.device, initial_position=tuple(pose.tolist())),
        )
        out.append(float(np.linalg.norm(np.mean(f[-100:], axis=0))))
    return np.array(out)
