"""The generalized-momentum observer (De Luca & Mattone 2003), discrete, as an alternative to the
disturbance observer (``haptic_dob.core.observers.disturbance``).

With ``p = D(q) q'`` the external effort is ``d = p' - tau + beta``, ``beta = G + friction -
C^T q'`` (the model's ``_mass_and_momentum_bias``), filtered by the same first-order lag ``1/K``
on every joint::

    r_k = a r_{k-1} + (1 - a) ((p_k - p_{k-1}) / T - tau_k + (beta_k + beta_{k-1}) / 2),
    a = exp(-K T)

``tau_k`` is the effort applied over [k-1, k) (the cycle contract). The first update only
initialises (estimate 0). The output clip and the wrench at the tip (``J^T F = r``) are the
disturbance observer's. Derivation and why one lag: docs/design/observer.md.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from haptic_dob.core.models.base import Vec
from haptic_dob.core.observers.disturbance import DisturbanceObserver
from haptic_dob.core.validation import positive


class MomentumObserver(DisturbanceObserver):
    """Estimate the external joint effort (N or N m) from the generalized momentum.

    Args:
        model: the device model the observer assumes.
        gain: K (1/s), > 0: every joint's estimate lags the true effort by ``1/K``.
        dt: update period T (s), > 0.
        limit: optional output clip, scalar or per joint (N or N m).
    """

    _scalar_path = False  # one update for every model, the slide's too

    def _set_gain(self, gain: float) -> None:
        self.gain = positive("gain", gain)
        self.discrete_gain = self.gain
        self._a = math.exp(-self.gain * self.dt)

    def retune(self, gain: float, limit: float | ArrayLike | None = None) -> None:
        """New K and clip; the estimate carries on (the filter's state is the estimate)."""
        new_limit = self._check_limit(limit)
        self._set_gain(gain)
        self._set_limit(new_limit)

    def reset(self) -> None:
        """Forget the state: the estimate is zero and the next ``update`` re-initialises."""
        super().reset()
        n = self.model.dof
        self._r = np.zeros(n)
        self._p_prev = np.zeros(n)
        self._beta_prev = np.zeros(n)

    def update(self, q: ArrayLike, qd: ArrayLike, tau: ArrayLike) -> Vec:
        """Advance one period with sample (q, qd) and the effort ``tau`` applied since the last one.

        Returns the estimated external joint effort, (dof,), clipped to ``limit``.
        """
        q_, qd_, tau_ = self._sample(q, qd, tau)
        D, beta = self.model._mass_and_momentum_bias(q_, qd_)
        p = D @ qd_
        if self._initialised:
            a = self._a
            raw = (p - self._p_prev) * (1.0 / self.dt) - tau_ + 0.5 * (beta + self._beta_prev)
            self._r = a * self._r + (1.0 - a) * raw
            d = self._r
        else:
            d = np.zeros(self._n)
            self._initialised = True
        self._p_prev, self._beta_prev = p, beta
        return self._output(d, qd_)
