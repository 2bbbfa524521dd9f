"""Identification of the 1-DOF device model ``m x'' + c x' + Fc sgn(x') = u`` from a record.

ROS-free (numpy/scipy); the input is what a driver's ``joint_states`` carries: the encoder
position of each sample k and the effort applied over [k-1, k). Two methods (thesis ch. 4.2):

- ``least_squares`` (default), on any excitation with motion (steps, chirps, a hand's motion):
  position low-passed by a zero-phase Butterworth filter, velocity and acceleration its
  derivatives (Savitzky-Golay), the effort filtered the same way, then ``[a, v, sgn v] theta =
  u`` over the samples that move (``|v| > min_speed``), decimated to about one sample per
  filter time constant so that the standard errors are not those of correlated residuals.
- ``step``, the thesis's method: under a virtual spring, a force step A: stiffness ``k = A /
  x_ss``, damping ratio from the overshoot, natural frequency from the time to the first peak,
  ``m = k / wn^2``, ``c = 2 zeta sqrt(k m)``; Coulomb friction is not identified.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from haptic_dob.fit_filters import IdentificationError, MotionFilters, fit, physical

Arr = NDArray[np.float64]
METHODS = ("least_squares", "step")
__all__ = ["METHODS", "IdentificationError", "JointRecord", "SlideFit", "identify"]


@dataclass(frozen=True)
class JointRecord:
    """One joint's samples: stamps (ns), position (m or rad), effort over [k-1, k) (N or N m)."""

    stamps_ns: NDArray[np.int64]
    position: Arr
    effort: Arr
    joint: str

    @property
    def dt_s(self) -> float:
        """The sample period (s): the median stamp difference."""
        return float(np.median(np.diff(self.stamps_ns))) * 1e-9


@dataclass(frozen=True)
class SlideFit:
    """An identified model; ``*_std`` are standard errors (None where the method gives none)."""

    method: str
    joint: str
    mass_kg: float
    viscous_n_s_per_m: float
    coulomb_n: float | None
    mass_std: float | None
    viscous_std: float | None
    coulomb_std: float | None
    samples: int  # samples the fit used
    rms_residual_n: float | None  # of the effort the fitted model explains (least squares)

    def as_params(self) -> dict[str, float]:
        """The ``slide.*`` parameters of the observer's model (Coulomb 0 when not identified)."""
        return {
            "slide.mass_kg": self.mass_kg,
            "slide.viscous_n_s_per_m": self.viscous_n_s_per_m,
            "slide.coulomb_n": self.coulomb_n or 0.0,
        }


def _check(rec: JointRecord, min_samples: int) -> float:
    n = len(rec.position)
    if n < min_samples:
        raise IdentificationError(f"too short: {n} samples of {rec.joint}, need {min_samples}")
    if not (np.all(np.isfinite(rec.position)) and np.all(np.isfinite(rec.effort))):
        raise IdentificationError(f"{rec.joint}: position or effort is not finite everywhere")
    dt = rec.dt_s
    if not dt > 0.0:
        raise IdentificationError(f"{rec.joint}: the stamps do not increase")
    return dt


def least_squares(rec: JointRecord, cutoff_hz: float = 40.0, min_speed: float = 2e-3) -> SlideFit:
    """Fit m, c and Fc on ``rec`` (see the module); ``cutoff_hz`` of the low-pass, ``min_speed``
    (m/s) the speed below which a sample is left out (stiction, sign of the velocity)."""
    f = MotionFilters.design(_check(rec, 200), cutoff_hz)
    _, v, a = f.motion(rec.position)
    u = f.effort(rec.effort)
    v_light = f.light_velocity(rec.position)
    idx = np.flatnonzero(f.usable(v_light, min_speed))[:: f.step]
    if len(idx) < 20:
        raise IdentificationError(
            f"{rec.joint}: too little motion to fit ({len(idx)} usable samples moving faster "
            f"than {min_speed:g}/s); record an excitation (steps, a chirp, the hand's motion)"
        )
    X = np.column_stack([a[idx], v[idx], f.coulomb_term(v_light)[idx]])
    theta, std, rms = fit(X, u[idx], rec.joint)
    m = float(theta[0])
    c = physical("viscous friction", float(theta[1]), float(std[1]), rec.joint)
    fc = physical("Coulomb friction", float(theta[2]), float(std[2]), rec.joint)
    if not m > 0.0:
        raise IdentificationError(
            f"{rec.joint}: the fit gives a non-positive mass ({m:.3g} kg): the excitation is "
            "too slow or too weak for the inertia to show"
        )
    return SlideFit(
        "least_squares",
        rec.joint,
        m,
        c,
        fc,
        float(std[0]),
        float(std[1]),
        float(std[2]),
        len(idx),
        rms,
    )


def step_response(rec: JointRecord) -> SlideFit:
    """The thesis's step method on the largest effort step of ``rec`` (see the module)."""
    dt = _check(rec, 100)
    jumps = np.abs(np.diff(rec.effort))
    i0 = int(np.argmax(jumps)) + 1  # first sample whose effort includes the step
    amplitude = float(rec.effort[i0] - rec.effort[i0 - 1])
    if jumps[i0 - 1] < 10.0 * (np.median(jumps) + 1e-12) or amplitude == 0.0:
        raise IdentificationError(f"{rec.joint}: no effort step found")
    x0 = float(np.mean(rec.position[max(0, i0 - 20) : i0]))
    nxt = np.flatnonzero(jumps[i0:] > 0.5 * abs(amplitude))  # the next step ends the window
    end = i0 + int(nxt[0]) if len(nxt) else len(rec.position)
    x = (rec.position[i0:end] - x0) * math.copysign(1.0, amplitude)
    if len(x) < 50:
        raise IdentificationError(f"{rec.joint}: the step's response is too short")
    tail = x[int(0.8 * len(x)) :]
    x_ss = float(np.mean(tail))
    if not x_ss > 0.0:
        raise IdentificationError(f"{rec.joint}: the step moved nothing")
    ip = int(np.argmax(x))
    overshoot = (float(x[ip]) - x_ss) / x_ss
    if overshoot <= 0.0 or ip == 0 or ip >= len(x) - len(tail):
        raise IdentificationError(
            f"{rec.joint}: the step response does not overshoot (over-damped); the step method "
            "needs an under-damped response (a stiffer spring), or use least squares"
        )
    ln = math.log(overshoot)
    zeta = -ln / math.sqrt(math.pi**2 + ln**2)
    # x[0] is sample i0, one period after the step began (its effort is that of [i0-1, i0)):
    # the first peak, half a damped period after the step, is (ip + 1) periods after it
    wd = math.pi / ((ip + 1) * dt)
    wn = wd / math.sqrt(1.0 - zeta**2)
    k = abs(amplitude) / x_ss
    m = k / wn**2
    c = 2.0 * zeta * math.sqrt(k * m)
    return SlideFit("step", rec.joint, m, c, None, None, None, None, len(x), None)


def identify(rec: JointRecord, method: str = "least_squares") -> SlideFit:
    """Identify the model of ``rec`` by ``method`` (``least_squares`` or ``step``)."""
    if method == "least_squares":
        return least_squares(rec)
    if method == "step":
        return step_response(rec)
    raise IdentificationError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
