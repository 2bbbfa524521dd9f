"""The design of an arm's excitation (``arm_excitation``): the condition number of its base
regressor minimised within the arm's limits (see ``arm_excitation`` for the problem).

The free coefficients of joint j are ``a_2..a_L, b_2..b_L``; its positions, speeds and
accelerations over the sample points are linear maps of them (``_Series``). The effort (the CAD
model's inverse dynamics, ``W theta_CAD``) and the tip's point are not: their Jacobians and the
objective's gradient come from one forward-difference pass, shared (``_Problem.gradients``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import minimize

from haptic_dob.core.models import UrdfModel
from haptic_dob.core.models._pinocchio_inertia import body_parameters
from haptic_dob.identification import arm_parameters as ap
from haptic_dob.identification.arm_excitation import (
    ExcitationDesign,
    ExcitationLimits,
    FourierExcitation,
)

Arr = NDArray[np.float64]
#: the finer grid the design is checked on, in sample points per design point
CHECK = 10


class _Series:
    """Positions (less the start), speeds and accelerations at times ``t`` as linear maps of
    one joint's free coefficients, and the full coefficients ``a``, ``b`` they stand for."""

    def __init__(self, t: Arr, period_s: float, harmonics: int) -> None:
        l_ = np.arange(1, harmonics + 1)
        w = 2.0 * math.pi / period_s * l_
        ea = np.vstack([-np.ones(harmonics - 1), np.eye(harmonics - 1)])  # a_1 = -sum a_l
        eb = np.vstack([-l_[1:].astype(float), np.eye(harmonics - 1)])  # b_1 = -sum l b_l
        s, c = np.sin(np.outer(t, w)), np.cos(np.outer(t, w))
        self.E = np.block([[ea, np.zeros_like(ea)], [np.zeros_like(eb), eb]])  # x -> (a, b)
        self.q = np.hstack([(s / w) @ ea, ((1.0 - c) / w) @ eb])
        self.v = np.hstack([c @ ea, s @ eb])
        self.a = np.hstack([(-s * w) @ ea, (c * w) @ eb])


class _Problem:
    """The design problem on ``samples`` points of a period (see the module)."""

    def __init__(
        self,
        model: UrdfModel,
        start: Arr,
        period_s: float,
        harmonics: int,
        limits: ExcitationLimits,
        samples: int,
    ) -> None:
        self.model, self.start, self.limits = model, start, limits
        self.dof = model.dof
        self.series = _Series(np.arange(samples) * period_s / samples, period_s, harmonics)
        rng = np.array(model.position_limits)
        self.lo, self.hi = rng[:, 0] + limits.margin_rad, rng[:, 1] - limits.margin_rad
        speed = np.array(model.velocity_limits) * limits.speed_share
        self.vmax = np.where(
            speed > 0.0, np.minimum(speed, limits.max_speed_rad_s), limits.max_speed_rad_s
        )
        effort = np.array(model.effort_limits) * limits.effort_share
        self.emax = np.where(effort > 0.0, effort, np.inf)
        ref = ap.regressor(model, *ap.reference_states(model, ap.REFERENCE_STATES))
        self.base = ap.base_set(ref).base
        self.theta = np.concatenate(
            [body_parameters(model).ravel(), model.armature, model.viscous, model.coulomb]
        )
        self.box = (
            None
            if limits.box_lo is None or limits.box_hi is None
            else (np.array(limits.box_lo), np.array(limits.box_hi))
        )
        self._cache: dict[bytes, tuple[float, Arr]] = {}
        self._grad: dict[bytes, tuple[Arr, Arr]] = {}

    def motion(self, x: Arr, s: _Series | None = None) -> tuple[Arr, Arr, Arr]:
        """Positions, speeds, accelerations (N, dof) of the free coefficients ``x``."""
        s = s or self.series
        X = x.reshape(self.dof, -1)
        return self.start + s.q @ X.T, s.v @ X.T, s.a @ X.T

    def linear(self, x: Arr, s: _Series | None = None) -> Arr:
        """The linear constraints' values (>= 0 holds)."""
        q, v, a = self.motion(x, s)
        amax = self.limits.max_accel_rad_s2
        parts = [q - self.lo, self.hi - q, self.vmax - v, self.vmax + v, amax - a, amax + a]
        return np.concatenate([p.ravel() for p in parts])

    def linear_jacobian(self) -> Arr:
        """The linear constraints' Jacobian (constant)."""
        s, eye = self.series, np.eye(self.dof)
        blocks = [np.kron(M, eye)[:, self._order()] for M in (s.q, s.v, s.a)]
        return np.vstack([blocks[0], -blocks[0], -blocks[1], blocks[1], -blocks[2], blocks[2]])

    def _order(self) -> NDArray[np.intp]:
        """Columns of ``kron(M, eye)`` (coefficient-major) in ``x``'s order (joint-major)."""
        k = self.series.q.shape[1]
        return np.array(
            [c * self.dof + j for j in range(self.dof) for c in range(k)], dtype=np.intp
        )

    def evaluate(self, x: Arr, s: _Series | None = None) -> tuple[float, Arr]:
        """log of the condition number, and the nonlinear constraints' values (>= 0 holds)."""
        key = x.tobytes()
        if s is None and key in self._cache:
            return self._cache[key]
        q, v, a = self.motion(x, s)
        W = ap.regressor(self.model, q, v, a, np.sign(v))
        tau = (W @ self.theta).reshape(q.shape)
        parts = [(self.emax - tau).ravel(), (self.emax + tau).ravel()]
        if self.box is not None:
            tips = np.array([self.model._forward_kinematics(qk) for qk in q])
            parts += [(tips - self.box[0]).ravel(), (self.box[1] - tips).ravel()]
        nl = np.concatenate(parts)
        out = (
            math.log(ap.condition_number(W[:, self.base])),
            np.where(np.isfinite(nl), nl, 1e9),
        )
        if s is None:
            self._cache = {key: out}
        return out

    def gradients(self, x: Arr) -> tuple[Arr, Arr]:
        """The objective's gradient and the nonlinear constraints' Jacobian (forward
        differences, one pass for both)."""
        key = x.tobytes()
        if key not in self._grad:
            f0, c0 = self.evaluate(x)
            g, J = np.zeros(x.size), np.zeros((c0.size, x.size))
            for i in range(x.size):
                step = 1e-6 * max(1.0, abs(float(x[i])))
                xi = x.copy()
                xi[i] += step
                fi, ci = self.evaluate(xi)
                g[i], J[:, i] = (fi - f0) / step, (ci - c0) / step
            self.evaluate(x)
            self._grad = {key: (g, J)}
        return self._grad[key]

    def feasible(self, x: Arr, s: _Series | None = None) -> bool:
        """Whether ``x`` keeps every limit on the points of ``s``."""
        return bool(np.all(self.linear(x, s) >= 0.0) and np.all(self.evaluate(x, s)[1] >= 0.0))

    def scaled(self, x: Arr, s: _Series | None = None) -> Arr:
        """``x`` scaled up or down to just within the limits (bisection on the scale)."""
        lo, hi = 0.0, 1.0
        while self.feasible(hi * x, s) and hi < 1e3:
            lo, hi = hi, 2.0 * hi
        for _ in range(30):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if self.feasible(mid * x, s) else (lo, mid)
        out: Arr = 0.98 * lo * x
        return out


def design_excitation(
    model: UrdfModel,
    start: Sequence[float],
    *,
    period_s: float = 10.0,
    harmonics: int = 5,
    limits: ExcitationLimits | None = None,
    samples: int = 60,
    candidates: int = 12,
    iterations: int = 40,
    seed: int = 0,
) -> ExcitationDesign:
    """Design an excitation for ``model`` from rest at ``start`` (see ``arm_excitation``);
    ``ValueError`` with one line when the start is outside the limits or the box."""
    if harmonics < 2 or samples < 4 * harmonics or not period_s > 0.0:
        raise ValueError(
            "an excitation needs at least 2 harmonics, 4 samples per harmonic and a period > 0"
        )
    lim = limits or ExcitationLimits()
    q0 = np.asarray(start, dtype=np.float64)
    if q0.shape != (model.dof,):
        raise ValueError(f"start must have {model.dof} joint positions, got {q0.size}")
    p = _Problem(model, q0, period_s, harmonics, lim, samples)
    zero = np.zeros(model.dof * 2 * (harmonics - 1))
    if not p.feasible(zero):
        raise ValueError(
            "the start breaks a limit: a joint within its margin of a position limit, the effort "
            "to hold it above its share of the limit, or the tip outside the box"
        )
    rng = np.random.default_rng(seed)
    decay = np.tile(1.0 / np.arange(2, harmonics + 1), 2)
    tried = [
        p.scaled(rng.normal(size=(model.dof, decay.size)).ravel() * np.tile(decay, model.dof))
        for _ in range(candidates)
    ]
    x0 = min(tried, key=lambda x: p.evaluate(x)[0])
    start_cond = math.exp(p.evaluate(x0)[0])
    A = p.linear_jacobian()
    found = minimize(
        lambda x: p.evaluate(x)[0],
        x0,
        jac=lambda x: p.gradients(x)[0],
        method="SLSQP",
        constraints=[
            {"type": "ineq", "fun": p.linear, "jac": lambda _x: A},
            {"type": "ineq", "fun": lambda x: p.evaluate(x)[1], "jac": lambda x: p.gradients(x)[1]},
        ],
        options={"maxiter": iterations, "ftol": 1e-4},
    )
    x = found.x if p.feasible(found.x) else p.scaled(found.x)  # SLSQP's tolerance
    x = x if p.evaluate(x)[0] < p.evaluate(x0)[0] else x0
    fine = _Series(np.arange(samples * CHECK) * period_s / (samples * CHECK), period_s, harmonics)
    if not p.feasible(x, fine):
        x = p.scaled(x, fine)
    return _design(p, x, fine, period_s, start_cond)


def _design(
    p: _Problem, x: Arr, fine: _Series, period_s: float, start_cond: float
) -> ExcitationDesign:
    dof = p.dof
    coef = (p.series.E @ x.reshape(dof, -1).T).T  # (dof, 2L): a then b
    L = coef.shape[1] // 2
    excitation = FourierExcitation(
        p.model.joint_names,
        period_s,
        tuple(float(v) for v in p.start),
        tuple(tuple(float(v) for v in row[:L]) for row in coef),
        tuple(tuple(float(v) for v in row[L:]) for row in coef),
    )
    q, v, a = p.motion(x, fine)
    W = ap.regressor(p.model, q, v, a, np.sign(v))
    tau = (W @ p.theta).reshape(q.shape)
    tips = np.array([p.model._forward_kinematics(qk) for qk in q])
    return ExcitationDesign(
        excitation,
        condition_number=math.exp(p.evaluate(x)[0]),
        start_condition_number=start_cond,
        peak_speed_share=float(np.max(np.abs(v) / p.vmax)),
        peak_accel_share=float(np.max(np.abs(a)) / p.limits.max_accel_rad_s2),
        peak_effort_share=float(np.max(np.abs(tau) / (p.emax / p.limits.effort_share))),
        tip_lo=_triple(tips.min(axis=0)),
        tip_hi=_triple(tips.max(axis=0)),
    )


def _triple(v: Arr) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))
