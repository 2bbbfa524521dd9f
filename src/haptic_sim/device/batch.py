"""Any simulated device's session in batch, from the node graph's own parameters.

``run_batch(nodes)`` takes the per-node parameter values a session YAML gives the graph
(``device_node``, ``environment_node``, ``observer_node``, ``controller_node``, ``/**``;
``load_session`` reads them from a file as the launcher does) and runs their cycle in-process:
the device the device node would simulate (``build_device``), the wall and excitation of the
environment node, the observer on the observer's model, the law on the controller's model, each
cycle the stages of ``haptic_dob.core.cycle``. A lockstep graph launched with the same parameters
records the same samples, to the bit; a record's joint states are what ``haptic-identify`` reads
from that bag."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from haptic_dob.core.control import ImpedanceController, ImpedanceLaw
from haptic_dob.core.cycle import LoopCycle
from haptic_dob.core.environment import VirtualWall
from haptic_dob.core.excitation import Excitation
from haptic_dob.core.models.factory import build_model
from haptic_dob.core.observers.factory import ObserverSettings
from haptic_dob.runtime.configs import urdf_beside
from haptic_dob.runtime.params import build, load_node_params, node_view
from haptic_sim.device.factory import build_device
from haptic_sim.slide.session import LoopSettings

Arr = NDArray[np.float64]
NODES = ("device_node", "environment_node", "observer_node", "controller_node")
SETTLE_S = 2.0  # s: the hand's ramp-in, left out of the figures in contact


@dataclass(frozen=True)
class BatchRecord:
    """One row per cycle k (SI units): what the device reported, what the loop computed, the
    truth. Joint arrays are (N, dof) in ``joint_names`` order, Cartesian ones (N, 3)."""

    joint_names: tuple[str, ...]
    stamps_ns: NDArray[np.int64]
    q: Arr
    qd: Arr
    effort: Arr  # applied over [k-1, k) after saturation
    command: Arr  # command k, held over [k, k+1)
    ee: Arr  # the end-effector point the device reported
    wall_force: Arr  # the environment's force (wall, excitation, holding spring)
    hand_force: Arr  # the true external force on the end effector (the hand's)
    force_measured: Arr  # the handle's force sensor
    force_estimated: Arr  # the observer's wrench

    @property
    def t(self) -> Arr:
        """Sample times (s)."""
        t: Arr = self.stamps_ns.astype(np.float64) * 1e-9
        return t

    def in_contact(self, wall: VirtualWall, settle_s: float = SETTLE_S) -> ContactFigures:
        """The estimate against the true hand force while the end effector is inside ``wall``,
        from ``settle_s`` (s) on."""
        start = int(np.searchsorted(self.t, settle_s))
        depth = (self.ee[start:] - np.asarray(wall.position)) @ np.asarray(wall.normal)
        inside = depth > 0.0
        if not inside.any():
            return ContactFigures(0.0, math.nan, math.nan)
        est, hand = self.force_estimated[start:][inside], self.hand_force[start:][inside]
        err = np.linalg.norm(est - hand, axis=1)
        span = float(np.ptp(hand @ np.asarray(wall.normal)))
        return ContactFigures(float(np.mean(inside)), float(np.sqrt(np.mean(err * err))), span)

    def save(self, path: str | Path) -> None:
        """Write the arrays to an ``.npz`` file."""
        arrays: dict[str, Any] = {
            k: v for k, v in self.__dict__.items() if isinstance(v, np.ndarray)
        }
        np.savez(path, **arrays)


@dataclass(frozen=True)
class ContactFigures:
    """The estimate in contact: the share of samples in contact (after the settling time), the
    RMS of the 3-D error against the true hand force there (N) and the span of that force along
    the normal (N)."""

    share: float
    rms_error_n: float
    span_n: float

    @property
    def error_of_span(self) -> float:
        """The RMS error over the span (issue 31's figure: at most 0.05)."""
        return self.rms_error_n / self.span_n


def load_session(path: str | Path) -> dict[str, dict[str, Any]]:
    """A session YAML's per-node parameters as the launcher gives them to the nodes (a relative
    ``urdf_path`` beside the file)."""
    nodes = load_node_params(path)
    urdf_beside(nodes, path)
    return nodes


def run_batch(nodes: Mapping[str, Mapping[str, Any]], cycles: int | None = None) -> BatchRecord:
    """Run the session ``nodes`` describe for ``cycles`` cycles (default: the device node's
    ``duration_s`` at its ``rate_hz``); ``ValueError`` names a refused parameter."""
    dev, env, obs, ctl = (node_view(nodes, n) for n in NODES)
    loop = build(LoopSettings, dev)
    device = build_device(dev)
    observer_model, controller_model = build_model(obs), build_model(ctl)
    for who, m in (("observer", observer_model), ("controller", controller_model)):
        if tuple(m.joint_names) != tuple(device.model.joint_names):
            raise ValueError(
                f"the {who}'s model has joints {list(m.joint_names)}, the device "
                f"{list(device.model.joint_names)}"
            )
    observer = build(ObserverSettings, obs).build(observer_model, device.period_ns * 1e-9)
    cycle = LoopCycle(
        build(VirtualWall, env),
        observer,
        ImpedanceController(controller_model, build(ImpedanceLaw, ctl)),
        device.period_ns,
        build(Excitation, env, "excitation."),
    )
    n, dof = loop.batch_cycles(cycles), device.dof
    joint = np.empty((4, n, dof))
    cart = np.empty((5, n, 3))
    stamps = np.empty(n, dtype=np.int64)
    for k in range(n):
        s = device.sample()
        f_wall, f_est, tau = cycle.step(
            s.stamp_ns, s.q, s.qd, s.effort, s.ee_position, s.ee_velocity, s.wrench_measured
        )
        device.apply(tau)
        stamps[k] = s.stamp_ns
        joint[:, k] = (s.q, s.qd, s.effort, tau)
        cart[:, k] = (s.ee_position, f_wall, s.hand_force, s.wrench_measured, f_est)
    return BatchRecord(tuple(device.model.joint_names), stamps, *joint, *cart)


@dataclass(frozen=True)
class BatchSummary:
    """A session's headline figures: its settings and the estimate in contact."""

    model: str
    controller: str
    kf: float
    stiffness_n_per_m: float
    observer_gain: float
    duration_s: float
    seed: int
    in_contact_pct: float  # of the samples after the hand's ramp-in (SETTLE_S)
    estimate_rms_error_in_contact_n: float
    hand_force_span_in_contact_n: float


def summarize(record: BatchRecord, nodes: Mapping[str, Mapping[str, Any]]) -> BatchSummary:
    """The figures of ``record``, a run of the session ``nodes`` describe."""
    dev = node_view(nodes, "device_node")
    law = build(ImpedanceLaw, node_view(nodes, "controller_node"))
    wall = build(VirtualWall, node_view(nodes, "environment_node"))
    loop = build(LoopSettings, dev)
    contact = record.in_contact(wall)
    return BatchSummary(
        str(dev.get("model", "slide")),
        law.mode.value,
        law.kf,
        wall.stiffness_n_per_m,
        build(ObserverSettings, node_view(nodes, "observer_node")).gain,
        record.t.size / loop.rate_hz,
        loop.seed,
        100.0 * contact.share,
        contact.rms_error_n,
        contact.span_n,
    )
