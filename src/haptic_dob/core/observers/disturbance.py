"""The nonlinear disturbance observer (thesis ch. 5, after Chen et al. 2000), implicit update.

Continuous: ``p(q') = c q'``, ``L = c D(q)^-1``, ``z' = -L z + L (C q' + G + friction - tau - p)``,
``d_hat = z + p``. Discrete at period T, consistent backward Euler (stable for every c > 0)::

    (D_k + T c I) z_{k+1} = D_k z_k + T c (C q'_k + G_k + f_k - tau_k - c q'_{k+1})
    d_hat_{k+1} = z_{k+1} + c q'_{k+1}

The slide (constant D = m) uses ``c_d = (m / T)(exp(c T / m) - 1)`` for c, so its estimate's
time constant is exactly m/c, and ``f_k = friction_k``. Other models take
``f_k = (friction_k + friction_{k+1}) / 2``, unless ``_has_friction`` is False (then the friction
is in the bias effort, at sample k). ``update(q, qd, tau)`` takes sample k+1 and the effort applied
over [k, k+1) (the first call only initialises: estimate 0); ``prepare()`` makes ``D_k`` and the
bias off the command's path. Why this form, the gain, the friction: docs/design/observer.md.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike

from haptic_dob.core.models.base import DeviceModel, Mat, Vec
from haptic_dob.core.models.slide import SlideModel
from haptic_dob.core.tip_force import tip_force
from haptic_dob.core.validation import positive, scalar_of, vector

#: default observer gain c (N s/m): time constant m/c = 10 ms on the slide, corner 15.9 Hz
DEFAULT_GAIN = 41.6


class DisturbanceObserver:
    """Estimate the external joint effort d (N or N m) from q, q' and the applied effort.

    Args:
        model: the device model the observer assumes (``DeviceModel``).
        gain: observer gain c (N s/m for prismatic, N m s/rad for revolute joints), > 0.
        dt: update period T (s), > 0.
        limit: optional output clip, a scalar or one value per joint (N or N m), > 0. Only the
            output is clipped; the internal state runs on.
        dls_threshold_m: smallest singular value of J (m) below which ``wrench`` damps.
        dls_damping_m: the damping at a fully singular J (m).
    """

    _z: Vec  # the state, set by reset() (N or N m)
    _scalar_path = True  # the slide's update in floats

    def __init__(
        self,
        model: DeviceModel,
        gain: float,
        dt: float,
        limit: float | ArrayLike | None = None,
        *,
        dls_threshold_m: float = 1e-2,
        dls_damping_m: float = 1e-2,
    ) -> None:
        if not isinstance(model, DeviceModel):
            raise ValueError(f"model must be a DeviceModel, got {type(model).__name__}")
        self.model = model
        self.gain = positive("gain", gain)
        self.dt = positive("dt", dt)
        n = model.dof
        self._set_limit(self._check_limit(limit))
        self.dls_threshold_m = positive("dls_threshold_m", dls_threshold_m)
        self.dls_damping_m = positive("dls_damping_m", dls_damping_m)
        self._scalar = self._scalar_path and isinstance(model, SlideModel)
        # friction apart from the bias effort (DeviceModel._friction), for the trapezoid
        self._with_friction = bool(getattr(model, "_has_friction", True))
        self._axis = model.axis if isinstance(model, SlideModel) else np.zeros(3)  # (3,) slide
        self._n = n
        self._eye = np.eye(n)
        # one pass for D(q) and the bias effort when the model offers it (pinocchio models)
        self._dynamics: Callable[[Vec, Vec], tuple[Mat, Vec]] = getattr(
            model, "_mass_and_bias", None
        ) or (lambda q, qd: (model._mass_matrix(q), model._bias_effort(q, qd)))
        self._set_gain(self.gain)
        self.reset()

    def _check_limit(self, limit: float | ArrayLike | None) -> Vec | None:
        if limit is None:
            return None
        n = self.model.dof
        lim = np.asarray(limit, dtype=np.float64)
        lim = np.full(n, float(lim)) if lim.ndim == 0 else vector("limit", lim, n)
        for i, v in enumerate(lim):
            positive(f"limit[{i}]", v)
        return lim

    def _set_limit(self, limit: Vec | None) -> None:
        self.limit = limit
        self._neg_limit = None if limit is None else -limit

    def _set_gain(self, gain: float) -> None:
        self.gain = positive("gain", gain)
        if self._scalar:
            m = self.model.mass_kg  # type: ignore[attr-defined]  # scalar models are SlideModel
            self._alpha = math.exp(-self.gain * self.dt / m)
            self.discrete_gain = m * math.expm1(self.gain * self.dt / m) / self.dt
        else:
            self.discrete_gain = self.gain
        self._tc_eye = (self.dt * self.gain) * self._eye
        self._step: tuple[Mat, Mat] | None = None  # made again for the new gain

    def retune(self, gain: float, limit: float | ArrayLike | None = None) -> None:
        """Change gain and output clip while running, keeping the current estimate (no jump).

        ``d_hat = z + c q'``: the state is shifted by ``(c_old - c_new) q'`` of the last sample.
        """
        new_limit = self._check_limit(limit)
        old = self.discrete_gain
        self._set_gain(gain)
        self._set_limit(new_limit)
        if self._initialised:
            if self._scalar:
                self._z_s += (old - self.discrete_gain) * self._v_last
            else:
                self._z = self._z + (old - self.discrete_gain) * self._qd_last

    # ------------------------------------------------------------------------------------------
    def reset(self) -> None:
        """Forget the state: the estimate is zero and the next ``update`` re-initialises."""
        n = self.model.dof
        self._initialised = False
        self._z = np.zeros(n)
        self._D_prev: Mat = np.zeros((n, n))
        self._h_prev: Vec = np.zeros(n)
        self._z_s: float = 0.0
        self._h_s: float = 0.0
        self._v_last: float = 0.0
        self._qd_last: Vec = np.zeros(n)
        self._f_prev: Vec = np.zeros(n)
        self._estimate = np.zeros(n)
        self._pending: tuple[Vec, Vec] | None = None  # the sample whose dynamics are not made
        self._step = None

    @property
    def initialised(self) -> bool:
        """True once an update has set the observer's state."""
        return self._initialised

    @property
    def estimate(self) -> Vec:
        """The latest (clipped) estimate of the external joint effort, (dof,)."""
        return self._estimate.copy()

    def update(self, q: ArrayLike, qd: ArrayLike, tau: ArrayLike) -> Vec:
        """Advance one period with sample (q, qd) and the effort ``tau`` applied since the last one.

        Returns the estimated external joint effort d_hat, (dof,), clipped to ``limit``.
        """
        if self._scalar:
            return self._update_scalar(q, qd, tau)
        q_, qd_, tau_ = self._sample(q, qd, tau)
        c = self.gain
        f = self.model._friction(qd_) if self._with_friction else None
        if self._initialised:
            self.prepare()  # nothing to do when the caller prepared once the last command was out
            P, Q = self._step or self._make_step()
            # the friction's impulse over the period from both its ends (trapezoid)
            bias = self._h_prev if f is None else self._h_prev + 0.5 * (f - self._f_prev)
            self._z = P @ self._z + Q @ (bias - tau_ - c * qd_)
            d = self._z + c * qd_
        else:
            self._z = -c * qd_
            d = np.zeros(self._n)
            self._initialised = True
        self._pending = (q_, qd_)
        if f is not None:
            self._f_prev = f
        return self._output(d, qd_)

    def prepare(self) -> None:
        """Make the next update's dynamics (``D`` and the bias effort of the last sample) and its
        implicit step's matrices. Call it once the command is out, to keep that work off the next
        command's path; ``update`` does it first otherwise, with the same result."""
        if self._pending is None:
            return
        q, qd = self._pending
        self._pending = None
        self._D_prev, self._h_prev = self._dynamics(q, qd)
        self._make_step()

    def _make_step(self) -> tuple[Mat, Mat]:
        """``z_{k+1} = P z_k + Q r``: ``P = A^-1 D_k``, ``Q = T c A^-1``, ``A = D_k + T c I``;
        made once for a model whose D is constant (until the gain or the state is reset)."""
        if self._step is not None and self.model.constant_mass_matrix:
            return self._step
        A_inv: Mat = np.linalg.inv(self._D_prev + self._tc_eye).astype(np.float64, copy=False)
        step: tuple[Mat, Mat] = (A_inv @ self._D_prev, (self.dt * self.gain) * A_inv)
        self._step = step
        return step

    def _output(self, d: Vec, qd: Vec) -> Vec:
        """Keep sample's ``q'``, clip ``d`` to ``limit``, hold it as the estimate; a copy."""
        self._qd_last = qd
        lim, neg = self.limit, self._neg_limit
        if lim is not None and neg is not None:
            d = np.minimum(np.maximum(d, neg), lim)
        self._estimate = d
        return d.copy()

    def _sample(self, q: ArrayLike, qd: ArrayLike, tau: ArrayLike) -> tuple[Vec, Vec, Vec]:
        """q, qd, tau as float vectors of length dof; ``ValueError`` names the bad one.

        The loop's fast path: one array for the three, one finiteness test (a dot product is
        finite only when every element is); anything unusual takes the full checks.
        """
        n = self._n
        try:
            if (
                len(q) == n  # type: ignore[arg-type]  # checked Sequence on the fast path
                and len(qd) == n  # type: ignore[arg-type]  # checked Sequence on the fast path
                and len(tau) == n  # type: ignore[arg-type]  # checked Sequence on the fast path
                and not isinstance(q, (str, bytes))
                and not isinstance(qd, (str, bytes))
                and not isinstance(tau, (str, bytes))
            ):
                v = np.array((*q, *qd, *tau), dtype=np.float64)  # type: ignore[misc]  # sequences of floats here
                if v.ndim == 1 and math.isfinite(v @ v):
                    return v[:n], v[n : 2 * n], v[2 * n :]
        except (TypeError, ValueError):
            pass
        return vector("q", q, n), vector("qd", qd, n), vector("tau", tau, n)

    def _vector(self, name: str, value: ArrayLike) -> Vec:
        """``value`` as a finite float vector of length dof (fast path, then full checks)."""
        try:
            if len(value) == self._n and not isinstance(value, (str, bytes)):  # type: ignore[arg-type]  # sized, checked just above
                v = np.array(value, dtype=np.float64)
                if v.ndim == 1 and math.isfinite(v @ v):
                    return v
        except (TypeError, ValueError):
            pass
        return vector(name, value, self._n)

    def _update_scalar(self, q: object, qd: object, tau: object) -> Vec:
        """Slide fast path: the implicit update in floats with the pole-matched gain.

        ``(m + T c_d) z1 = m z0 + T c_d (h0 - u - c_d v1)`` written with ``alpha = m / (m + T c_d)
        = exp(-c T / m)``.
        """
        scalar_of("q", q)
        v = scalar_of("qd", qd)
        u = scalar_of("tau", tau)
        model: SlideModel = self.model  # type: ignore[assignment]  # the scalar path has a SlideModel
        c, alpha = self.discrete_gain, self._alpha
        if self._initialised:
            self._z_s = alpha * self._z_s + (1.0 - alpha) * (self._h_s - u - c * v)
            d = self._z_s + c * v
        else:
            self._z_s = -c * v
            d = 0.0
            self._initialised = True
        self._h_s = model.friction_scalar(v)
        self._v_last = v
        if self.limit is not None:
            lim = self.limit[0]
            d = lim if d > lim else (-lim if d < -lim else d)
        est = np.array((d,))
        self._estimate = est
        return est.copy()

    # ------------------------------------------------------------------------------------------
    def wrench(self, q: ArrayLike) -> Vec:
        """End-effector force F_hat (N), (3,), with J(q)^T F_hat = d_hat (damped least squares)."""
        if self._scalar:
            scalar_of("q", q)
            return self._axis * float(self._estimate[0])
        J = self.model._jacobian(self._vector("q", q))
        return tip_force(J, self._estimate, self.dls_threshold_m, self.dls_damping_m)
