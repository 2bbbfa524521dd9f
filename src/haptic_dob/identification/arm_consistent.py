"""A physically consistent set of an arm's parameters that fits its efforts, drawn toward CAD.

A body's parameters are its joint's child link's (the variables) plus the fixed links' (the
URDF's). The child link (``Link``): mass ``m_0 exp(alpha)``, centre of mass ``mid + half
tanh(s)`` (in its box), second moment about it ``L_0 V V^T L_0^T``, ``V`` lower triangular with
diagonal ``exp(d)`` (with m > 0 the pseudo-inertia is positive definite, the inertia keeps the
triangle inequalities): log-Cholesky about the CAD ``m_0``, ``L_0 L_0^T``. Armature and friction
are squares (>= 0).

``fit_consistent`` minimises ``|R theta - z|^2 / sigma^2`` (the effort's least squares) plus the
squared distance from CAD (``alpha``, ``s - s_0``, ``d``, V's off-diagonal; joint parameters in
units of their size): the data outweigh it where they see a parameter, it decides where they do
not. scipy's Levenberg-Marquardt; each body's Jacobian by central differences.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

Arr = NDArray[np.float64]
_TRI = ((1, 0), (2, 0), (2, 1))  # V's off-diagonal entries
_I6 = ((0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2))  # pinocchio's order of the inertia
#: the central differences' step in the (dimensionless) variables
STEP = 1e-6


@dataclass(frozen=True)
class Link:
    """A body's child link: its CAD values, the box its centre of mass stays in (link frame, m)
    and the other links' fixed parameters (10, in the joint frame)."""

    mass: float  # kg, > 0 (the CAD mass, or a floor where CAD has none)
    com: Arr  # m, strictly inside the box
    second_moment: Arr  # kg m^2, (3, 3) positive definite: about the centre of mass
    lo: Arr
    hi: Arr
    rest: Arr

    def values(self, x: Arr) -> tuple[float, Arr, Arr]:
        """Mass, centre of mass and second moment about it at the variables ``x`` (10,)."""
        mid, half = 0.5 * (self.lo + self.hi), 0.5 * (self.hi - self.lo)
        m = self.mass * float(np.exp(x[0]))
        c = mid + half * np.tanh(x[1:4])
        V = np.diag(np.exp(x[4:7]))
        for k, (i, j) in enumerate(_TRI):
            V[i, j] = x[7 + k]
        L = self.cholesky @ V
        return m, c, L @ L.T

    @cached_property
    def cholesky(self) -> Arr:
        """``L_0``: the CAD second moment's Cholesky factor."""
        out: Arr = np.asarray(np.linalg.cholesky(self.second_moment), dtype=np.float64)
        return out

    def parameters(self, x: Arr) -> Arr:
        """The body's ten parameters at the variables ``x``."""
        out: Arr = self.rest + body_parameters(*self.values(x))
        return out

    def jacobian(self, x: Arr) -> Arr:
        """The body's ten parameters' derivatives in ``x`` (10 x 10, central differences)."""
        out = np.empty((10, 10))
        for k in range(10):
            step = np.zeros(10)
            step[k] = STEP
            out[:, k] = (self.parameters(x + step) - self.parameters(x - step)) / (2.0 * STEP)
        return out

    def start(self) -> Arr:
        """The variables of the CAD values."""
        mid, half = 0.5 * (self.lo + self.hi), 0.5 * (self.hi - self.lo)
        out = np.zeros(10)
        out[1:4] = np.arctanh((self.com - mid) / half)
        return out


def inertia_about_com(second_moment: Arr) -> Arr:
    """The rotational inertia of a second moment of mass (both about the same point)."""
    out: Arr = np.trace(second_moment) * np.eye(3) - second_moment
    return out


def body_parameters(m: float, c: Arr, second_moment: Arr) -> Arr:
    """The ten parameters (pinocchio's order) of a mass ``m`` at ``c`` with that second moment."""
    inertia = inertia_about_com(second_moment) + m * (float(c @ c) * np.eye(3) - np.outer(c, c))
    return np.array([m, *(m * c), *(inertia[i, j] for i, j in _I6)])


def pseudo_inertia(m: float, c: Arr, second_moment: Arr) -> Arr:
    """The 4x4 pseudo-inertia ``[[Sigma + m c c^T, m c], [m c^T, m]]`` about the link origin."""
    out = np.zeros((4, 4))
    out[:3, :3] = second_moment + m * np.outer(c, c)
    out[:3, 3] = out[3, :3] = m * c
    out[3, 3] = m
    return out


@dataclass(frozen=True)
class ConsistentFit:
    """Each child link's mass, centre of mass and second moment; armature, viscous and Coulomb
    friction per joint; the optimiser's word."""

    links: list[tuple[float, Arr, Arr]]
    armature: Arr
    viscous: Arr
    coulomb: Arr
    theta: Arr  # the standard parameters (bodies', then per joint)
    message: str


def _theta(links: Sequence[Link], x: Arr, dof: int) -> Arr:
    rigid = [link.parameters(x[10 * i : 10 * i + 10]) for i, link in enumerate(links)]
    return np.concatenate([*rigid, x[10 * len(links) : 10 * len(links) + 3 * dof]])


def _theta_jacobian(links: Sequence[Link], x: Arr) -> Arr:
    """``d theta / d x``: a 10 x 10 block per body, the identity for the joints' parameters."""
    out = np.eye(x.size)
    for i, link in enumerate(links):
        out[10 * i : 10 * i + 10, 10 * i : 10 * i + 10] = link.jacobian(x[10 * i : 10 * i + 10])
    return out


def fit_consistent(
    R: Arr, z: Arr, sigma: float, links: Sequence[Link], joints: tuple[Arr, Arr, Arr]
) -> ConsistentFit:
    """Solve the problem of the module from the CAD values. ``joints`` (each 3 * dof: armature,
    viscous, Coulomb per joint): the CAD values, the sizes their changes are counted in, and
    where to start (least squares' values; a start at 0 would hold a square there)."""
    joints_cad, joints_scale, joints_start = joints
    nb, dof = len(links), len(joints_cad) // 3
    rigid = 10 * nb
    ref = np.concatenate([link.start() for link in links])
    u0 = np.concatenate([ref, np.sqrt(np.maximum(joints_start, 0.1 * joints_scale))])

    def params(u: Arr) -> Arr:  # the joints' parameters are squares: >= 0
        return np.concatenate([u[:rigid], u[rigid:] ** 2])

    def residual(u: Arr) -> Arr:
        x = params(u)
        data = (R @ _theta(links, x, dof) - z) / sigma
        prior = np.concatenate([x[:rigid] - ref, (x[rigid:] - joints_cad) / joints_scale])
        return np.concatenate([data, prior])

    def jacobian(u: Arr) -> Arr:
        J = _theta_jacobian(links, params(u))
        J[:, rigid:] *= 2.0 * u[rigid:]
        prior = np.zeros((u.size, u.size))
        prior[:rigid, :rigid] = np.eye(rigid)
        prior[rigid:, rigid:] = np.diag(2.0 * u[rigid:] / joints_scale)
        return np.vstack([R @ J / sigma, prior])

    # Levenberg-Marquardt (MINPACK): the bounded methods stalled here (trf took hundreds of
    # reflective steps, dogbox stuck far off on a published arm)
    found = least_squares(residual, u0, jac=jacobian, method="lm", max_nfev=100 * len(u0))
    x = params(found.x)
    values = [link.values(x[10 * i : 10 * i + 10]) for i, link in enumerate(links)]
    j = x[rigid:]
    return ConsistentFit(
        values, j[:dof], j[dof : 2 * dof], j[2 * dof :], _theta(links, x, dof), str(found.message)
    )
