"""The tip force that explains a joint effort: ``J(q)^T F = d`` solved for F (3,).

Costed for the 1 kHz loop: a square J by cofactors and a well-conditioned one by the normal
equations whenever J is provably far from singular, the damped least squares on an SVD
(Chiaverini's scheme) only near a singularity, so a singular arm gives a bounded force.
"""

from __future__ import annotations

import numpy as np

from haptic_dob.core.models.base import Mat, Vec


def tip_force(J: Mat, d: Vec, threshold: float, damping: float) -> Vec:
    """F (N) with ``J^T F = d`` for a (3, n) linear Jacobian and joint effort ``d`` (N or N m):
    exact while the smallest singular value of J is at least ``threshold`` (m), damped up to
    ``damping`` (m) below it."""
    if J.shape == (3, 3):
        F = solve_transpose3(J, d, threshold)
        if F is not None:
            return F
    # well-conditioned J (the usual case): the plain least-squares solution, no SVD.
    # 3 max|(J J^T)^-1| bounds its Frobenius norm, hence 1 / s_min^2, from above: passing
    # the test guarantees s_min >= threshold, where the damped solution is the undamped one.
    if J.shape[1] >= 3:
        try:
            Ginv = np.linalg.inv(J @ J.T)
        except np.linalg.LinAlgError:
            Ginv = None
        if Ginv is not None and 3.0 * np.abs(Ginv).max() * threshold**2 <= 1.0:
            return Ginv @ (J @ d)
    return dls_transpose_solve(J, d, threshold, damping)


def dls_transpose_solve(J: Mat, d: Vec, threshold: float, damping: float) -> Vec:
    """Solve ``J^T F = d`` for F (3,) by damped least squares on the SVD of J (3, n).

    Below the singular value ``threshold`` the damping grows smoothly to ``damping``
    (Chiaverini's scheme), so a singular arm gives a bounded wrench instead of a blow-up.
    """
    U, s, Vt = np.linalg.svd(J, full_matrices=False)
    smin = float(s[-1]) if s.size else 0.0
    lam2 = 0.0 if smin >= threshold else damping**2 * (1.0 - (smin / threshold) ** 2)
    inv = s / (s * s + lam2) if lam2 > 0.0 else np.where(s > 0.0, 1.0 / np.where(s > 0, s, 1), 0.0)
    return U @ (inv * (Vt @ d))


def solve_transpose3(J: Mat, d: Vec, threshold: float) -> Vec | None:
    """``J^T F = d`` for a square (3, 3) J by cofactors, or None when J may be ill-conditioned.

    None unless ``2 |det J| / |J|_F^2 >= threshold``, a lower bound of the smallest singular
    value (``s1 s2 <= |J|_F^2 / 2``): then no damping applies and the solution is exact. Plain
    floats: several times faster than an SVD for the 1 kHz loop.
    """
    (a, b, c), (e, f, g), (h, i, k) = J.tolist()
    c00, c01, c02 = f * k - g * i, g * h - e * k, e * i - f * h
    det = a * c00 + b * c01 + c * c02
    fro2 = a * a + b * b + c * c + e * e + f * f + g * g + h * h + i * i + k * k
    if not 2.0 * abs(det) >= threshold * fro2:  # also refuses NaN
        return None
    c10, c11, c12 = c * i - b * k, a * k - c * h, b * h - a * i
    c20, c21, c22 = b * g - c * f, c * e - a * g, a * f - b * e
    d0, d1, d2 = d.tolist()
    r = 1.0 / det
    return np.array(
        (
            (c00 * d0 + c01 * d1 + c02 * d2) * r,
            (c10 * d0 + c11 * d1 + c12 * d2) * r,
            (c20 * d0 + c21 * d1 + c22 * d2) * r,
        )
    )
