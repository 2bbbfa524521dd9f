"""Joint friction of an arm from its joint states:
``tau - RNEA(q, q', q'') = b q' + Fc tanh(q' / v_c)`` (``Fc sgn(q')`` for ``v_c = 0``).

ROS-free (numpy/scipy/the model's pinocchio). The rigid-body part comes from the arm's model (its
URDF's masses and inertias, friction left out); what the measured effort has beyond it is fitted
per joint as viscous plus Coulomb friction with the 1-DOF identification's filters
(``haptic_dob.identification.filters``). ``v_c`` is searched over a grid (``b`` and ``Fc`` by
least squares at each, the smallest residual wins, refined by scipy's bounded scalar search) on
every sample but the filters' ends, slow ones included (reversals are where it shows), possibly
through a wider low-pass (``turn_cutoff_hz``); then ``b`` and ``Fc`` where the joint moves
clear of its turns (``MotionFilters.clear_of_turns``). Why: docs/recording-and-analysis.md,
"Identifying the device model". The fit uses the first ``1 - holdout`` of the record; on the
rest each joint reports the RMS the rigid body leaves unexplained without and with the friction.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import minimize_scalar

from haptic_dob.core.models._pinocchio import PinocchioModel
from haptic_dob.identification.filters import (
    MIN_SPEED,
    IdentificationError,
    MotionFilters,
    fit,
    physical,
)

Arr = NDArray[np.float64]


@dataclass(frozen=True)
class JointFriction:
    """One joint's fitted friction with standard errors and its held-out residuals (N m)."""

    joint: str
    viscous: float  # N m s/rad (or N s/m)
    coulomb: float  # N m (or N)
    viscous_std: float
    coulomb_std: float
    samples: int  # samples the fit used
    heldout_rms_rigid: float  # RMS of effort - rigid-body model on held-out moving samples
    heldout_rms: float  # the same with the fitted friction
    coulomb_speed: float = 0.0  # rad/s (or m/s): the Coulomb term turns over it; 0 = a sign


@dataclass(frozen=True)
class ArmFrictionFit:
    """Every joint's friction; ``as_params`` gives the URDF model's ``urdf.*`` overrides."""

    joints: list[JointFriction]
    holdout: float  # the part of the record held out (its end)

    def as_params(self) -> dict[str, list[float]]:
        """``urdf.viscous_n_m_s_per_rad``, ``urdf.coulomb_n_m`` and
        ``urdf.coulomb_speed_rad_per_s``, one value per joint."""
        return {
            "urdf.viscous_n_m_s_per_rad": [j.viscous for j in self.joints],
            "urdf.coulomb_n_m": [j.coulomb for j in self.joints],
            "urdf.coulomb_speed_rad_per_s": [j.coulomb_speed for j in self.joints],
        }


#: the speeds over which the Coulomb friction may turn (rad/s or m/s); 0 is a sign
COULOMB_SPEEDS = (0.0, *np.logspace(-4.0, -0.7, 67).tolist())


def identify_arm_friction(
    rigid: PinocchioModel,
    stamps_ns: NDArray[np.int64],
    position: Arr,
    effort: Arr,
    names: Sequence[str],
    cutoff_hz: float = 20.0,
    min_speed: float = MIN_SPEED,
    holdout: float = 0.3,
    turn_cutoff_hz: float | None = None,
) -> ArmFrictionFit:
    """Fit each joint's viscous and Coulomb friction on the effort ``rigid`` leaves unexplained.

    ``position`` and ``effort`` are (N, dof) in ``rigid``'s joint order (``names``); the effort of
    sample k was applied over [k-1, k). ``min_speed`` (rad/s or m/s): the held-out residuals, and
    the check that each joint moved enough, count only faster samples. ``turn_cutoff_hz``: the
    low-pass through which the search for ``v_c`` judges each candidate (default ``cutoff_hz``).
    """
    n, dof = position.shape
    if dof != rigid.dof or effort.shape != position.shape:
        raise IdentificationError(
            f"the record has {dof} joints and efforts of shape {effort.shape}; the model has "
            f"{rigid.dof} joints"
        )
    if n < 500:
        raise IdentificationError(f"too short: {n} samples, need 500")
    dt = float(np.median(np.diff(stamps_ns))) * 1e-9
    if not dt > 0.0 or not np.all(np.isfinite(position)) or not np.all(np.isfinite(effort)):
        raise IdentificationError("the stamps do not increase, or a value is not finite")
    f = MotionFilters.design(dt, cutoff_hz)
    wide = f if turn_cutoff_hz is None else turn_filters(dt, cutoff_hz, turn_cutoff_hz)
    # continuous joints a driver wraps to (-pi, pi]; no other joint jumps by pi in one sample
    position = np.unwrap(position, axis=0)
    v_light = f.light_velocity(position)
    r, v = _unexplained(rigid, f, position, effort)
    r_w, v_w = (r, v) if wide is f else _unexplained(rigid, wide, position, effort)
    split = int((1.0 - holdout) * n)
    speed = np.abs(v_light).max(axis=1)  # no gap nor a stretch held still in reach
    whole, whole_w = f.fit_rows(stamps_ns, speed), wide.fit_rows(stamps_ns, speed)
    every = np.arange(2 * f.window, split, f.step)  # slow samples too: the turn shows there
    every = every[whole[every]]
    every_w = np.arange(2 * wide.window, split, wide.step)
    every_w = every_w[whole_w[every_w]]
    out = []
    for j, name in enumerate(names):
        usable = f.usable(v_light[:, j], min_speed) & whole
        moving = np.flatnonzero(usable[:split])
        test_idx = np.flatnonzero(usable[split:])[:: f.step] + split
        if len(moving) < 20 * f.step or len(test_idx) < 10:
            raise IdentificationError(
                f"{name}: too little motion to fit ({len(moving) // f.step} usable samples faster "
                f"than {min_speed:g}/s before the held-out part, {len(test_idx)} in it)"
            )
        c = turn_speed(
            f,
            wide,
            v_light[:, j],
            (v[:, j], r[:, j], every),
            (v_w[:, j], r_w[:, j], every_w),
            str(name),
        )
        s = coulomb_term(f, v_light[:, j], c)
        rows = every[f.clear_of_turns(v_light[:, j], c, min_speed, every)]  # the term flat
        theta, std, _ = fit(np.column_stack([v[rows, j], s[rows]]), r[rows, j], str(name))
        rt = r[test_idx, j]
        pred = np.column_stack([v[test_idx, j], s[test_idx]]) @ theta
        out.append(
            JointFriction(
                str(name),
                physical("viscous friction", float(theta[0]), float(std[0]), str(name)),
                physical("Coulomb friction", float(theta[1]), float(std[1]), str(name)),
                float(std[0]),
                float(std[1]),
                len(rows),
                math.sqrt(float(np.mean(rt * rt))),
                math.sqrt(float(np.mean((rt - pred) ** 2))),
                float(c),
            )
        )
    return ArmFrictionFit(out, holdout)


def _unexplained(
    rigid: PinocchioModel, f: MotionFilters, position: Arr, effort: Arr
) -> tuple[Arr, Arr]:
    """The effort the rigid body leaves unexplained and the velocity, both through ``f``: the
    rigid body's effort on the light motion, filtered like the effort (``filters``' notes)."""
    x, v, a = f.light_motion(position)
    rigid_effort = np.array([rigid.inverse_dynamics(x[k], v[k], a[k]) for k in range(len(x))])
    _, v_f, _ = f.motion(position)
    return f.effort(effort) - f.smooth(rigid_effort), v_f


def turn_filters(dt: float, cutoff_hz: float, turn_cutoff_hz: float) -> MotionFilters:
    """The search's filters: a low-pass no narrower than the fit's; ``IdentificationError``
    naming ``turn_cutoff_hz`` otherwise."""
    if not turn_cutoff_hz >= cutoff_hz:
        raise IdentificationError(
            f"turn_cutoff_hz must be at least the fit's cutoff ({cutoff_hz:g} Hz), got "
            f"{turn_cutoff_hz:g}"
        )
    try:
        return MotionFilters.design(dt, turn_cutoff_hz)
    except IdentificationError as exc:
        raise IdentificationError(f"turn_cutoff_hz: {exc}") from None


def coulomb_term(f: MotionFilters, v_light: Arr, speed: float) -> Arr:
    """The Coulomb term through ``f``: the sign (``speed`` 0) or ``tanh(v / speed)``."""
    return f.coulomb_term(v_light) if speed == 0.0 else f.smooth(np.tanh(v_light / speed))


def turn_speed(
    f: MotionFilters,
    wide: MotionFilters,
    v_light: Arr,
    terms: tuple[Arr, Arr, NDArray[np.intp]],
    terms_w: tuple[Arr, Arr, NDArray[np.intp]],
    where: str,
) -> float:
    """The ``v_c`` whose model (``b`` and ``Fc`` by least squares through ``f``) leaves the least
    residual through ``wide``: the best of the grid, then refined between its neighbours on the
    grid (scipy's bounded scalar search on ``log v_c``); ``terms``: (velocity, unexplained
    effort, samples)."""
    v, r, every = terms
    v_w, r_w, every_w = terms_w

    def residual(c: float) -> float:
        s = coulomb_term(f, v_light, c)
        theta, _, _ = fit(np.column_stack([v[every], s[every]]), r[every], where)
        s_w = s if wide is f else coulomb_term(wide, v_light, c)
        e = r_w[every_w] - np.column_stack([v_w[every_w], s_w[every_w]]) @ theta
        return float(e @ e)

    grid = [residual(c) for c in COULOMB_SPEEDS]
    i = int(np.argmin(grid))
    if i == 0:  # a sign
        return 0.0
    lo = COULOMB_SPEEDS[i - 1] if i > 1 else COULOMB_SPEEDS[1] ** 2 / COULOMB_SPEEDS[2]
    hi = COULOMB_SPEEDS[min(i + 1, len(COULOMB_SPEEDS) - 1)]
    found = minimize_scalar(
        lambda x: residual(math.exp(x)),
        bounds=(math.log(lo), math.log(hi)),
        method="bounded",
        options={"xatol": 1e-3},
    )
    best = math.exp(float(found.x))
    return best if float(found.fun) < grid[i] else COULOMB_SPEEDS[i]
