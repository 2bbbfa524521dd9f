"""The simulated arm's encoders: the joint angles as the device's counts give them.

Each encoder reads one row of ``E q`` (rad), rounded to its count; the joints are then
``E^-1`` of the counts. ``E`` is the identity where each joint has its own encoder. A device
whose driver reports a joint as a difference of two encoders (a Geomagic Touch's elbow is HD
joint 2 - HD joint 1, HD joint 2 the shoulder plus the elbow) has that sum as a row, so the
joint it reports is two rounded counts apart, as on the device.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from haptic_dob.core.models.base import Vec


class Encoders:
    """Quantize joint angles through the encoders' map ``E`` (rows over the joints).

    Args:
        resolution_rad: one count (rad); 0 = ideal encoders (the angles as they are).
        matrix: ``E`` flattened row by row (``dof * dof`` values, invertible); [] = identity.
        dof: the number of joints.
    """

    def __init__(self, resolution_rad: float, matrix: Sequence[float], dof: int) -> None:
        self.resolution_rad = float(resolution_rad)
        self._E: Vec | None = None
        self._E_inv: Vec | None = None
        if len(matrix) == 0:
            return
        if len(matrix) != dof * dof:
            raise ValueError(
                f"encoder_matrix must have {dof * dof} values ({dof} rows of {dof} joints), "
                f"got {len(matrix)}"
            )
        E = np.array(matrix, dtype=np.float64).reshape(dof, dof)
        if not np.all(np.isfinite(E)) or abs(np.linalg.det(E)) < 1e-9:
            raise ValueError(f"encoder_matrix must be finite and invertible, got {list(matrix)}")
        self._E, self._E_inv = E, np.asarray(np.linalg.inv(E), dtype=np.float64)

    def read(self, q: Vec) -> Vec:
        """The joint angles (rad) the counts give for the true angles ``q`` (rad)."""
        res = self.resolution_rad
        if res <= 0.0:
            return q.copy()
        if self._E is None:
            return np.round(q / res) * res
        assert self._E_inv is not None
        return self._E_inv @ (np.round(self._E @ q / res) * res)
