"""An arm's least squares ``W theta = y`` kept as normal equations, per joint.

``W`` holds N samples of dof rows each (``arm_parameters.regressor``): tens of thousands of rows
by about a hundred parameters. ``Normal`` keeps, per joint j, ``W_j^T W_j``, ``W_j^T y_j`` and
``y_j^T y_j`` (numpy's einsum: no BLAS threads, which on a loaded machine made a QR of the rows
take seconds to minutes), from which least squares on any columns and any weighting of the
joints' rows needs only matrices of the parameters' size. The columns are scaled to unit norm
before each solve (the conditioning is then the regressor's with unit columns, about 10 on a
designed excitation, squared).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from haptic_dob.identification.filters import IdentificationError

Arr = NDArray[np.float64]
Cols = NDArray[np.intp]


@dataclass(frozen=True)
class Normal:
    """Per joint: ``G`` (dof, p, p), ``b`` (dof, p), ``yy`` (dof,); ``samples`` N, of which
    ``counts`` (dof,) are each joint's rows taken."""

    G: Arr
    b: Arr
    yy: Arr
    samples: int
    counts: Arr

    @classmethod
    def of(cls, W: Arr, y: Arr, dof: int, keep: NDArray[np.bool_] | None = None) -> Normal:
        """From the rows (sample by sample, ``dof`` rows each); ``keep`` (N, dof): the rows
        taken (default all)."""
        n = len(y) // dof
        W3, y2 = W.reshape(n, dof, -1), y.reshape(n, dof)
        if keep is not None:
            W3, y2 = W3 * keep[:, :, None], y2 * keep
        counts = np.full(dof, float(n)) if keep is None else keep.sum(axis=0).astype(float)
        G = np.einsum("kjp,kjq->jpq", W3, W3)
        b, yy = np.einsum("kjp,kj->jp", W3, y2), np.einsum("kj,kj->j", y2, y2)
        return cls(G, b, yy, n, counts)

    @property
    def rows(self) -> int:
        """Rows taken, over every joint."""
        return int(self.counts.sum())

    def total(self, weight: Arr | None = None) -> tuple[Arr, Arr, float]:
        """``W^T W``, ``W^T y``, ``y^T y`` with joint j's rows times ``weight[j]`` (default 1)."""
        w2 = np.ones(len(self.yy)) if weight is None else weight * weight
        G = np.einsum("j,jpq->pq", w2, self.G)
        return G, np.einsum("j,jp->p", w2, self.b), float(w2 @ self.yy)

    def residual_rms(self, cols: Cols, theta: Arr) -> Arr:
        """Each joint's RMS of ``y - W[:, cols] theta``."""
        G = self.G[:, cols][:, :, cols]
        rss = self.yy - 2.0 * self.b[:, cols] @ theta + np.einsum("p,jpq,q->j", theta, G, theta)
        out: Arr = np.sqrt(np.maximum(rss, 0.0) / np.maximum(self.counts, 1.0))
        return out


def _scaled(G: Arr, cols: Cols) -> tuple[Arr, Arr]:
    Gc = G[np.ix_(cols, cols)]
    d = np.sqrt(np.diag(Gc))
    d = np.where(d > 0.0, d, 1.0)
    return Gc / np.outer(d, d), d


def solve(G: Arr, b: Arr, yy: float, rows: int, cols: Cols, where: str) -> tuple[Arr, Arr, float]:
    """Least squares on ``cols``: theta, its standard errors, the residual's RMS (per row);
    ``IdentificationError`` where the motion does not separate the columns."""
    Gs, d = _scaled(G, cols)
    w, U = np.linalg.eigh(Gs)
    if not w[0] > 1e-12 * w[-1]:
        raise IdentificationError(
            f"{where}: the motion does not separate the terms of the model (a richer "
            "excitation is needed)"
        )
    inv = (U / w) @ U.T
    theta = (inv @ (b[cols] / d)) / d
    Gc = G[np.ix_(cols, cols)]
    rss = max(yy - 2.0 * float(theta @ b[cols]) + float(theta @ Gc @ theta), 0.0)
    sigma2 = rss / max(1, rows - len(cols))
    std = np.sqrt(np.maximum(np.diag(inv) * sigma2, 0.0)) / d
    return theta, std, float(np.sqrt(sigma2))


def condition_number(G: Arr, cols: Cols) -> float:
    """The condition number of ``W[:, cols]`` with its columns scaled to unit norm."""
    w = np.linalg.eigvalsh(_scaled(G, cols)[0])
    return float(np.sqrt(w[-1] / w[0])) if w[0] > 0.0 else float("inf")


def square_root(G: Arr, b: Arr) -> tuple[Arr, Arr]:
    """``R``, ``z`` with ``|R theta - z|^2 = theta^T G theta - 2 theta^T b`` plus a constant
    (a symmetric square root; directions ``G`` lacks are left out)."""
    w, U = np.linalg.eigh(G)
    keep = w > 1e-14 * max(float(w[-1]), 1e-300)
    root = np.sqrt(np.where(keep, w, 0.0))
    R = root[:, None] * U.T
    z = np.where(keep, (U.T @ b) / np.where(keep, root, 1.0), 0.0)
    return R, z
