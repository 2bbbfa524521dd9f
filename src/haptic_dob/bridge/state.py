"""A driver's state as the model's joint vectors: joints by name, signs, units, velocity.

``StateReader`` turns one driver message (a ``JointState``'s fields, or a pose's position) into
the model's q and q' (and the driver's effort, where it reports one): joints matched by name in
any order with extra joints ignored (``core.joint_states.JointMap``), each multiplied by its sign
and the unit scale; a pose's axes permuted and signed (``frame.*``). Velocity is the driver's
where it gives one and the settings take it, else differenced from the positions
(``bridge.velocity``: low-passed, or by an adaptive window for coarse counts). Anything unusable
raises ``ValueError`` naming it; nothing is kept from a refused message.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np

from haptic_dob.bridge.driver_settings import FrameSettings
from haptic_dob.bridge.settings import per_element
from haptic_dob.bridge.state_settings import StateSettings
from haptic_dob.bridge.velocity import KalmanVelocity, Velocity, VelocityFilter, WindowVelocity
from haptic_dob.core.joint_states import JointMap, pick
from haptic_dob.core.models.base import DeviceModel


class DriverState(NamedTuple):
    """One driver sample in the model's joint order (SI): stamp (ns), q, q', and the effort
    the driver reports (``None``: it reports none)."""

    stamp_ns: int
    q: tuple[float, ...]
    qd: tuple[float, ...]
    effort: tuple[float, ...] | None


def velocity_estimator(state: StateSettings, n: int, period_s: float, max_gap_s: float) -> Velocity:
    """The settings' estimator of a differenced velocity for ``n`` joints: the Kalman filter
    where ``state.velocity_jerk_psd`` is set, else the adaptive window where
    ``state.encoder_resolution`` is, else the low-pass."""
    counts = per_element(
        "state.encoder_resolution", state.encoder_resolution, n, positive=False, of="joint"
    )
    if not all(math.isfinite(c) and c >= 0.0 for c in counts):
        raise ValueError(f"state.encoder_resolution must be >= 0 (0: the low-pass), got {counts}")
    psd = per_element("state.velocity_jerk_psd", state.velocity_jerk_psd, n, False, of="joint")
    if not all(math.isfinite(p) and p >= 0.0 for p in psd):
        raise ValueError(f"state.velocity_jerk_psd must be >= 0 (0: no Kalman filter), got {psd}")
    if any(psd) and not all(psd):
        raise ValueError(
            f"state.velocity_jerk_psd: set every joint's (> 0) or none (0), got {list(psd)}"
        )
    if any(psd) and not all(counts):
        raise ValueError(
            "state.velocity_jerk_psd needs every joint's state.encoder_resolution (> 0): the "
            "Kalman filter takes the counts' rounding as its noise"
        )
    if not any(counts):
        return VelocityFilter(state.velocity_cutoff_hz, max_gap_s)
    if not all(counts):
        raise ValueError(
            f"state.encoder_resolution: set every joint's (> 0) or none (0: the low-pass), got "
            f"{list(counts)}"
        )
    if any(psd):
        return KalmanVelocity(counts, psd, period_s, max_gap_s)
    return WindowVelocity(counts, state.velocity_window_samples, max_gap_s)


def check_cartesian(model: DeviceModel) -> None:
    """``ValueError`` unless ``model``'s joints are the tip's point (a pose state's model)."""
    x = np.array([0.01, -0.02, 0.03])
    if model.dof != 3 or not (
        np.allclose(model._forward_kinematics(x), x) and np.allclose(model._jacobian(x), np.eye(3))
    ):
        raise ValueError("state.type pose needs a Cartesian model (q = the tip's point)")


class StateReader:
    """Reads a driver's states into the model's joint order (``DriverState``).

    Args:
        state: the state settings (topic type, joints, signs, scale, velocity source).
        frame: the driver's axes against the model's base frame (pose states).
        model_joints: the model's joint names, in order.
        period_s: the driver's nominal period (the difference restarts after 5 of them).
    """

    def __init__(
        self,
        state: StateSettings,
        frame: FrameSettings,
        model_joints: Sequence[str],
        period_s: float,
    ) -> None:
        n = len(model_joints)
        names = [s for s in state.joints if s]
        if names and len(names) != n:
            raise ValueError(
                f"state.joints names {len(names)} joints for the model's {n} "
                f"({', '.join(model_joints)})"
            )
        self.driver_joints = tuple(names or model_joints)
        self.signs = per_element("state.signs", state.signs, n, positive=False)
        self.scale = state.scale
        self.source = state.velocity
        self.pose = state.type == "pose"
        if self.pose and n != 3:
            raise ValueError(f"state.type pose needs a 3-axis Cartesian model, not {n} joints")
        self.axes = tuple(frame.axes)
        self.axis_signs = tuple(frame.signs)
        self._map = JointMap(self.driver_joints)
        self._gain = [s * self.scale for s in self.signs]
        self.velocity = velocity_estimator(state, n, period_s, 5.0 * period_s)

    def joints(
        self, stamp_ns: int, names: Sequence[str], position: Any, velocity: Any, effort: Any
    ) -> DriverState:
        """A ``JointState``'s fields in model order; ``ValueError`` for a missing joint, a field
        of the wrong length, or NaN/inf."""
        idx = self._map.index(names, len(position))
        count = len(names) or len(position)
        gain = self._gain
        q = tuple(g * x for g, x in zip(gain, pick(position, idx, "position", count), strict=True))
        given = len(velocity) > 0 and self.source != "difference"
        if self.source == "driver" and not len(velocity):
            raise ValueError("the state has no velocity (state.velocity is driver)")
        if given:
            vel = pick(velocity, idx, "velocity", count)
            qd = tuple(g * v for g, v in zip(gain, vel, strict=True))
        tau = None
        if len(effort):
            tau = tuple(
                s * e for s, e in zip(self.signs, pick(effort, idx, "effort", count), strict=True)
            )
        values = q + (qd if given else ()) + (tau or ())
        if not all(map(math.isfinite, values)):
            raise ValueError("the state holds NaN or inf")
        if not given:
            qd = self.velocity.update(stamp_ns, q)
        return DriverState(stamp_ns, q, qd, tau)

    def count_warnings(self) -> list[str]:
        """A line for each joint newly seen to step by less than half its
        ``state.encoder_resolution`` (a count set too coarse makes the velocity lag; up to twice
        the true count passes unsaid). None for a pose state."""
        v = self.velocity
        if self.pose or not isinstance(v, WindowVelocity | KalmanVelocity):
            return []  # a pose's axes come through kinematics: their steps are no counts
        return [
            f"state.encoder_resolution: {self.driver_joints[j]} stepped {step:.3g} between two "
            f"states, under half its count ({2.0 * v.half[j]:.3g}): set the count it has, the "
            "smallest step it takes (too coarse, the velocity lags)"
            for j, step in sorted(v.finer_steps().items())
        ]

    def position(self, stamp_ns: int, xyz: Sequence[float]) -> DriverState:
        """A pose's position (driver axes) as the Cartesian model's q; q' differenced."""
        if not all(map(math.isfinite, xyz)):
            raise ValueError("the pose holds NaN or inf")
        q = tuple(
            s * self.scale * float(xyz[a]) for a, s in zip(self.axes, self.axis_signs, strict=True)
        )
        return DriverState(stamp_ns, q, self.velocity.update(stamp_ns, q), None)
