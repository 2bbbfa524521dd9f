"""A 1-DOF slide simulator that is not the suite's: the identification's check of honesty.

Nothing here comes from ``haptic_sim``: LuGre friction (a bristle state with stiction and a
Stribeck fall-off, presliding displacement and micro-damping), an amplifier current loop as a
first-order lag, integrated by fixed-step RK4 at ``substeps`` per sample; a 1 um encoder; a
driver that holds each sample's command over the next period and reports it as the next joint
state's effort (what ``sensor_msgs/JointState`` of a driver carries). The parameters are drawn
from a seeded generator, so the identification is not told them.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

ENCODER_M = 1e-6


@dataclass(frozen=True)
class ForeignSlide:
    """The truth: mass (kg), viscous (N s/m), Coulomb and static friction (N), the Stribeck
    velocity (m/s), LuGre bristle stiffness (N/m) and damping (N s/m), amplifier lag (s)."""

    mass_kg: float
    viscous_n_s_per_m: float
    coulomb_n: float
    static_n: float
    stribeck_m_per_s: float
    bristle_n_per_m: float
    bristle_damping_n_s_per_m: float
    amplifier_lag_s: float

    @classmethod
    def draw(cls, seed: int) -> ForeignSlide:
        """A slide like the thesis's, with parameters the test does not pass on."""
        g = np.random.default_rng(seed)
        m = float(g.uniform(0.3, 0.6))
        fc = float(g.uniform(0.15, 0.35))
        sigma0 = float(g.uniform(1e4, 3e4))
        return cls(
            mass_kg=m,
            viscous_n_s_per_m=float(g.uniform(0.8, 2.0)),
            coulomb_n=fc,
            static_n=fc * float(g.uniform(1.2, 2.0)),
            stribeck_m_per_s=float(g.uniform(2e-3, 1e-2)),
            bristle_n_per_m=sigma0,
            bristle_damping_n_s_per_m=math.sqrt(sigma0 * m),
            amplifier_lag_s=float(g.uniform(2e-5, 2e-4)),
        )

    def _deriv(self, s: list[float], u: float) -> list[float]:
        """d/dt of (position, velocity, bristle deflection, amplifier force) under command u."""
        _, v, z, f = s
        g = self.coulomb_n + (self.static_n - self.coulomb_n) * math.exp(
            -((v / self.stribeck_m_per_s) ** 2)
        )
        dz = v - self.bristle_n_per_m * abs(v) * z / g
        friction = self.bristle_n_per_m * z + self.bristle_damping_n_s_per_m * dz
        friction += self.viscous_n_s_per_m * v
        return [v, (f - friction) / self.mass_kg, dz, (u - f) / self.amplifier_lag_s]

    def run(
        self,
        command: Callable[[float, float], float],
        seconds: float,
        dt: float = 1e-3,
        substeps: int = 60,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Stamps (ns), encoder positions (m) and efforts (N, the command held over [k-1, k))
        of ``seconds`` at ``1/dt`` Hz; ``command(t, encoder position)`` is the driver's."""
        n = round(seconds / dt)
        h = dt / substeps
        s = [0.0, 0.0, 0.0, 0.0]
        stamps = np.arange(n, dtype=np.int64) * round(dt * 1e9)
        pos, eff = np.empty(n), np.empty(n)
        u_prev = 0.0
        for k in range(n):
            pos[k] = ENCODER_M * round(s[0] / ENCODER_M)
            eff[k] = u_prev
            u = command(k * dt, float(pos[k]))
            for _ in range(substeps):
                k1 = self._deriv(s, u)
                k2 = self._deriv(_step(s, 0.5 * h, k1), u)
                k3 = self._deriv(_step(s, 0.5 * h, k2), u)
                k4 = self._deriv(_step(s, h, k3), u)
                s = [
                    a + h / 6.0 * (b + 2.0 * c + 2.0 * d + e)
                    for a, b, c, d, e in zip(s, k1, k2, k3, k4, strict=True)
                ]
            u_prev = u
        return stamps, pos, eff


def _step(s: list[float], h: float, d: list[float]) -> list[float]:
    return [a + h * b for a, b in zip(s, d, strict=True)]
