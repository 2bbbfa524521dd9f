"""Identification of the 1-DOF device model ``m x'' + c x' + Fc sgn(x') = u`` from a record.

ROS-free (numpy/scipy); the input is what a driver's ``joint_states`` carries: the encoder
position of each sample k and the effort applied over [k-1, k). The methods (thesis ch. 4.2;
details and figures: docs/recording-and-analysis.md, "Identifying the device model"):

- ``least_squares`` (default), on any excitation with motion: position, its derivatives
  (Savitzky-Golay) and the effort through the same zero-phase Butterworth low-pass, then
  ``[a, v, sgn v] theta = u`` over the samples that move (``|v| > min_speed``), decimated to
  about one sample per filter time constant; a Stribeck term, kept where significant, takes the
  friction above Fc at low speed and is left out of the model returned.
- ``step`` (the thesis's method) under a virtual spring: k from the effort's spring, the damping
  ratio and Fc from two swings' decay, ``m = k / wn^2``, ``c = 2 zeta sqrt(k m)``.
- ``thesis_step``: the thesis's formulas verbatim, no Coulomb friction (``step`` without a spring).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import signal

from haptic_dob.identification.filters import IdentificationError, MotionFilters, fit, physical

Arr = NDArray[np.float64]
METHODS = ("least_squares", "step", "thesis_step")
OVERSHOOT_MIN = 0.02  # of the step: a smaller first overshoot is noise, not a swing
#: the Stribeck velocities (m/s) tried by least squares, a term ``sgn(v) exp(-(v/vs)^2)`` each
STRIBECK_GRID_M_PER_S = np.geomspace(1e-3, 3e-2, 15)
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
    rms_residual_n: float | None  # of the effort the fitted terms leave (least squares; with
    # the Stribeck term where it was kept)

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
    idx = np.flatnonzero(f.usable(v_light, min_speed) & f.contiguous(rec.stamps_ns))[:: f.step]
    if len(idx) < 20:
        raise IdentificationError(
            f"{rec.joint}: too little motion to fit ({len(idx)} usable samples moving faster "
            f"than {min_speed:g}/s); record an excitation (steps, a chirp, the hand's motion)"
        )
    X = np.column_stack([a[idx], v[idx], f.coulomb_term(v_light)[idx]])
    theta, std, rms = fit(X, u[idx], rec.joint)
    for vs in STRIBECK_GRID_M_PER_S:  # friction above Fc at low speed, which Fc must not absorb
        fall = f.smooth(np.sign(v_light) * np.exp(-((v_light / vs) ** 2)))[idx]
        try:
            th, sd, r = fit(np.column_stack([X, fall]), u[idx], rec.joint)
        except IdentificationError:  # this vs does not separate from Fc: try the next
            continue
        if r < rms and th[3] > 2.0 * sd[3]:
            theta, std, rms = th, sd, r
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


def _turning_points(x: Arr, tol: float, rest: int) -> tuple[list[int], bool]:
    """Indices of the alternating extrema of ``x`` (a max first), each confirmed by a retreat of
    more than ``tol``; the last swing's end too when ``x`` moves less than ``tol`` over its last
    ``rest`` samples (the swing ended at rest: then True)."""
    points: list[int] = []
    rising, best = True, 0
    for i in range(1, len(x)):
        if (x[i] > x[best]) == rising and x[i] != x[best]:
            best = i
        elif abs(x[best] - x[i]) > tol:
            points.append(best)
            rising, best = not rising, i
    if float(np.ptp(x[-rest:])) >= tol:
        return points, False
    # at rest: where the last swing stopped, before the resting tail (whose noise or creep
    # would otherwise move the extreme into it)
    start, stop = (points[-1] if points else 0), len(x) - rest
    if stop <= start:
        return points, False
    seg = x[start:stop] if rising else -x[start:stop]
    end = start + int(np.argmax(seg))
    if points and abs(x[end] - x[points[-1]]) <= tol:
        return points, False
    return [*points, end], True


def _peak_time(x: Arr, smooth: Arr, i: int, half: int, top: bool, first: bool) -> float:
    """The time (samples) of the extreme of the raw ``x`` near index ``i`` of ``smooth`` (within
    ``half`` samples; a maximum when ``top``): the middle of the samples that reach it within the
    noise (the zero-phase filter shifts a peak whose sides curve differently), or the first of
    them when ``first`` (where the motion stopped)."""
    lo, hi = max(0, i - half), min(len(x), i + half + 1)
    w = x[lo:hi] if top else -x[lo:hi]
    noise = float(np.std(np.diff(x[lo:hi], 2))) / math.sqrt(6.0)  # of white noise on x
    at = np.flatnonzero(w >= w.max() - 2.0 * noise - 1e-12)
    return lo + float(at[0] if first else np.mean(at))


def _spring_in_effort(x: Arr, u: Arr) -> tuple[float, float] | None:
    """The virtual spring the effort holds, ``u[j] = b - k x[j-1]`` (the effort of [j-1, j) is
    the command computed at sample j-1): ``(k, x_eq = b / k)``, or None when the effort is not
    such a spring (R^2 < 0.99, or k <= 0)."""
    X = np.column_stack([np.ones(len(x) - 1), x[:-1]])
    theta, *_ = np.linalg.lstsq(X, u[1:], rcond=None)
    resid = u[1:] - X @ theta
    k = -float(theta[1])
    spread = float(np.var(u[1:]))
    if not k > 0.0 or spread == 0.0 or float(np.var(resid)) > 0.01 * spread:
        return None
    return k, float(theta[0]) / k


def _over_damped(joint: str) -> str:
    return (
        f"{joint}: the step response does not overshoot (over-damped); the step method needs an "
        "under-damped response (a stiffer spring), or use least squares"
    )


def step_response(rec: JointRecord, thesis: bool = False) -> SlideFit:
    """The step method on the largest effort step of ``rec``: from the swings' decay, or by the
    thesis's formulas verbatim when ``thesis`` (see the module)."""
    dt = _check(rec, 100)
    jumps = np.abs(np.diff(rec.effort))
    i0 = int(np.argmax(jumps)) + 1  # first sample whose effort includes the step
    amplitude = float(rec.effort[i0] - rec.effort[i0 - 1])
    if jumps[i0 - 1] < 10.0 * (np.median(jumps) + 1e-12) or amplitude == 0.0:
        raise IdentificationError(f"{rec.joint}: no effort step found")
    x0 = float(np.mean(rec.position[max(0, i0 - 20) : i0]))
    nxt = np.flatnonzero(jumps[i0:] > 0.5 * abs(amplitude))  # the next step ends the window
    end = i0 + int(nxt[0]) if len(nxt) else len(rec.position)
    sign = math.copysign(1.0, amplitude)
    x = (rec.position[i0:end] - x0) * sign
    if len(x) < 50:
        raise IdentificationError(f"{rec.joint}: the step's response is too short")
    tail = x[int(0.8 * len(x)) :]
    x_ss = float(np.mean(tail))
    if not x_ss > 0.0:
        raise IdentificationError(f"{rec.joint}: the step moved nothing")
    spring = None if thesis else _spring_in_effort(x, rec.effort[i0:end] * sign)
    k, x_eq = spring if spring is not None else (abs(amplitude) / x_ss, x_ss)
    if not x_eq > 0.0:
        raise IdentificationError(
            f"{rec.joint}: the effort's spring holds the slide against the step (equilibrium "
            f"{x_eq:.3g}); not a step under a spring, use least squares"
        )
    # x[0] is sample i0, one period after the step began (its effort is that of [i0-1, i0)):
    # the step is at index -1; the extrema p_1, p_2, ... follow p_0 = 0, the rest before it
    low = signal.butter(2, min(20.0, 0.2 / dt), fs=1.0 / dt, output="sos")  # Hz
    smooth = signal.sosfiltfilt(low, x)
    idx, rested = _turning_points(smooth, 0.02 * x_eq, len(tail))
    if not idx or idx[0] >= len(x) - len(tail):
        raise IdentificationError(_over_damped(rec.joint))
    e = np.concatenate([[-x_eq], x[idx] - x_eq])  # each extremum's distance from equilibrium
    if spring is not None and len(idx) >= 2:
        # each half swing is linear about an equilibrium that Coulomb friction moves by
        # +-Fc/k against the motion: e_{n+1} = -r e_n + (1 + r) (Fc/k) sgn(e_n)
        A = np.column_stack([-e[:-1], np.sign(e[:-1])])
        (r, g), *_ = np.linalg.lstsq(A, e[1:], rcond=None)
        coulomb: float | None = k * float(g) / (1.0 + float(r))
    elif spring is not None:
        raise IdentificationError(
            f"{rec.joint}: the step response swung only once (it stopped on friction, or the "
            "record or the next step cut it); the step method needs two swings to tell damping "
            "from friction (a larger or longer step), or use least squares"
        )
    else:  # the thesis's: the first overshoot, no Coulomb friction
        r, coulomb = float(-e[1] / e[0]), None
    if not r > OVERSHOOT_MIN:
        raise IdentificationError(_over_damped(rec.joint))
    if not r < 1.0:
        raise IdentificationError(
            f"{rec.joint}: the swings of the step response do not decay geometrically (ratio "
            f"{r:.3g}); the step method needs an under-damped linear response, or use least squares"
        )
    ln = math.log(r)
    zeta = -ln / math.sqrt(math.pi**2 + ln**2)
    # the damped half period, counted from the step at index -1, from the swings that turned
    # (one that ended at rest stopped on friction, a little early), or from the only swing
    half = round(0.03 / dt)
    last = len(idx) - 1
    times = [
        _peak_time(x, smooth, i, half, j % 2 == 0, rested and j == last) for j, i in enumerate(idx)
    ]
    turned = np.asarray(times[:1] if spring is None else times[:-1] if rested else times)
    n = np.arange(1, len(turned) + 1)
    half_period = float(n @ (turned + 1.0) / (n @ n))  # samples
    wn = math.pi / (half_period * dt) / math.sqrt(1.0 - zeta**2)
    m = k / wn**2
    c = 2.0 * zeta * math.sqrt(k * m)
    if spring is not None:
        c += 0.5 * k * dt  # the spring, held over each period, lags dt/2: -k dt/2 of damping
    method = "thesis_step" if thesis else "step"
    return SlideFit(method, rec.joint, m, c, coulomb, None, None, None, len(x), None)


def identify(rec: JointRecord, method: str = "least_squares") -> SlideFit:
    """Identify the model of ``rec`` by ``method`` (one of ``METHODS``)."""
    if method == "least_squares":
        return least_squares(rec)
    if method in ("step", "thesis_step"):
        return step_response(rec, thesis=method == "thesis_step")
    raise IdentificationError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
