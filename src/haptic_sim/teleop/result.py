"""What a teleoperation session gives: per-cycle arrays (``TeleopResult``) and its headline
figures (``TeleopMetrics``).

Contact: the true contact force is non-zero. In contact, ``estimate_error_pct`` is the RMS of the
3-D error of the slave observer's estimate against the true contact force, in % of the true
force's RMS (``estimate_error_n``: in N); ``force_tracking_error_pct`` the same for the force the
master renders, scaled back to the slave (``R F_w / force_scale``) at the same instant. Outside
contact: ``free_estimate_max_n``, the largest estimate after ``settle_s``; ``position_error_mm``,
the RMS distance from the slave's tool point (its encoders' ``ee_pose``) to the master's point
mapped to the slave. Channel: ``channel_energy_min_j``, the lowest net energy the channel took in
(``E_in`` minus ``E_out`` of both ports; below zero it generated energy); ``dissipated_j``, what
the passivity controllers took out; ``oscillation_mm``, the standard deviation of the master's
point over the last second, high-passed at 2 Hz, on its most moving axis.
What each figure tells: docs/design/teleoperation.md.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from scipy import signal

from haptic_msgs_py.stamps import period_ns

if TYPE_CHECKING:
    from haptic_sim.teleop.config import TeleopConfig

OSCILLATION_HZ = 2.0  # the oscillation figure looks above this


@dataclass(frozen=True)
class TeleopMetrics:
    """Headline figures of one session (see the module docstring)."""

    architecture: str
    force_source: str
    round_trip_delay_ms: float
    passivity: bool
    duration_s: float
    contact_pct: float
    contact_force_rms_n: float
    estimate_error_n: float
    estimate_error_pct: float
    force_tracking_error_pct: float
    free_estimate_max_n: float
    position_error_mm: float
    channel_energy_min_j: float
    channel_energy_final_j: float
    dissipated_j: float
    oscillation_mm: float


@dataclass
class TeleopResult:
    """Per-cycle arrays (SI units), one row per cycle k; 3-vectors in the slave's frame.

    ``master_point``: the master's point mapped to the slave (``mapped_point``);
    ``slave_point``: the slave's tool point from its encoders (its ``ee_pose``); ``target``: the
    point the slave tracks; ``contact``: the true contact force; ``estimate``: the slave
    observer's; ``sensor``: the wrist sensor's; ``rendered``: the master's wall force scaled to
    the slave (``rendered_force``); ``hand``: the hand's force on the master (its frame);
    ``e_in_*``/``e_out_*``: each port's energy book (J); ``dissipated``: both controllers'
    (J); ``silent``: 1 the master's end lost the slave, 2 the slave's end the master, 3 both.
    """

    config: TeleopConfig
    t: np.ndarray
    master_q: np.ndarray
    master_qd: np.ndarray
    slave_q: np.ndarray
    slave_command: np.ndarray
    master_point: np.ndarray
    slave_point: np.ndarray
    target: np.ndarray
    contact: np.ndarray
    estimate: np.ndarray
    sensor: np.ndarray
    rendered: np.ndarray
    hand: np.ndarray
    e_in_master: np.ndarray
    e_out_master: np.ndarray
    e_in_slave: np.ndarray
    e_out_slave: np.ndarray
    dissipated: np.ndarray
    silent: np.ndarray

    @property
    def in_contact(self) -> np.ndarray:
        """Samples with a non-zero true contact force."""
        mask: np.ndarray = np.linalg.norm(self.contact, axis=1) > 0.0
        return mask

    @property
    def channel_energy(self) -> np.ndarray:
        """Net energy the channel took in (J): ``E_in - E_out`` of both ports."""
        e: np.ndarray = (self.e_in_master + self.e_in_slave) - (
            self.e_out_master + self.e_out_slave
        )
        return e

    def metrics(self, settle_s: float = 0.5) -> TeleopMetrics:
        """The headline figures, leaving out the first ``settle_s`` (the observer's start)."""
        cfg = self.config
        fs = cfg.loop.rate_hz
        start = min(round(settle_s * fs), self.t.size // 4)
        s = slice(start, None)
        touch = self.in_contact[s]
        free = ~touch
        true = self.contact[s]
        ref = _rms(true[touch])
        est_err = _rms((self.estimate[s] - true)[touch])
        trk_err = _rms((self.rendered[s] - true)[touch])
        e = self.channel_energy
        return TeleopMetrics(
            architecture=cfg.teleop.architecture,
            force_source=cfg.teleop.force_source,
            round_trip_delay_ms=cfg.channel.simulated_round_trip_ms(period_ns(cfg.loop.rate_hz)),
            passivity=cfg.channel.passivity,
            duration_s=self.t.size / fs,
            contact_pct=float(np.mean(touch) * 100.0),
            contact_force_rms_n=ref,
            estimate_error_n=est_err,
            estimate_error_pct=_pct(est_err, ref),
            force_tracking_error_pct=_pct(trk_err, ref),
            free_estimate_max_n=float(
                np.max(np.linalg.norm(self.estimate[s][free], axis=1), initial=0.0)
            ),
            position_error_mm=_rms((self.slave_point[s] - self.master_point[s])[free]) * 1e3,
            channel_energy_min_j=float(np.min(e)),
            channel_energy_final_j=float(e[-1]),
            dissipated_j=float(self.dissipated[-1]),
            oscillation_mm=max(oscillation(x, fs) for x in self.master_point.T)
            * 1e3
            / cfg.teleop.position_scale,
        )

    def save(self, path: str | Path) -> None:
        """Write the arrays to an ``.npz`` file."""
        arrays = {
            f.name: getattr(self, f.name) for f in dataclasses.fields(self) if f.name != "config"
        }
        np.savez(path, **arrays)


def mapped_point(
    R: np.ndarray, scale: float, p_s0: np.ndarray, p_m0: np.ndarray, p: Sequence[float]
) -> np.ndarray:
    """The master's point ``p`` (m, its frame) mapped to the slave: ``p_s0 + scale R (p -
    p_m0)``, the start points ``p_m0`` and ``p_s0`` of master and slave."""
    out: np.ndarray = p_s0 + scale * (R @ (np.asarray(p) - p_m0))
    return out


def rendered_force(R: np.ndarray, force_scale: float, f_w: Sequence[float]) -> np.ndarray:
    """The master's wall force ``f_w`` (N, its frame) in slave units: ``R f_w / force_scale``
    (zero for a zero scale)."""
    if force_scale <= 0.0:
        return np.zeros(3)
    out: np.ndarray = (R @ np.asarray(f_w)) / force_scale
    return out


def _rms(x: np.ndarray) -> float:
    """RMS of the rows' norms (NaN for no rows)."""
    if x.size == 0:
        return float("nan")
    sq = x * x
    return float(np.sqrt(np.mean(np.sum(sq, axis=1) if x.ndim == 2 else sq)))


def _pct(err: float, ref: float) -> float:
    return float(err / ref * 100.0) if ref > 0.0 else float("nan")


def oscillation(x: np.ndarray, fs: float, last_s: float = 1.0) -> float:
    """Standard deviation (m) of ``x`` over its last ``last_s`` seconds, high-passed at
    ``OSCILLATION_HZ`` (4th order, zero phase)."""
    n = min(x.size, round(last_s * fs))
    if n < 32:
        return float("nan")
    sos = signal.butter(4, OSCILLATION_HZ, "highpass", fs=fs, output="sos")
    y = signal.sosfiltfilt(sos, x[-n:] - x[-n:].mean())
    return float(np.std(y))


def metrics_row(m: TeleopMetrics) -> dict[str, Any]:
    """The figures as a flat mapping (JSON, tables)."""
    return dataclasses.asdict(m)
