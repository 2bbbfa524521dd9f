"""The parameters an arm's joint efforts are linear in, and which of them a motion tells apart.

Standard parameters, in this order: each moving body's ten (``<link>.m``, ``.mx``, ``.my``,
``.mz``, ``.Ixx``, ``.Ixy``, ``.Iyy``, ``.Ixz``, ``.Iyz``, ``.Izz``: pinocchio's, about the joint
frame's origin; ``haptic_dob.core.models._pinocchio_inertia``), then each joint's armature,
viscous and Coulomb friction (``<joint>.armature``, ``.viscous``, ``.coulomb``). The effort is
``W theta``: per sample, the rigid-body regressor beside ``diag(q'')``, ``diag(q')`` and the
Coulomb term (a filtered sign or ``tanh(q' / v_c)``).

Base parameters (``base_set``): the standard columns, taken in order over many states, that are
not in the span of the ones before (a body's mass that no joint lifts is in every span); the
dependent ones are carried by them, ``beta = theta_b + K theta_d``. Visibility (``visibility``):
the variance of each base parameter's least-squares estimate per sample over a record, others
free, against the same over motion across the joints' ranges (``reference_states``): their ratio.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from haptic_dob.core.models._pinocchio import PinocchioModel
from haptic_dob.core.models._pinocchio_inertia import BODY_PARAMETERS, bodies, torque_regressor

Arr = NDArray[np.float64]
#: the per-joint parameters after the bodies', in this order
JOINT_PARAMETERS = ("armature", "viscous", "coulomb")
#: a column whose part outside the span of the earlier ones is below this share of its norm is
#: dependent (exact dependencies leave about 1e-13 over random states)
DEPENDENT = 1e-7
#: states of the motion across the joints' ranges (the base set's and the visibility's)
REFERENCE_STATES = 300


@dataclass(frozen=True)
class Layout:
    """The standard parameters of an arm: body (link) names, joint names, every name."""

    links: tuple[str, ...]
    joints: tuple[str, ...]

    @property
    def names(self) -> tuple[str, ...]:
        """Every standard parameter's name, in the columns' order."""
        rigid = [f"{b}.{p}" for b in self.links for p in BODY_PARAMETERS]
        per_joint = [f"{j}.{p}" for p in JOINT_PARAMETERS for j in self.joints]
        return (*rigid, *per_joint)

    @property
    def rigid(self) -> int:
        """The number of rigid-body parameters (10 per body)."""
        return 10 * len(self.links)

    @property
    def size(self) -> int:
        """The number of standard parameters."""
        return self.rigid + 3 * len(self.joints)


def layout_of(model: PinocchioModel) -> Layout:
    """The layout of ``model``'s parameters."""
    return Layout(tuple(b.link for b in bodies(model)), model.joint_names)


def regressor(model: PinocchioModel, x: Arr, v: Arr, a: Arr, coulomb: Arr) -> Arr:
    """``W`` (N * dof, standard parameters) for N samples of position, velocity, acceleration
    and Coulomb term (each (N, dof)), sample by sample (dof rows each)."""
    n, dof = x.shape
    rigid = np.array([torque_regressor(model, x[k], v[k], a[k]) for k in range(n)])
    eye = np.eye(dof)
    per_joint = [eye * a[:, :, None], eye * v[:, :, None], eye * coulomb[:, :, None]]
    out: Arr = np.concatenate([rigid, *per_joint], axis=2).reshape(n * dof, -1)
    return out


def with_coulomb(W: Arr, coulomb: Arr) -> Arr:
    """``W`` with its Coulomb columns from ``coulomb`` (N, dof) instead."""
    n, dof = coulomb.shape
    out = W.copy().reshape(n, dof, -1)
    out[:, :, -dof:] = np.eye(dof) * coulomb[:, :, None]
    return out.reshape(n * dof, -1)


def reference_states(model: PinocchioModel, n: int, seed: int = 0) -> tuple[Arr, Arr, Arr, Arr]:
    """``n`` states across the joints (positions over +-pi, speeds up to 1 rad/s, accelerations
    up to 3 rad/s^2, the Coulomb term their sign): what a motion is measured against."""
    rng = np.random.default_rng(seed)
    shape = (n, model.dof)
    x, v = rng.uniform(-np.pi, np.pi, shape), rng.uniform(-1.0, 1.0, shape)
    return x, v, rng.uniform(-3.0, 3.0, shape), np.sign(v)


@dataclass(frozen=True)
class BaseSet:
    """The base parameters: which standard columns they are, and how the rest are carried."""

    base: NDArray[np.intp]  # standard columns that are base parameters (named after them)
    dependent: NDArray[np.intp]
    K: Arr  # (base, dependent): beta = theta[base] + K theta[dependent]

    def beta(self, theta: Arr) -> Arr:
        """The base parameters of a standard set."""
        out: Arr = theta[self.base] + self.K @ theta[self.dependent]
        return out

    def names(self, layout: Layout) -> list[str]:
        """The base parameters' names (their standard column's)."""
        return [layout.names[i] for i in self.base]


def base_set(W: Arr) -> BaseSet:
    """The base parameters of a regressor ``W`` over many states (see the module)."""
    norms = np.linalg.norm(W, axis=0)
    scale = float(np.max(norms)) if norms.size else 0.0
    basis = np.zeros((W.shape[0], 0))
    base, dependent = [], []
    for i in range(W.shape[1]):
        c = W[:, i]
        if norms[i] <= 1e-9 * scale:
            dependent.append(i)
            continue
        r = c - basis @ (basis.T @ c)
        r = r - basis @ (basis.T @ r)  # twice: the classical Gram-Schmidt's lost orthogonality
        if np.linalg.norm(r) <= DEPENDENT * norms[i]:
            dependent.append(i)
        else:
            base.append(i)
            basis = np.column_stack([basis, r / np.linalg.norm(r)])
    b, d = np.array(base, dtype=np.intp), np.array(dependent, dtype=np.intp)
    K = np.asarray(np.linalg.lstsq(W[:, b], W[:, d], rcond=None)[0], dtype=np.float64)
    K[np.abs(K) < 1e-9 * max(1.0, float(np.max(np.abs(K), initial=0.0)))] = 0.0
    return BaseSet(b, d, K)


def _variances(A: Arr) -> Arr:
    """The diagonal of ``A``'s inverse (a Gram matrix), huge along directions it lacks."""
    w, U = np.linalg.eigh(A)
    floor = 1e-14 * max(float(np.max(w)), 1e-300)
    out: Arr = (U * U) @ (1.0 / np.maximum(w, floor))
    return out


def visibility(per_data: Arr, per_reference: Arr) -> Arr:
    """Per column (base parameters), the variance of its estimate per sample from motion across
    the joints over that from the record: 1 sees it as well, 0 not at all. Each argument is a
    regressor's Gram matrix per sample, ``W^T W / N`` (N samples of dof rows)."""
    scale = np.sqrt(np.diag(per_reference))
    scale[scale == 0.0] = 1.0
    outer = np.outer(scale, scale)
    out: Arr = _variances(per_reference / outer) / _variances(per_data / outer)
    return out


def condition_number(W: Arr) -> float:
    """The condition number of ``W`` with its columns scaled to unit norm (from the eigenvalues
    of its Gram matrix: exact to about 1e-8 times it)."""
    norms = np.linalg.norm(W, axis=0)
    Ws = W / np.where(norms > 0.0, norms, 1.0)
    w = np.linalg.eigvalsh(Ws.T @ Ws)
    return float(np.sqrt(w[-1] / w[0])) if w[0] > 0.0 else float("inf")


def unseen_names(names: Sequence[str], seen: Arr, threshold: float) -> list[str]:
    """The names whose visibility is below ``threshold``."""
    return [n for n, s in zip(names, seen, strict=True) if not s >= threshold]
