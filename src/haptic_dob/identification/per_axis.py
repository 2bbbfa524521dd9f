"""Identification of a Cartesian device per axis: mass, viscous and Coulomb friction of each.

A point-mass device (``haptic_dob.core.models.point_mass``: Force Dimension's ``fd_x, fd_y,
fd_z``) is three uncoupled 1-DOF axes, so each axis is the 1-DOF least-squares fit of
``haptic_dob.identification.one_dof`` on that axis's positions and efforts (velocity and
acceleration by its filters from positions alone: a driver's velocity is never read). One
record of an excitation session along every axis (``Excitation(along="axes")``) identifies all
three. ``as_params`` is the ``point_mass.*`` block the observer and the controller load.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from haptic_dob.identification.filters import IdentificationError
from haptic_dob.identification.one_dof import JointRecord, SlideFit, least_squares


@dataclass(frozen=True)
class AxesFit:
    """Each axis's fit (least squares), in the order of the axes asked for (x, y, z)."""

    axes: tuple[SlideFit, ...]

    def as_params(self) -> dict[str, list[float] | list[str]]:
        """The ``point_mass.*`` parameters of the observer's and the controller's model."""
        if len(self.axes) != 3:
            raise IdentificationError(
                f"a point-mass model has three axes (x, y, z), the fit has {len(self.axes)}"
            )
        return {
            "point_mass.mass_kg": [f.mass_kg for f in self.axes],
            "point_mass.viscous_n_s_per_m": [f.viscous_n_s_per_m for f in self.axes],
            "point_mass.coulomb_n": [f.coulomb_n or 0.0 for f in self.axes],
            "point_mass.joint_names": [f.joint for f in self.axes],
        }


def identify_axes(
    stamps_ns: NDArray[np.int64],
    position: NDArray[np.float64],
    effort: NDArray[np.float64],
    names: Sequence[str],
    cutoff_hz: float = 40.0,
) -> AxesFit:
    """Fit m, c and Fc of every axis: ``position`` and ``effort`` (N, n) in ``names``' order, the
    effort of sample k applied over [k-1, k). ``IdentificationError`` (one line, naming the axis)
    when an axis cannot be fitted."""
    if position.ndim != 2 or position.shape != effort.shape or position.shape[1] != len(names):
        raise IdentificationError(
            f"positions {position.shape} and efforts {effort.shape} must be (samples, "
            f"{len(names)}) for the axes {', '.join(names)}"
        )
    fits = []
    for i, name in enumerate(names):
        rec = JointRecord(stamps_ns, position[:, i], effort[:, i], str(name))
        fits.append(least_squares(rec, cutoff_hz))
    return AxesFit(tuple(fits))
